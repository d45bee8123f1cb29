"""Inverse design: printable settings whose predicted k and c hit targets, ranked by desirability.

The engineering standard of response optimisers (Minitab, JMP): a Derringer-Suich target-is-best
desirability per response, their importance-weighted geometric mean as the composite, and a
multi-start IPOPT search (CasADi ``nlpsol``) over the continuous factors for every combination of
the categorical levels. IPOPT minimises the smooth importance-weighted squared deviation from the
targets (the desirability's kink at the target makes it a poor NLP objective), plus a small
term on the prediction interval so that, among designs that hit the target, the better supported
one wins; candidates are then rounded to printable values and ranked by composite desirability.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import casadi as ca
import numpy as np

from . import space, units
from .errors import DesignerError
from .surrogate import Prediction, Surrogate

#: relative deviation from a target within which it counts as hit
HIT_TOLERANCE = 0.02
#: weight of the (normalised) squared PI width in the objective: a tie-breaker only
PI_WEIGHT = 1e-3
#: starts per categorical combination: the centre, then fixed pseudo-random points
N_STARTS = 4
#: designs closer than this in normalised factor space are the same design
DISTINCT = 0.05
_IPOPT = {
    "ipopt.print_level": 0,
    "print_time": False,
    "ipopt.sb": "yes",
    "ipopt.tol": 1e-9,
    "ipopt.max_iter": 300,
    "error_on_fail": False,
}


@dataclass(frozen=True)
class Target:
    """A target-is-best goal on one response, with the desirability's lower and upper bounds."""

    quantity: str  # "k" or "c"
    value: float
    low: float
    high: float
    importance: float = 1.0

    def desirability(self, y: float) -> float:
        """Derringer-Suich two-sided desirability (linear weights): 1 at target, 0 at the bounds."""
        if y <= self.low or y >= self.high:
            return 0.0
        if y <= self.value:
            return (y - self.low) / (self.value - self.low)
        return (self.high - y) / (self.high - self.value)


def _extended_range(f: space.Factor) -> tuple[float, float]:
    """The search range with --allow-extrapolation: half the tested span beyond each end."""
    half = (f.high - f.low) / 2
    low = max(f.low - half, 2 * space.WALL_MM if f.name == "width" else 1e-3)
    return low, min(f.high + half, 100.0) if f.name == "density" else f.high + half


def make_target(
    surrogate: Surrogate,
    quantity: str,
    axis: str,
    value: float,
    importance: float = 1.0,
    low: float | None = None,
    high: float | None = None,
) -> Target:
    """A target with desirability bounds defaulting to the observed range of the response.

    A target outside that range widens the violated bound to half (or 1.5 times) the target, so
    the ranking still works; `suggest` states that the target lies outside what the data supports.
    """
    unit = units.rig_unit(quantity, axis)
    if not np.isfinite(value) or value <= 0:
        raise DesignerError(f"target {quantity} = {value:g} {unit} must be positive", "give a value > 0")
    if not np.isfinite(importance) or importance <= 0:
        raise DesignerError(f"importance of {quantity} = {importance:g} must be positive", "give a value > 0")
    obs_lo, obs_hi = surrogate.model(f"{quantity}_{axis}").observed_range
    lo = min(obs_lo, 0.5 * value) if low is None else low
    hi = max(obs_hi, 1.5 * value) if high is None else high
    if not lo < value < hi:
        raise DesignerError(
            f"the {quantity} bounds {lo:g} to {hi:g} {unit} do not enclose the target {value:g} {unit}",
            "give bounds below and above the target",
        )
    return Target(quantity, float(value), float(lo), float(hi), float(importance))


@dataclass
class Candidate:
    """One design: the six print settings and the predicted k and c (`Prediction`s of floats)."""

    params: dict[str, float]
    predicted: dict[str, Prediction]
    desirability: float
    rel_error: dict[str, float]
    extrapolated: bool
    notes: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        return {
            "params": self.params,
            "predicted": {q: p.to_dict() for q, p in self.predicted.items()},
            "desirability": self.desirability,
            "rel_error": self.rel_error,
            "extrapolated": self.extrapolated,
            "notes": self.notes,
        }


@dataclass
class Suggestion:
    """The result of `suggest`: ranked candidates and plain statements about the targets."""

    axis: str
    targets: dict[str, Target]
    candidates: list[Candidate]
    reachable: bool
    statements: list[str]
    predictability: dict[str, dict[str, Any]]
    surrogate_id: str
    fixed: dict[str, float]

    def to_dict(self) -> dict[str, Any]:
        return {
            "axis": self.axis,
            "units": {q: units.rig_unit(q, self.axis) for q in ("k", "c")},
            "targets": {q: (self.targets[q].value if q in self.targets else None) for q in ("k", "c")},
            "desirability_bounds": {
                q: {"low": t.low, "high": t.high, "importance": t.importance} for q, t in self.targets.items()
            },
            "fixed": self.fixed,
            "reachable": self.reachable,
            "statements": self.statements,
            "predictability": self.predictability,
            "surrogate_id": self.surrogate_id,
            "candidates": [c.to_dict() for c in self.candidates],
        }

    @classmethod
    def from_dict(cls, d: Mapping[str, Any], *, where: str = "suggestion") -> Suggestion:
        """Read back `to_dict` output (a `designer suggest --json` file); DesignerError when malformed."""
        try:
            axis = units.check_axis(d["axis"])
            bounds = d.get("desirability_bounds") or {}
            targets = {
                q: Target(
                    q,
                    float(v),
                    float(bounds.get(q, {}).get("low", 0.0)),
                    float(bounds.get(q, {}).get("high", np.inf)),
                    float(bounds.get(q, {}).get("importance", 1.0)),
                )
                for q, v in d["targets"].items()
                if v is not None
            }
            candidates = [
                Candidate(
                    params=dict(c["params"]),
                    predicted={
                        q: Prediction.from_dict(p, where=f"{where} candidate {i + 1} {q}")
                        for q, p in c["predicted"].items()
                    },
                    desirability=float(c["desirability"]),
                    rel_error=dict(c.get("rel_error", {})),
                    extrapolated=bool(c.get("extrapolated", False)),
                    notes=list(c.get("notes", [])),
                )
                for i, c in enumerate(d["candidates"])
            ]
            return cls(
                axis,
                targets,
                candidates,
                bool(d.get("reachable", True)),
                list(d.get("statements", [])),
                dict(d.get("predictability", {})),
                str(d.get("surrogate_id", "")),
                dict(d.get("fixed", {})),
            )
        except (KeyError, TypeError, ValueError, AttributeError) as exc:
            raise DesignerError(
                f"{where} is not a suggestion (missing or malformed {exc})",
                "use the output of designer.suggest(...).to_dict()",
            ) from None

    @classmethod
    def load(cls, path: str | Path) -> Suggestion:
        """Read a suggestion saved as JSON; DesignerError naming `path` when it cannot be read."""
        import json

        path = Path(path)
        try:
            data = json.loads(path.read_text())
        except (OSError, ValueError) as exc:
            raise DesignerError(
                f"cannot read a suggestion from path={str(path)!r}: {exc}",
                "give a JSON file written from Suggestion.to_dict()",
            ) from None
        if not isinstance(data, dict):
            raise DesignerError(
                f"{path.name} is not a suggestion", "give a JSON file written from Suggestion.to_dict()"
            )
        return cls.from_dict(data, where=path.name)


class _Problem:
    """One IPOPT problem over the coded continuous factors, categorical levels and targets as parameters."""

    def __init__(self, surrogate: Surrogate, axis: str, targets: Mapping[str, Target]) -> None:
        self.responses = {q: surrogate.model(f"{q}_{axis}") for q in ("k", "c")}
        self.functions = {q: m.casadi_function() for q, m in self.responses.items()}
        u = ca.SX.sym("u", len(space.CONTINUOUS))  # continuous factors scaled to [0, 1] of the range
        cat = ca.SX.sym("cat", len(space.CATEGORICAL))
        lows = ca.SX.sym("lows", len(space.CONTINUOUS))
        spans = ca.SX.sym("spans", len(space.CONTINUOUS))
        goal = ca.SX.sym("goal", 2)  # targets for k and c
        weight = ca.SX.sym("weight", 2)  # importance / scale^2, zero for an absent or unpredictable response
        x = ca.vertcat(lows + spans * u, cat)  # factor order: continuous first, then layer, raster
        cost = 0
        for i, q in enumerate(("k", "c")):
            value, lo, hi = self.functions[q](x)
            cost += weight[i] * ((value - goal[i]) ** 2 + PI_WEIGHT * (hi - lo) ** 2)
        self._u, self._x = u, x
        self._box = ca.vertcat(cat, lows, spans)
        self.solver = ca.nlpsol(
            "suggest", "ipopt", {"x": u, "p": ca.vertcat(self._box, goal, weight), "f": cost}, _IPOPT
        )

    def extreme_solver(self, q: str) -> ca.Function:
        """IPOPT minimising sign * predicted value of one response (sign is the last parameter)."""
        sign = ca.SX.sym("sign")
        value = self.functions[q](self._x)[0]
        nlp = {"x": self._u, "p": ca.vertcat(self._box, sign), "f": sign * value}
        return ca.nlpsol(f"extreme_{q}", "ipopt", nlp, _IPOPT)

    def solve(self, u0: np.ndarray, ubounds: tuple[np.ndarray, np.ndarray], p: np.ndarray) -> np.ndarray:
        sol = self.solver(x0=u0, lbx=ubounds[0], ubx=ubounds[1], p=p)
        return np.asarray(sol["x"]).ravel()


def _starts(n: int, dim: int) -> np.ndarray:
    """The centre and n - 1 fixed pseudo-random points of the unit box (deterministic results)."""
    rng = np.random.default_rng(20251122)
    return np.vstack([np.full(dim, 0.5), rng.uniform(0.05, 0.95, size=(n - 1, dim))])


def _distance(a: Mapping[str, float], b: Mapping[str, float], spans: Mapping[str, float]) -> float:
    cont = [(a[f.name] - b[f.name]) / spans[f.name] for f in space.CONTINUOUS]
    cat = [float(not np.isclose(a[f.name], b[f.name])) for f in space.CATEGORICAL]
    return float(np.sqrt(np.sum(np.square(cont)) + np.sum(cat)))


def predictability(surrogate: Surrogate, axis: str) -> dict[str, dict[str, Any]]:
    """Per response: LOO Q2, form, and a plain statement of how much of it the data explains."""
    out = {}
    for q in ("k", "c"):
        m = surrogate.model(f"{q}_{axis}")
        q2 = m.loo["q2"]
        if not m.predictable:
            text = (
                f"{q}_{axis} is not predictable from the six factors: no form beats the mean of the "
                f"runs under leave-one-out (Q2 = {q2:.2f}); every design gets the same prediction"
            )
        else:
            text = (
                f"{q}_{axis}: the factors explain about {100 * q2:.0f} % of its variation "
                f"(leave-one-out Q2 = {q2:.2f}, {m.form} form); the 95 % PIs show the rest"
            )
        out[q] = {"q2": q2, "form": m.form, "predictable": m.predictable, "statement": text}
    return out


def suggest(
    surrogate: Surrogate,
    k: float | None = None,
    c: float | None = None,
    axis: str = "x",
    fixed: Mapping[str, float] | None = None,
    top: int = 5,
    importance: Mapping[str, float] | None = None,
    bounds: Mapping[str, tuple[float | None, float | None]] | None = None,
    allow_extrapolation: bool = False,
) -> Suggestion:
    """Ranked printable designs whose predicted k and/or c (rig units) hit the targets."""
    units.check_axis(axis)
    if axis not in surrogate.axes:
        raise DesignerError(
            f"the surrogate has no axis '{axis}'",
            f"it has {', '.join(surrogate.axes) or 'none'}; "
            "fit one on a table with that axis: Surrogate().fit(table)",
        )
    if k is None and c is None:
        raise DesignerError("no target given", "give k= and/or c=")
    if top < 1:
        raise DesignerError(f"top={top} must be at least 1", "give a positive number of candidates")
    importance = importance or {}
    bounds = bounds or {}
    targets = {
        q: make_target(surrogate, q, axis, v, importance.get(q, 1.0), *bounds.get(q, (None, None)))
        for q, v in (("k", k), ("c", c))
        if v is not None
    }
    fixed = {name: space.check_value(name, v, allow_extrapolation) for name, v in (fixed or {}).items()}
    pred_info = predictability(surrogate, axis)

    ranges = {
        f.name: (_extended_range(f) if allow_extrapolation else (f.low, f.high)) for f in space.CONTINUOUS
    }
    lows = np.array([ranges[f.name][0] for f in space.CONTINUOUS])
    spans = np.array([ranges[f.name][1] - ranges[f.name][0] for f in space.CONTINUOUS])
    lbu, ubu = np.zeros(len(lows)), np.ones(len(lows))
    for i, f in enumerate(space.CONTINUOUS):
        if f.name in fixed:
            lbu[i] = ubu[i] = (fixed[f.name] - lows[i]) / spans[i]
    weights = np.array(
        [
            (targets[q].importance / (targets[q].high - targets[q].low) ** 2)
            if q in targets and pred_info[q]["predictable"]
            else 0.0
            for q in ("k", "c")
        ]
    )
    goal = np.array([targets[q].value if q in targets else 1.0 for q in ("k", "c")])
    problem = _Problem(surrogate, axis, targets)
    combos = [
        combo
        for combo in itertools.product(*[f.levels for f in space.CATEGORICAL])
        if all(np.isclose(fixed.get(f.name, lv), lv) for f, lv in zip(space.CATEGORICAL, combo, strict=True))
    ]

    raw: list[dict[str, float]] = []
    starts = _starts(N_STARTS, len(lows))
    for combo in combos:
        p = np.concatenate([combo, lows, spans, goal, weights])
        for u0 in starts:
            u = problem.solve(np.clip(u0, lbu, ubu), (lbu, ubu), p)
            design = dict(zip([f.name for f in space.CONTINUOUS], lows + spans * u, strict=True))
            design.update(zip([f.name for f in space.CATEGORICAL], combo, strict=True))
            design.update({n: v for n, v in fixed.items() if n in design})
            raw.append(space.round_printable(design))

    span_of = {f.name: float(s) for f, s in zip(space.CONTINUOUS, spans, strict=True)}
    picked: list[Candidate] = []
    for cand in _rank(surrogate, axis, raw, targets):
        if all(_distance(cand.params, other.params, span_of) > DISTINCT for other in picked):
            picked.append(cand)
        if len(picked) == top:
            break

    statements, reachable = _statements(
        surrogate,
        axis,
        targets,
        picked[0],
        pred_info,
        problem,
        combos,
        (lows, spans, lbu, ubu),
        allow_extrapolation,
    )
    return Suggestion(axis, targets, picked, reachable, statements, pred_info, surrogate.id, fixed)


def _rank(
    surrogate: Surrogate,
    axis: str,
    designs: list[dict[str, float]],
    targets: Mapping[str, Target],
) -> list[Candidate]:
    """Predict each design, score it, and sort by desirability, then by the narrower k interval."""
    cols = {n: np.array([d[n] for d in designs]) for n in space.FACTOR_NAMES}
    preds = surrogate.predict(cols, responses=[f"k_{axis}", f"c_{axis}"], allow_extrapolation=True)
    out = []
    for i, design in enumerate(designs):
        predicted, rel_error, ds, ws = {}, {}, [], []
        for q in ("k", "c"):
            p = preds[f"{q}_{axis}"]
            predicted[q] = p.at(i)
            if q in targets:
                t = targets[q]
                rel_error[q] = float((p.value[i] - t.value) / t.value)
                ds.append(t.desirability(float(p.value[i])))
                ws.append(t.importance)
        desirability = float(np.prod(np.power(ds, np.array(ws) / np.sum(ws)))) if ds else 0.0
        extrapolated = any(not (f.low - 1e-9 <= design[f.name] <= f.high + 1e-9) for f in space.CONTINUOUS)
        notes = space.printability_notes(design)
        if extrapolated:
            notes.append("outside the tested ranges: the prediction is an extrapolation")
        out.append(Candidate(design, predicted, desirability, rel_error, extrapolated, notes))

    def k_width(c: Candidate) -> float:
        k = c.predicted["k"]
        return float(np.log(k.high / k.low))

    return sorted(out, key=lambda c: (-round(c.desirability, 6), k_width(c)))


def _statements(
    surrogate: Surrogate,
    axis: str,
    targets: Mapping[str, Target],
    best: Candidate,
    pred_info: Mapping[str, Mapping[str, Any]],
    problem: _Problem,
    combos: list[tuple[float, ...]],
    box: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
    allow_extrapolation: bool,
) -> tuple[list[str], bool]:
    """Plain statements on each target: hit, out of reach (with the reachable range), or unpredictable."""
    statements, reachable = [], True
    for q, t in targets.items():
        unit = units.rig_unit(q, axis)
        model = surrogate.model(f"{q}_{axis}")
        obs_lo, obs_hi = model.observed_range
        if not pred_info[q]["predictable"]:
            p = best.predicted[q]
            inside = "lies inside" if p.low <= t.value <= p.high else "lies outside"
            statements.append(
                f"{q} = {t.value:g} {unit}: {pred_info[q]['statement']} "
                f"({p.value:.3g} {unit}, 95 % PI {p.low:.3g} to {p.high:.3g} {unit}); "
                f"the target {inside} that interval, so no setting can be chosen for it from this data"
            )
            continue
        if not obs_lo <= t.value <= obs_hi:
            statements.append(
                f"{q} = {t.value:g} {unit} lies outside the measured range of {q}_{axis} "
                f"({obs_lo:.3g} to {obs_hi:.3g} {unit}): the data does not support it"
            )
        if abs(best.rel_error[q]) <= HIT_TOLERANCE:
            statements.append(
                f"{q} = {t.value:g} {unit} is reached: predicted {best.predicted[q].value:.4g} {unit} "
                f"({100 * best.rel_error[q]:+.2f} %)"
            )
            continue
        reachable = False
        lo_r, hi_r = _reachable_range(problem, q, combos, box)
        where = "the tested ranges" if not allow_extrapolation else "the extended ranges"
        statements.append(
            f"{q} = {t.value:g} {unit} is out of reach: within {where} the surrogate predicts "
            f"{q}_{axis} from {lo_r:.3g} to {hi_r:.3g} {unit}; the candidates below are the nearest "
            f"designs (best {best.predicted[q].value:.3g} {unit}, {100 * best.rel_error[q]:+.1f} %)"
        )
    return statements, reachable


def _reachable_range(
    problem: _Problem, q: str, combos: list[tuple[float, ...]], box: tuple[np.ndarray, ...]
) -> tuple[float, float]:
    """Smallest and largest predicted value of one response over the search box (IPOPT, per combo)."""
    lows, spans, lbu, ubu = box
    solver, f = problem.extreme_solver(q), problem.functions[q]
    values = []
    for combo in combos:
        for sign in (1.0, -1.0):
            sol = solver(
                x0=np.clip(0.5, lbu, ubu), lbx=lbu, ubx=ubu, p=np.concatenate([combo, lows, spans, [sign]])
            )
            u = np.asarray(sol["x"]).ravel()
            values.append(float(f(np.concatenate([lows + spans * u, combo]))[0]))
    return min(values), max(values)
