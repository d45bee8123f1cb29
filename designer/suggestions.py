"""Inverse design: printable settings for goals on k and c, ranked by the chance of meeting them.

The engineering standard of response optimisers (Minitab Response Optimizer, JMP Profiler): per
response a goal (a target value, or min or max) with Derringer-Suich desirability bounds, weight and
importance; the importance-weighted geometric mean of the predictable responses' desirabilities as
the composite D; and a multi-start IPOPT search (CasADi ``nlpsol``) over the continuous factors for
every combination of the categorical levels. IPOPT minimises a smooth surrogate of the goals
(squared deviation from a target, the predicted value itself for min or max, plus a small term on
the prediction interval); the candidates, rounded to printable values, are ranked by the
probability that a printed joint lands within a tolerance of the target (`probability_within`),
then by D.
"""

from __future__ import annotations

import functools
import itertools
import math
import numbers
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import casadi as ca
import numpy as np

from . import space, units
from .errors import DesignerError, check_type, describe, number_argument
from .surrogate import Prediction, Surrogate, check_surrogate

#: default tolerance around a target within which a printed joint counts as meeting it
TOLERANCE = 0.10
#: weight of the (normalised) squared PI width in the objective: a tie-breaker only
PI_WEIGHT = 1e-3
#: IPOPT starts in all (the centre, then fixed pseudo-random points), shared among the categorical
#: combinations left free, at least 2 each: 12 solves of ~5 ms when all 6 are searched
N_STARTS = 12
#: designs closer than this in normalised factor space are the same design
DISTINCT = 0.05
#: measured runs listed when a target lies between the predicted and the measured range
N_NEAREST_RUNS = 3
_IPOPT = {
    "ipopt.print_level": 0,
    "print_time": False,
    "ipopt.sb": "yes",
    "ipopt.tol": 1e-9,
    "ipopt.max_iter": 300,
    "error_on_fail": False,
}
KINDS = ("target", "min", "max")


def student_t_cdf(x: float, dof: float) -> float:
    """P(T <= x) for Student's t with `dof` degrees of freedom (dof > 0, not necessarily whole).

    Through the regularised incomplete beta function: for x > 0,
    P(T <= x) = 1 - I_{dof / (dof + x^2)}(dof / 2, 1 / 2) / 2, and symmetric for x < 0; I is
    evaluated by its continued fraction (modified Lentz), accurate to about 1e-14.
    """
    if math.isinf(x):
        return 1.0 if x > 0 else 0.0
    tail = 0.5 * _betainc(dof / 2, 0.5, dof / (dof + x * x))
    return 1.0 - tail if x > 0 else tail


def _betainc(a: float, b: float, x: float) -> float:
    """The regularised incomplete beta function I_x(a, b) for 0 <= x <= 1."""
    if x <= 0.0:
        return 0.0
    if x >= 1.0:
        return 1.0
    front = math.exp(
        math.lgamma(a + b) - math.lgamma(a) - math.lgamma(b) + a * math.log(x) + b * math.log1p(-x)
    )
    if x < (a + 1) / (a + b + 2):
        return front * _beta_fraction(a, b, x) / a
    return 1.0 - front * _beta_fraction(b, a, 1 - x) / b


def _beta_fraction(a: float, b: float, x: float) -> float:
    """The continued fraction of I_x(a, b), modified Lentz (Numerical Recipes, 6.4)."""
    tiny = 1e-300
    c, d = 1.0, 1.0 - (a + b) * x / (a + 1)
    d = 1.0 / (d if abs(d) > tiny else tiny)
    h = d
    for m in range(1, 500):
        for num in (
            m * (b - m) * x / ((a + 2 * m - 1) * (a + 2 * m)),
            -(a + m) * (a + b + m) * x / ((a + 2 * m) * (a + 2 * m + 1)),
        ):
            d = 1.0 + num * d
            d = 1.0 / (d if abs(d) > tiny else tiny)
            c = 1.0 + num / c
            c = c if abs(c) > tiny else tiny
            h *= d * c
        if abs(d * c - 1.0) < 1e-15:
            break
    return h


def probability_within(
    prediction: Prediction, target: float, tolerance: float, dof: float, *, log: bool = True
) -> float:
    """Probability that a printed joint's response lies within +-tolerance (relative) of `target`.

    The surrogate's predictive distribution is a Student t in its fit space g(y) (g = log for the
    power law, `log=True`; the identity otherwise): g(Y) = mu + s T_dof, whose 95 % interval is the
    prediction's (low, high) = g^-1(mu -+ t95 s), t95 the 0.975 quantile of t with `dof`. So
    mu = g(value), s = (g(high) - g(low)) / (2 t95), and

        P = F_dof((g(target (1 + tolerance)) - mu) / s) - F_dof((g(target (1 - tolerance)) - mu) / s)

    with F_dof the t CDF (`student_t_cdf`) and the lower term 0 when target (1 - tolerance) <= 0
    under the log. `dof` is the fitted surface's `dof` in the surrogate JSON; `value`, `low` and
    `high` are the prediction's, in rig units. Returns a float in [0, 1].
    """
    g = math.log if log else (lambda v: v)
    t95 = _t_quantile(dof)
    mu = g(float(prediction.value))
    s = (g(float(prediction.high)) - g(float(prediction.low))) / (2 * t95)
    hi_edge, lo_edge = target * (1 + tolerance), target * (1 - tolerance)
    upper = student_t_cdf((g(hi_edge) - mu) / s, dof)
    lower = 0.0 if (log and lo_edge <= 0) else student_t_cdf((g(lo_edge) - mu) / s, dof)
    return max(0.0, min(1.0, upper - lower))


@functools.lru_cache(maxsize=64)
def _t_quantile(dof: float, p: float = 0.975) -> float:
    """The p quantile of Student's t by bisection on `student_t_cdf` (no scipy at suggest time)."""
    lo, hi = 0.0, 1e3
    for _ in range(200):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if student_t_cdf(mid, dof) < p else (lo, mid)
        if hi - lo < 1e-13:
            break
    return (lo + hi) / 2


@dataclass(frozen=True)
class Target:
    """A goal on one response: a target value, or min or max, with Derringer-Suich bounds.

    `low`, `high`: where the desirability reaches 0 (and 1 for min/max); `weight`: the shape
    exponent (1 linear, > 1 insists on closeness); `importance`: its share in the composite.
    """

    quantity: str  # "k" or "c"
    value: float | None  # the target for kind "target", None for min and max
    low: float
    high: float
    importance: float = 1.0
    kind: str = "target"
    weight: float = 1.0

    def desirability(self, y: float) -> float:
        """Derringer-Suich desirability of a predicted value: 1 at the goal, 0 at or past a bound."""
        if self.kind == "max":
            return float(np.clip((y - self.low) / (self.high - self.low), 0, 1) ** self.weight)
        if self.kind == "min":
            return float(np.clip((self.high - y) / (self.high - self.low), 0, 1) ** self.weight)
        if y <= self.low or y >= self.high:
            return 0.0
        side = (
            (y - self.low) / (self.value - self.low)
            if y <= self.value
            else (self.high - y) / (self.high - self.value)
        )
        return float(side**self.weight)

    def to_dict(self) -> dict[str, Any]:
        return {
            "kind": self.kind,
            "value": self.value,
            "low": self.low,
            "high": self.high,
            "weight": self.weight,
            "importance": self.importance,
        }


def make_target(
    surrogate: Surrogate,
    quantity: str,
    axis: str,
    goal: float | str,
    importance: float = 1.0,
    low: float | None = None,
    high: float | None = None,
    weight: float = 1.0,
) -> Target:
    """A goal (a number, "min" or "max") with bounds defaulting to the measured range of the response.

    A target outside that range widens the violated bound to half (or 1.5 times) the target, so
    the ranking still works; `suggest` states that the target lies outside what the data supports.
    """
    unit = units.rig_unit(quantity, axis)
    for name, v in (("importance", importance), ("weight", weight)):
        if not np.isfinite(v) or v <= 0:
            raise DesignerError(
                f"{name} of {quantity} = {v:g} must be positive", f"give {name}={{'{quantity}': 1.0}}"
            )
    obs_lo, obs_hi = surrogate.model(f"{quantity}_{axis}").observed_range
    if isinstance(goal, str):
        kind = goal.strip().lower()
        if kind not in ("min", "max"):
            raise DesignerError(
                f"goal {quantity}={goal!r} is not a number, 'min' or 'max'",
                f"give {quantity}=0.8 or {quantity}='max'",
            )
        value = None
        lo, hi = (obs_lo if low is None else low), (obs_hi if high is None else high)
    else:
        kind, value = "target", number_argument(goal, quantity)
        if not np.isfinite(value) or value <= 0:
            raise DesignerError(f"target {quantity} = {value:g} {unit} must be positive", "give a value > 0")
        if value > 1e6 * obs_hi:  # the desirability scale (bounds squared) would overflow
            raise DesignerError(
                f"target {quantity} = {value:g} {unit} is over a million times the largest measured, "
                f"{obs_hi:.3g} {unit}",
                "give a target near the data's range",
            )
        lo = min(obs_lo, 0.5 * value) if low is None else low
        hi = max(obs_hi, 1.5 * value) if high is None else high
    if not (lo < hi and (value is None or lo < value < hi)):
        raise DesignerError(
            f"the {quantity} bounds {lo:g} to {hi:g} {unit} do not enclose the goal {value or kind}",
            "give a lower bound below the upper (and the target between them)",
        )
    return Target(quantity, value, float(lo), float(hi), float(importance), kind, float(weight))


@dataclass
class Candidate:
    """One design: the six print settings, the predicted k and c, and how well it meets the goals.

    `p_within`: probability that a printed joint meets every predictable target within the
    tolerance (None without such a target); `probability`: the same per response with a target;
    `desirability`: composite D over the predictable responses (None without one); `any`: factors
    with no effect on this design (density when the walls fill the section; `params` then holds the
    value predicted with, 100 % = solid); `extrapolated`: factors outside their tested range.
    """

    params: dict[str, float]
    predicted: dict[str, Prediction]
    desirability: float | None
    rel_error: dict[str, float]
    extrapolated: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    p_within: float | None = None
    probability: dict[str, float] = field(default_factory=dict)
    any: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        return {
            "params": self.params,
            "any": self.any,
            "predicted": {q: p.to_dict() for q, p in self.predicted.items()},
            "p_within": self.p_within,
            "probability": self.probability,
            "desirability": self.desirability,
            "rel_error": self.rel_error,
            "extrapolated": self.extrapolated,
            "notes": self.notes,
        }

    @classmethod
    def from_dict(cls, c: Mapping[str, Any], *, where: str) -> Candidate:
        extra = c.get("extrapolated", [])
        return cls(
            params=space.check_design(c["params"], allow_extrapolation=True),
            predicted={q: Prediction.from_dict(p, where=f"{where} {q}") for q, p in c["predicted"].items()},
            desirability=None if c.get("desirability") is None else float(c["desirability"]),
            rel_error=dict(c.get("rel_error", {})),
            extrapolated=list(extra) if isinstance(extra, list) else (["unknown"] if extra else []),
            notes=list(c.get("notes", [])),
            p_within=None if c.get("p_within") is None else float(c["p_within"]),
            probability=dict(c.get("probability", {})),
            any=list(c.get("any", [])),
        )


@dataclass
class Suggestion:
    """The result of `suggest`: ranked candidates and plain statements about the goals."""

    axis: str
    targets: dict[str, Target]
    candidates: list[Candidate]
    reachable: bool
    statements: list[str]
    predictability: dict[str, dict[str, Any]]
    surrogate_id: str
    fixed: dict[str, float]
    tolerance: float = TOLERANCE
    #: per response with a goal: {"measured": [lo, hi], "predicted": [lo, hi] or None (not computed)}
    ranges: dict[str, dict[str, Any]] = field(default_factory=dict)
    #: measured runs nearest a target the surrogate cannot reach but the data has seen
    nearest_runs: list[dict[str, Any]] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        def goal(q: str) -> Any:
            t = self.targets.get(q)
            return None if t is None else (t.value if t.kind == "target" else t.kind)

        return {
            "axis": self.axis,
            "units": {q: units.rig_unit(q, self.axis) for q in ("k", "c")},
            "targets": {q: goal(q) for q in ("k", "c")},
            "goals": {q: t.to_dict() for q, t in self.targets.items()},
            "tolerance": self.tolerance,
            "fixed": self.fixed,
            "reachable": self.reachable,
            "statements": self.statements,
            "predictability": self.predictability,
            "ranges": self.ranges,
            "nearest_runs": self.nearest_runs,
            "surrogate_id": self.surrogate_id,
            "candidates": [c.to_dict() for c in self.candidates],
        }

    @classmethod
    def from_dict(cls, d: Mapping[str, Any], *, where: str = "suggestion") -> Suggestion:
        """Read back `to_dict` output (a `designer suggest --json` file); DesignerError when malformed."""
        _check_schema(d, where)
        try:
            axis = units.check_axis(d["axis"])
            goals = d.get("goals") or {
                q: {"kind": "target", "value": v, "low": 0.0, "high": math.inf}
                for q, v in d["targets"].items()
                if v is not None
            }
            targets = {
                q: Target(
                    q,
                    None if g.get("value") is None else float(g["value"]),
                    float(g.get("low", 0.0)),
                    float(g.get("high", math.inf)),
                    float(g.get("importance", 1.0)),
                    str(g.get("kind", "target")),
                    float(g.get("weight", 1.0)),
                )
                for q, g in goals.items()
            }
            candidates = [
                Candidate.from_dict(c, where=f"{where} candidate {i + 1}")
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
                float(d.get("tolerance", TOLERANCE)),
                dict(d.get("ranges", {})),
                list(d.get("nearest_runs", [])),
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
            data = json.loads(path.read_text(encoding="utf-8-sig"))  # a BOM (Windows editors) is fine
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


_SUGGESTION_KEYS = (
    "axis", "units", "targets", "goals", "tolerance", "fixed", "reachable", "statements", "predictability",
    "ranges", "nearest_runs", "surrogate_id", "candidates", "desirability_bounds",
)  # fmt: skip
_CANDIDATE_KEYS = (
    "params", "any", "predicted", "p_within", "probability", "desirability", "rel_error", "extrapolated",
    "notes",
)  # fmt: skip


def _check_schema(d: Any, where: str) -> None:
    """The keys of a suggestion dict: required ones present, none unknown (with the closest valid one)."""
    from .keys import check_keys

    fix = "use the output of designer.suggest(...).to_dict() (designer suggest --json)"
    if not isinstance(d, Mapping):
        raise DesignerError(f"{where} is not a suggestion (a JSON {type(d).__name__}, not an object)", fix)
    missing = [k for k in ("axis", "targets", "candidates") if k not in d]
    if missing:
        has = ", ".join(f"'{k}'" for k in list(d)[:6]) or "nothing"
        absent = ", ".join(map(repr, missing))
        raise DesignerError(f"{where} is not a suggestion: no {absent} (it has {has})", fix)
    check_keys(d, _SUGGESTION_KEYS, where=where)
    _check_types(d, _SUGGESTION_TYPES, where, fix)
    if not isinstance(d["candidates"], list) or not d["candidates"]:
        raise DesignerError(f"{where}: 'candidates' is not a non-empty list", fix)
    for i, c in enumerate(d["candidates"], 1):
        if not isinstance(c, Mapping) or "params" not in c or "predicted" not in c:
            raise DesignerError(f"{where}: candidate {i} has no 'params' and 'predicted'", fix)
        check_keys(c, _CANDIDATE_KEYS, where=f"candidate {i} of {where}")
        _check_types(c, _CANDIDATE_TYPES, f"candidate {i} of {where}", fix)
        for name, v in c["params"].items():  # float() would take "60" and true (1 %) silently
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                raise DesignerError(
                    f"candidate {i} of {where}: {name} = {json_text(v)} is {describe(v)}, not a number",
                    "write the number without quotes, e.g. 60",
                )


#: the JSON types of a suggestion's entries (hand-edited files: "targets": [0.8], "axis": 3)
_SUGGESTION_TYPES = {
    "axis": str, "units": dict, "targets": dict, "goals": dict, "tolerance": (int, float), "fixed": dict,
    "reachable": bool, "statements": list, "predictability": dict, "ranges": dict, "nearest_runs": list,
    "surrogate_id": str, "candidates": list,
}  # fmt: skip
_CANDIDATE_TYPES = {
    "params": dict, "any": list, "predicted": dict, "p_within": (int, float, type(None)),
    "probability": dict, "desirability": (int, float, type(None)), "rel_error": dict,
    "extrapolated": (list, bool), "notes": list,
}  # fmt: skip
_JSON_NAMES = {str: "a string", dict: "an object", list: "a list", bool: "true or false", int: "a number"}


def _check_types(d: Mapping[str, Any], types: Mapping[str, Any], where: str, fix: str) -> None:
    """Raise for the first entry of `d` whose JSON type is not the one `types` gives."""
    for key, want in types.items():
        if key not in d:
            continue
        v = d[key]
        wants = want if isinstance(want, tuple) else (want,)
        numeric = float in wants or int in wants
        if not isinstance(v, wants) or (isinstance(v, bool) and bool not in wants and numeric):
            expected = " or ".join(dict.fromkeys(_JSON_NAMES.get(t, "null") for t in wants))
            raise DesignerError(f"{where}: '{key}' is {json_text(v)}, not {expected}", fix)


def json_text(v: Any) -> str:
    """A JSON value as written in the file, shortened: 3, "x", [0.8], {...}."""
    import json

    text = json.dumps(v, default=str)
    return text if len(text) <= 40 else text[:37] + "..."


class _Problem:
    """One IPOPT problem over the coded continuous factors; levels, box and goals as parameters.

    The cost per response q is wsq_q (value - goal_q)^2 + wlin_q value + wpi_q (high - low)^2:
    a target sets wsq, min a positive and max a negative wlin; zero weights switch a response off.
    """

    def __init__(self, surrogate: Surrogate, axis: str) -> None:
        self.functions = {q: surrogate.model(f"{q}_{axis}").casadi_function() for q in ("k", "c")}
        n_cont = len(space.CONTINUOUS)
        u = ca.SX.sym("u", n_cont)  # continuous factors scaled to [0, 1] of the search box
        cat = ca.SX.sym("cat", len(space.CATEGORICAL))
        lows, spans = ca.SX.sym("lows", n_cont), ca.SX.sym("spans", n_cont)
        goal, wsq, wlin, wpi = (ca.SX.sym(name, 2) for name in ("goal", "wsq", "wlin", "wpi"))
        x = ca.vertcat(lows + spans * u, cat)  # factor order: continuous first, then layer, raster
        cost = 0
        for i, q in enumerate(("k", "c")):
            value, lo, hi = self.functions[q](x)
            cost += wsq[i] * (value - goal[i]) ** 2 + wlin[i] * value + wpi[i] * (hi - lo) ** 2
        self._u, self._x = u, x
        self._box = ca.vertcat(cat, lows, spans)
        p = ca.vertcat(self._box, goal, wsq, wlin, wpi)
        self.solver = ca.nlpsol("suggest", "ipopt", {"x": u, "p": p, "f": cost}, _IPOPT)

    def extreme_solver(self, q: str) -> ca.Function:
        """IPOPT minimising sign * predicted value of one response (sign is the last parameter)."""
        sign = ca.SX.sym("sign")
        value = self.functions[q](self._x)[0]
        nlp = {"x": self._u, "p": ca.vertcat(self._box, sign), "f": sign * value}
        return ca.nlpsol(f"extreme_{q}", "ipopt", nlp, _IPOPT)

    def solve(self, u0: np.ndarray, ubounds: tuple[np.ndarray, np.ndarray], p: np.ndarray) -> np.ndarray:
        sol = self.solver(x0=u0, lbx=ubounds[0], ubx=ubounds[1], p=p)
        return np.asarray(sol["x"]).ravel()


@dataclass(frozen=True)
class _Box:
    """The search box of the continuous factors (rig units) and the categorical combinations."""

    lows: np.ndarray
    spans: np.ndarray
    lbu: np.ndarray  # bounds of the coded factors, [0, 1], equal where a factor is fixed
    ubu: np.ndarray
    combos: list[tuple[float, ...]]
    extrapolate: bool

    def design(self, u: np.ndarray, combo: tuple[float, ...]) -> dict[str, float]:
        design = dict(zip([f.name for f in space.CONTINUOUS], self.lows + self.spans * u, strict=True))
        return design | dict(zip([f.name for f in space.CATEGORICAL], combo, strict=True))


def _box(fixed: Mapping[str, float], allow_extrapolation: bool) -> _Box:
    ranges = [space.extended_range(f) if allow_extrapolation else (f.low, f.high) for f in space.CONTINUOUS]
    lows = np.array([r[0] for r in ranges])
    spans = np.array([r[1] - r[0] for r in ranges])
    lbu, ubu = np.zeros(len(lows)), np.ones(len(lows))
    for i, f in enumerate(space.CONTINUOUS):
        if f.name in fixed:
            lbu[i] = ubu[i] = (fixed[f.name] - lows[i]) / spans[i]
    combos = [
        combo
        for combo in itertools.product(*[f.levels for f in space.CATEGORICAL])
        if all(np.isclose(fixed.get(f.name, lv), lv) for f, lv in zip(space.CATEGORICAL, combo, strict=True))
    ]
    return _Box(lows, spans, lbu, ubu, combos, allow_extrapolation)


def _starts(n: int, dim: int) -> np.ndarray:
    """The centre and n - 1 fixed pseudo-random points of the unit box (deterministic results)."""
    rng = np.random.default_rng(20251122)
    return np.vstack([np.full(dim, 0.5), rng.uniform(0.05, 0.95, size=(n - 1, dim))])


def _distance(a: Mapping[str, float], b: Mapping[str, float], spans: Mapping[str, float]) -> float:
    """Distance in normalised factor space; density counts only where it changes both designs."""
    names = [
        f.name
        for f in space.CONTINUOUS
        if f.name != "density" or (space.infill_matters(a) and space.infill_matters(b))
    ]
    cont = [(a[n] - b[n]) / spans[n] for n in names]
    cat = [float(not np.isclose(a[f.name], b[f.name])) for f in space.CATEGORICAL]
    return float(np.sqrt(np.sum(np.square(cont)) + np.sum(cat)))


def predictability(surrogate: Surrogate, axis: str) -> dict[str, dict[str, Any]]:
    """Per response: nested LOO Q2, form, and a plain statement of how much of it the data explains."""
    out = {}
    for q in ("k", "c"):
        m = surrogate.model(f"{q}_{axis}")
        q2 = m.accuracy["q2"]
        label = "nested leave-one-out" if m.loo_nested else "leave-one-out"
        if not m.predictable:
            text = (
                f"{q}_{axis} is not predictable from the six factors: no form beats the mean of the "
                f"runs ({label} Q2 = {q2:.2f}); every design gets the same prediction"
            )
        else:
            text = (
                f"{q}_{axis}: the factors explain about {100 * max(q2, 0):.0f} % of its variation "
                f"({label} Q2 = {q2:.2f}, {m.form} form); the 95 % PIs show the rest"
            )
        out[q] = {"q2": q2, "form": m.form, "predictable": m.predictable, "dof": m.dof, "statement": text}
    return out


def suggest(
    surrogate: Surrogate,
    *,
    k: float | str | None = None,
    c: float | str | None = None,
    axis: str = "x",
    fixed: Mapping[str, float] | None = None,
    top: int = 5,
    importance: Mapping[str, float] | None = None,
    bounds: Mapping[str, tuple[float | None, float | None]] | None = None,
    weight: Mapping[str, float] | None = None,
    tolerance: float = TOLERANCE,
    allow_extrapolation: bool = False,
) -> Suggestion:
    """Ranked printable designs for goals on k and/or c (rig units) of one axis.

    Args:
        surrogate: the fitted surrogate (`Surrogate.load()` for the shipped one).
        k, c: a target value, "min" or "max"; None leaves that response free.
        axis: the surrogate's axis the goals are on.
        fixed: factors held at a value, e.g. {"width": 4.5}.
        top: how many distinct candidates to return (fewer are explained in `statements`).
        importance, bounds, weight: per response, the composite's importance, the desirability's
            (low, high) bounds (None: the measured range) and its shape exponent.
        tolerance: relative band around a target for `probability_within` (0.10 = +-10 %).
        allow_extrapolation: search half a range beyond the tested ranges, within printable limits.

    Returns:
        A `Suggestion`: candidates ranked by the probability of meeting the predictable targets
        within the tolerance, then by composite desirability; `reachable` False when the best
        candidate's predicted value misses a target by more than the tolerance.

    Raises:
        DesignerError: no goal, an unknown axis or factor, a fixed value out of range, a
            non-positive target, importance or weight, bounds not enclosing a target, top < 1, or
            tolerance not in (0, 1).
    """
    _check_request(surrogate, axis, k is None and c is None, top, tolerance)
    for name, value in (("fixed", fixed), ("importance", importance), ("bounds", bounds), ("weight", weight)):
        if value is not None:
            fix = f"give {name} as a dict, e.g. {name}={MAPPING_EXAMPLES[name]}"
            check_type(value, Mapping, name, expected="a mapping", fix=fix)
    importance, bounds, weight = importance or {}, bounds or {}, weight or {}
    targets = {
        q: make_target(
            surrogate, q, axis, v, importance.get(q, 1.0), *bounds.get(q, (None, None)), weight.get(q, 1.0)
        )
        for q, v in (("k", k), ("c", c))
        if v is not None
    }
    fixed = {name: space.check_value(name, v, allow_extrapolation) for name, v in (fixed or {}).items()}
    info = predictability(surrogate, axis)
    # a fixed width or height that leaves one nozzle line inside makes the infill irrelevant: solid
    thin = any(
        n in fixed and fixed[n] - 2 * space.WALL_MM <= space.NOZZLE_MM + 1e-9 for n in ("width", "height")
    )
    search_fixed = fixed | {"density": 100.0} if thin else fixed
    box = _box(search_fixed, allow_extrapolation)
    problem = _Problem(surrogate, axis)
    raw = _search(problem, box, targets, info, search_fixed)
    ranked = _rank(surrogate, axis, raw, targets, info, tolerance)
    spans = {f.name: float(s) for f, s in zip(space.CONTINUOUS, box.spans, strict=True)}
    picked: list[Candidate] = []
    for cand in ranked:
        if len(picked) < top and all(_distance(cand.params, o.params, spans) > DISTINCT for o in picked):
            picked.append(cand)
    sug = Suggestion(axis, targets, picked, True, [], info, surrogate.id, fixed, tolerance)
    _assess(sug, surrogate, problem, box)
    if len(picked) < top:
        sug.statements.append(
            f"{len(picked)} distinct design(s) instead of the {top} asked for: every start of the search "
            "ended at one of these" + (" (the fixed factors leave little to choose)" if fixed else "")
        )
    return sug


MAPPING_EXAMPLES = {
    "fixed": "{'width': 3.0}",
    "importance": "{'k': 2.0}",
    "bounds": "{'k': (0.5, 1.2)}",
    "weight": "{'k': 1.0}",
}


def _check_request(surrogate: Surrogate, axis: str, no_goal: bool, top: int, tolerance: float) -> None:
    """Raise DesignerError for an axis the surrogate lacks, no goal, top < 1 or a tolerance not in (0, 1)."""
    check_surrogate(surrogate)
    check_type(top, numbers.Integral, "top", expected="a whole number", fix="give e.g. top=5")
    number_argument(tolerance, "tolerance", example="0.1")
    units.check_axis(axis)
    if axis not in surrogate.axes:
        raise DesignerError(
            f"the surrogate has no axis '{axis}'",
            f"it has {', '.join(surrogate.axes) or 'none'}; "
            "fit one on a table with that axis: Surrogate().fit(table)",
        )
    if no_goal:
        raise DesignerError("no target given", "give k= and/or c= (a value, 'min' or 'max')")
    if top < 1:
        raise DesignerError(f"top={top} must be at least 1", "give a positive number of candidates")
    if not 0 < tolerance < 1:
        raise DesignerError(
            f"tolerance={tolerance:g} is not between 0 and 1", "give e.g. tolerance=0.1 (+-10 %)"
        )


def _weights(targets: Mapping[str, Target], info: Mapping[str, Mapping[str, Any]]) -> np.ndarray:
    """The NLP's goal and weight parameters [goal, wsq, wlin, wpi] for k and c; unpredictable: 0."""
    goal, wsq, wlin, wpi = np.ones(2), np.zeros(2), np.zeros(2), np.zeros(2)
    for i, q in enumerate(("k", "c")):
        t = targets.get(q)
        if t is None or not info[q]["predictable"]:
            continue
        scale = t.high - t.low
        wpi[i] = PI_WEIGHT * t.importance / scale**2
        if t.kind == "target":
            goal[i], wsq[i] = t.value, t.importance / scale**2
        else:
            wlin[i] = (1.0 if t.kind == "min" else -1.0) * t.importance / scale
    return np.concatenate([goal, wsq, wlin, wpi])


def _search(
    problem: _Problem,
    box: _Box,
    targets: Mapping[str, Target],
    info: Mapping[str, Mapping[str, Any]],
    fixed: Mapping[str, float],
) -> list[dict[str, float]]:
    """IPOPT from every start in every categorical combination; rounded, printable designs.

    Where the walls fill the section (2.0 mm width) the infill has no effect: the part prints
    solid. When a start ends there, that combination is searched again with width 2.0 mm and
    density 100 % held, so the optimum as printed is found, not the optimum of a tuned infill.
    """
    params = _weights(targets, info)
    names = [f.name for f in space.CONTINUOUS]
    iw, idens = names.index("width"), names.index("density")
    solid = box.lbu.copy(), box.ubu.copy()
    solid[0][iw] = solid[1][iw] = (space.PRINTABLE_MIN_MM - box.lows[iw]) / box.spans[iw]
    solid[0][idens] = solid[1][idens] = (100.0 - box.lows[idens]) / box.spans[idens]
    may_be_solid = "width" not in fixed and "density" not in fixed and 0 <= solid[0][iw] <= 1
    raw: list[dict[str, float]] = []
    for combo in box.combos:
        p = np.concatenate([combo, box.lows, box.spans, params])
        found = []
        for u0 in _starts(max(2, -(-N_STARTS // len(box.combos))), len(names)):
            u = problem.solve(np.clip(u0, box.lbu, box.ubu), (box.lbu, box.ubu), p)
            found.append(box.design(u, combo))
        if may_be_solid and not all(space.infill_matters(space.round_printable(d)) for d in found):
            found.append(box.design(problem.solve(np.clip(0.5, *solid), solid, p), combo))
        held = {n: v for n, v in fixed.items() if n in names}
        raw += [_solid(space.round_printable(d | held)) for d in found]
    return raw


def _solid(design: dict[str, float]) -> dict[str, float]:
    """Where infill has no effect the part prints solid: predict it at 100 % density."""
    return design if space.infill_matters(design) else design | {"density": 100.0}


def _rank(
    surrogate: Surrogate,
    axis: str,
    designs: list[dict[str, float]],
    targets: Mapping[str, Target],
    info: Mapping[str, Mapping[str, Any]],
    tolerance: float,
) -> list[Candidate]:
    """Predict and score each design; sort by P(within tolerance), then D, then the narrower k PI."""
    cols = {n: np.array([d[n] for d in designs]) for n in space.FACTOR_NAMES}
    preds = surrogate.predict(cols, responses=[f"k_{axis}", f"c_{axis}"], allow_extrapolation=True)
    models = {q: surrogate.model(f"{q}_{axis}") for q in ("k", "c")}
    out = []
    for i, design in enumerate(designs):
        predicted = {q: preds[f"{q}_{axis}"].at(i) for q in ("k", "c")}
        rel_error, prob, ds, ws = {}, {}, [], []
        for q, t in targets.items():
            p = predicted[q]
            if t.kind == "target":
                rel_error[q] = (p.value - t.value) / t.value
                prob[q] = probability_within(
                    p, t.value, tolerance, models[q].dof, log=models[q].transform == "log"
                )
            if info[q]["predictable"]:
                ds.append(t.desirability(p.value))
                ws.append(t.importance)
        scored = [prob[q] for q in prob if info[q]["predictable"]]
        extrapolated = space.extrapolated(design)
        notes = space.printability_notes(design)
        if extrapolated:
            notes.append(
                f"{', '.join(extrapolated)} outside the tested ranges: the prediction is an extrapolation"
            )
        out.append(
            Candidate(
                params=design,
                predicted=predicted,
                desirability=float(np.prod(np.power(ds, np.array(ws) / np.sum(ws)))) if ds else None,
                rel_error=rel_error,
                extrapolated=extrapolated,
                notes=notes,
                p_within=float(np.prod(scored)) if scored else None,
                probability=prob,
                any=[] if space.infill_matters(design) else ["density"],
            )
        )

    def key(c: Candidate) -> tuple[float, float, float]:
        k = c.predicted["k"]
        return (-(c.p_within or 0.0), -(c.desirability or 0.0), float(np.log(k.high / k.low)))

    return sorted(out, key=key)


def _pi_text(p: Prediction, unit: str) -> str:
    """A prediction as '1.27 [0.81, 2.0] N/mm': three significant digits, bounds two."""
    return f"{p.value:.3g} [{p.low:.2g}, {p.high:.2g}] {unit}"


def _assess(sug: Suggestion, surrogate: Surrogate, problem: _Problem, box: _Box) -> None:
    """Fill reachable, statements, ranges and nearest runs of a suggestion, goal by goal."""
    best = sug.candidates[0]
    tol = sug.tolerance
    scored = [
        q for q, t in sug.targets.items() if t.kind == "target" and sug.predictability[q]["predictable"]
    ]
    judged = scored or [q for q, t in sug.targets.items() if t.kind == "target"]
    sug.reachable = all(abs(best.rel_error[q]) <= tol for q in judged)
    for q, t in sug.targets.items():
        model = surrogate.model(f"{q}_{sug.axis}")
        unit = model.unit
        sug.ranges[q] = {"measured": list(model.observed_range), "predicted": None}
        p = best.predicted[q]
        if not sug.predictability[q]["predictable"]:
            sug.statements.append(_unpredictable_statement(sug, q, t, p, unit))
            continue
        if t.kind != "target":
            word = "largest" if t.kind == "max" else "smallest"
            sug.statements.append(
                f"{q} {t.kind}imised: the best design is predicted at {_pi_text(p, unit)}, the {word} the "
                f"surrogate predicts within the {'extended' if box.extrapolate else 'tested'} ranges "
                f"(measured runs span {model.observed_range[0]:.3g} to {model.observed_range[1]:.3g} {unit})"
            )
            continue
        band = f"+-{100 * tol:.0f} %"
        prob = f"a printed joint lands within {band} of it with probability {best.probability[q]:.2f}"
        if abs(best.rel_error[q]) <= tol:
            sug.statements.append(
                f"{q} = {t.value:g} {unit} is reached within {band}: predicted {_pi_text(p, unit)}; {prob}"
            )
            continue
        lo_r, hi_r = _reachable_range(problem, q, box)
        sug.ranges[q]["predicted"] = [lo_r, hi_r]
        obs_lo, obs_hi = model.observed_range
        sug.statements.append(
            f"{q} = {t.value:g} {unit} is out of reach within {band}: over the "
            f"{'extended' if box.extrapolate else 'tested'} ranges the surrogate predicts "
            f"{q}_{sug.axis} from {lo_r:.3g} to {hi_r:.3g} {unit}, the runs measured {obs_lo:.3g} to "
            f"{obs_hi:.3g} {unit}; the nearest design is predicted at {_pi_text(p, unit)} "
            f"({100 * best.rel_error[q]:+.0f} %) and {prob}"
        )
        if obs_lo <= t.value <= obs_hi:
            sug.nearest_runs = _nearest_runs(surrogate, q, sug.axis, t.value)
            sug.statements += [r["statement"] for r in sug.nearest_runs]
        else:
            sug.statements.append(
                f"{q} = {t.value:g} {unit} lies outside the measured range of {q}_{sug.axis}: "
                "the data does not support it"
            )


def _unpredictable_statement(sug: Suggestion, q: str, t: Target, p: Prediction, unit: str) -> str:
    """What the data can and cannot tell about a goal on a response no form predicts."""
    head = f"{sug.predictability[q]['statement']}: {_pi_text(p, unit)} for any design"
    if t.kind != "target":
        verb = "raises" if t.kind == "max" else "lowers"
        return f"{head}; '{t.kind}' cannot be acted on: the data shows no setting that {verb} it"
    inside = "inside" if p.low <= t.value <= p.high else "outside"
    chance = probability_within(p, t.value, sug.tolerance, sug.predictability[q]["dof"], log=False)
    return (
        f"{head}; the target {q} = {t.value:g} {unit} lies {inside} that interval and any design meets "
        f"it within +-{100 * sug.tolerance:.0f} % with probability {chance:.2f}: no setting can be chosen "
        "for it from this data"
    )


def _nearest_runs(surrogate: Surrogate, q: str, axis: str, target: float) -> list[dict[str, Any]]:
    """The measured runs closest to a target (log ratio), with the surrogate's prediction there."""
    response = f"{q}_{axis}"
    train = surrogate.training
    y = np.asarray(train[response], dtype=float)
    order = np.argsort(np.abs(np.log(y / target)))[:N_NEAREST_RUNS]
    unit = units.rig_unit(q, axis)
    out = []
    for i in order:
        design = {n: float(train[n][i]) for n in space.FACTOR_NAMES}
        p = surrogate.predict(design, responses=[response], allow_extrapolation=True)[response].at(0)
        run = int(train["run"][i]) if "run" in train else int(i) + 1
        where = ", ".join(f"{n} {design[n]:g} {space.BY_NAME[n].unit}" for n in space.FACTOR_NAMES)
        out.append(
            {
                "run": run,
                "params": design,
                "measured": float(y[i]),
                "predicted": p.to_dict(),
                "statement": f"run {run} measured {y[i]:.3g} {unit} at {where}; the surrogate predicts "
                f"{_pi_text(p, unit)} there",
            }
        )
    return out


def _reachable_range(problem: _Problem, q: str, box: _Box) -> tuple[float, float]:
    """Smallest and largest predicted value of one response over the search box (IPOPT, per combo),
    each extreme evaluated as printed (solid where the walls fill the section)."""
    solver, f = problem.extreme_solver(q), problem.functions[q]
    values = []
    for combo in box.combos:
        for sign in (1.0, -1.0):
            p = np.concatenate([combo, box.lows, box.spans, [sign]])
            sol = solver(x0=np.clip(0.5, box.lbu, box.ubu), lbx=box.lbu, ubx=box.ubu, p=p)
            design = _solid(box.design(np.asarray(sol["x"]).ravel(), combo))  # as printed
            values.append(float(f([design[n] for n in space.FACTOR_NAMES])[0]))
    return min(values), max(values)
