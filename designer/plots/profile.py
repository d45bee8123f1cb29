"""An interactive prediction profiler: one self-contained HTML page (no server, no network).

As JMP's Profiler and Minitab's Response Optimizer do it: a slider per continuous factor and level
buttons for the categorical ones; per response a row of panels with the prediction and its 95 %
prediction interval against each factor, the others held at the sliders; targets, desirability and
the probability of landing within a tolerance of the target; a strip of `designer suggest`
candidates that set the sliders when clicked. As a design console: goals set on the page, a lock
per factor and "maximize", which runs `designer suggest`'s search (its cost, starts, rounding and
ranking; `_search_data` exports what it needs) over the unlocked factors; a simulator propagating
print-process noise (`PRINT_NOISE`, `MC_DRAWS`) to a defect rate; remembered settings copied as a
`designer export` command line or as JSON for `--from`.

The page evaluates the surrogate itself, from the exported coefficients: each response's feature
columns are exported as expression trees recorded by running the surrogate's own feature code
(`designer.model.forms.columns`) on symbols, so the page and `Surrogate.predict` compute the same
expressions with the same coefficients, covariance, t quantile and transform.
"""

from __future__ import annotations

import html
import json
import math
import shlex
from collections.abc import Mapping
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from .. import units
from ..errors import DesignerError
from ..files import atomic_write
from ..model.forms import columns
from ..model.plausibility import SLIP_TOLERANCE, unit_slip
from ..model.prediction import ResponseSurface
from ..model.surrogate import Surrogate, default_path
from ..study import space

#: the design the page opens at unless told otherwise (the study's centre, layer 0.16 mm, raster 0 deg)
DEFAULT_DESIGN: dict[str, float] = {
    "density": 60.0,
    "length": 24.0,
    "width": 4.5,
    "height": 9.0,
    "layer": 0.16,
    "raster": 0.0,
}
#: relative tolerance within which a printed joint counts as meeting its target
TOLERANCE = 0.10
#: narrowest printable width or height: two walls and one infill line, mm
PRINTABLE_MIN_MM = 2 * space.WALL_MM + space.NOZZLE_MM
#: points per continuous factor where the y range of each response's panels is sampled
_RANGE_POINTS = 5
#: the simulator's default print-process noise, one standard deviation per continuous factor
#: (rig units: an FDM printer holds a dimension to about +-0.1 mm; the slicer sets the infill exactly)
PRINT_NOISE: dict[str, float] = {"density": 0.0, "length": 0.1, "width": 0.1, "height": 0.1}
#: the simulator's Monte Carlo size (draws of the print noise)
MC_DRAWS = 4000
#: the page's scripts, in the order the page runs them (each uses what the ones before define)
SCRIPTS = (
    "profile_model.js",
    "profile_search.js",
    "profile_views.js",
    "profile_goals.js",
    "profile_contour.js",
    "profile_trace.js",
    "profile_page.js",
)


class _Expr:
    """A symbolic value: arithmetic on it records an expression tree (nested JSON lists)."""

    __array_ufunc__ = None  # numpy scalars defer to the reflected operators below

    def __init__(self, node: list[Any]) -> None:
        self.node = node

    def _op(self, op: str, other: Any, swap: bool = False) -> _Expr:
        a, b = self.node, _node(other)
        return _Expr([op, b, a] if swap else [op, a, b])

    def __add__(self, o: Any) -> _Expr:
        return self._op("+", o)

    def __radd__(self, o: Any) -> _Expr:
        return self._op("+", o, swap=True)

    def __sub__(self, o: Any) -> _Expr:
        return self._op("-", o)

    def __rsub__(self, o: Any) -> _Expr:
        return self._op("-", o, swap=True)

    def __mul__(self, o: Any) -> _Expr:
        return self._op("*", o)

    def __rmul__(self, o: Any) -> _Expr:
        return self._op("*", o, swap=True)

    def __truediv__(self, o: Any) -> _Expr:
        return self._op("/", o)

    def __rtruediv__(self, o: Any) -> _Expr:
        return self._op("/", o, swap=True)


def _node(v: Any) -> list[Any]:
    return v.node if isinstance(v, _Expr) else ["c", float(v)]


class _TraceOps:
    """The surrogate's array operations on symbols: `log` and the categorical level indicator."""

    @staticmethod
    def log(a: Any) -> _Expr:
        return _Expr(["log", _node(a)])

    @staticmethod
    def is_level(a: Any, level: float) -> _Expr:
        return _Expr(["level", _node(a), float(level)])


def feature_program(form: str) -> list[list[Any]]:
    """The feature columns of a surrogate form (intercept excluded) as expression trees.

    Nodes: ``["x", factor]``, ``["c", constant]``, ``[op, a, b]`` with op one of ``+ - * /``,
    ``["log", a]`` and ``["level", a, level]`` (1 where a is the level as numpy.isclose says, else 0).
    """
    symbols = {n: _Expr(["x", n]) for n in space.FACTOR_NAMES}
    return [_node(c) for c in columns(form, symbols, _TraceOps)]


def _accuracy(model: ResponseSurface) -> dict[str, Any]:
    """The response's validation figures: nested leave-one-out when the surrogate has them."""
    nested = getattr(model, "loo_nested", None)
    if nested:
        kind = "nested leave-one-out (form and penalty chosen inside each fold)"
        return {"kind": kind, "nested": True} | {
            k: float(nested[k]) for k in ("q2", "rmse", "mape", "coverage95")
        }
    kind = "leave-one-out of the selected form (this surrogate has no nested figures; optimistic)"
    return {"kind": kind, "nested": False} | {
        k: float(model.loo[k]) for k in ("q2", "rmse", "mape", "coverage95")
    }


def _value_range(model: ResponseSurface, observed: np.ndarray, target: float | None) -> list[float]:
    """The y range shared by a response's panels: its PI over the tested box, the runs and the target."""
    axes = [np.linspace(f.low, f.high, _RANGE_POINTS) for f in space.CONTINUOUS]
    axes += [np.asarray(f.levels, float) for f in space.CATEGORICAL]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, len(space.FACTORS))
    pred = model.predict(pd.DataFrame(grid, columns=list(space.FACTOR_NAMES)))
    lo = min(float(np.min(pred.low)), float(np.min(observed)), target if target is not None else math.inf)
    hi = max(float(np.max(pred.high)), float(np.max(observed)), target if target is not None else -math.inf)
    pad = 0.04 * (hi - lo)
    return [max(lo - pad, 0.0) if lo >= 0 else lo - pad, hi + pad]


def _slips(quantity: str, axis: str) -> list[dict[str, Any]]:
    """The unit slips a typed goal may carry (a value in N/m typed for N/mm), as `designer suggest`
    names them: each with the ratio to the measured range it shows as, its cause and the multiplier
    that corrects it; a goal within `SLIP_TOLERANCE` of that ratio is named on the page as by suggest."""
    out = []
    for ratio in (1e3, 1e-3):
        slip = unit_slip(quantity, axis, ratio, logged=False)
        if slip:
            out.append({"ratio": ratio, "cause": slip[0], "multiplier": slip[1], "within": SLIP_TOLERANCE})
    return out


def _target(surrogate: Surrogate, quantity: str, axis: str, goal: float | str) -> dict[str, Any]:
    """A goal (a target value, "min" or "max") with its desirability bounds, as `designer suggest`
    sets them."""
    from ..design.targets import make_target

    return make_target(surrogate, quantity, axis, goal).to_dict()


def _response(surrogate: Surrogate, name: str, statement: str, target: float | str | None) -> dict[str, Any]:
    model = surrogate.model(name)
    observed = np.asarray(surrogate.training[name], float)
    return {
        "name": name,
        "quantity": model.quantity,
        "unit": model.unit,
        "form": model.form,
        "transform": model.transform,
        "base_transform": "log" if model.form == "powerlaw" else "none",
        "calibration": model.page_data() if hasattr(model, "page_data") else None,
        "features": feature_program(model.form),
        "coef": [float(v) for v in model.coef],
        "vcov": np.asarray(model.vcov, float).tolist(),
        "sigma": float(model.sigma),
        "t95": float(model.t95),
        "dof": float(model.dof),
        "predictable": bool(model.predictable),
        "statement": statement,
        "accuracy": _accuracy(model),
        "range": _value_range(model, observed, target if isinstance(target, float | int) else None),
        "observed": [float(v) for v in model.observed_range],
        "slips": _slips(model.quantity, model.axis),
        "target": None if target is None else _target(surrogate, model.quantity, model.axis, target),
    }


def suggestion_data(suggestion: Any) -> Any:
    """A `Suggestion`, its `to_dict()` or the path of a JSON file of it, as the dict."""
    if isinstance(suggestion, str | Path):
        p = Path(suggestion)
        try:
            suggestion = json.loads(p.read_text(encoding="utf-8"))
        except FileNotFoundError:
            raise DesignerError(
                f"no such suggestion file: {p}", "give a JSON file of Suggestion.to_dict()"
            ) from None
        except (OSError, ValueError) as exc:
            raise DesignerError(
                f"cannot read suggestion {p}: {exc}", "give a JSON file of Suggestion.to_dict()"
            ) from None
    if hasattr(suggestion, "to_dict"):
        suggestion = suggestion.to_dict()
    return suggestion


def is_next_prints(data: Any) -> bool:
    """Whether `data` is a `designer.next_prints` result as a dict (`designer next --json`): a
    recommendation and the prints to measure, not a suggestion's candidates."""
    return isinstance(data, Mapping) and "recommendation" in data and "prints" in data


def _suggestions(suggestion: Any) -> list[dict[str, Any]]:
    """Candidates of a `Suggestion`, of its `to_dict()`, or of a JSON file holding that dict.

    A `next_prints` result is refused: its prints after the first are chosen for what measuring them
    teaches, not ranked by the chance of landing as the page's buttons are, and before a calibration
    its P counts an unmeasured printer's departure, which the page does not."""
    if suggestion is None:
        return []
    suggestion = suggestion_data(suggestion)
    if is_next_prints(suggestion):
        raise DesignerError(
            "suggestion is a next_prints result (a recommendation and prints to measure), not a Suggestion",
            "pass designer.suggest(...) with the same goals, or its to_dict(); open the page at the "
            "recommendation with design=",
        )
    candidates = suggestion.get("candidates") if isinstance(suggestion, Mapping) else None
    if not isinstance(candidates, list):
        raise DesignerError(
            "suggestion has no list of candidates", "pass a Suggestion, its to_dict() or such a JSON file"
        )
    out = []
    for i, c in enumerate(candidates, start=1):
        try:
            params = {n: float(c["params"][n]) for n in space.FACTOR_NAMES}
        except (KeyError, TypeError, ValueError):
            raise DesignerError(
                f"suggestion candidate {i} does not give all six factors",
                "pass a Suggestion, its to_dict() or such a JSON file",
            ) from None
        # outside the tested ranges: listed with the reason, but the sliders cannot reach it
        outside = [
            f"{f.name} {params[f.name]:g} {f.unit} outside {f.describe_range()}"
            for f in space.FACTORS
            if not _within(f, params[f.name])
        ]
        # factors without effect on this design (suggest's "any", e.g. density at 2 mm width)
        free = [n for n in c.get("any", []) if n in space.FACTOR_NAMES]
        p = c.get("p_within")
        out.append(
            {
                "rank": i,
                "params": params,
                "inside": not outside,
                "outside": outside,
                "any": free,
                "p_within": None if p is None else float(p),
            }
        )
    return out


def _suggestion_goals(suggestion: Any) -> dict[str, Any] | None:
    """The goals, tolerance and surrogate id a suggestion was found for (its buttons grey out once
    the page's goals differ, or when the page shows another surrogate), or None when it does not
    record goals and tolerance."""
    if suggestion is None:
        return None
    data = suggestion_data(suggestion)
    targets = data.get("targets") if isinstance(data, Mapping) else None
    tol = data.get("tolerance") if isinstance(data, Mapping) else None
    if not isinstance(targets, Mapping) or not isinstance(tol, int | float):
        return None
    goals = {}
    for q in ("k", "c"):
        v = targets.get(q)
        goals[q] = float(v) if isinstance(v, int | float) else v if v in ("min", "max") else None
    found_with = data.get("surrogate_id")
    return {
        "targets": goals,
        "tolerance": float(tol),
        "surrogate_id": found_with if isinstance(found_with, str) else None,
    }


def _within(f: space.Factor, v: float) -> bool:
    """Whether a value lies in a factor's tested range (one of its levels when categorical)."""
    if f.categorical:
        return any(abs(v - lv) <= 1e-9 for lv in f.levels)
    return f.low - 1e-9 <= v <= f.high + 1e-9


def _search_data() -> dict[str, Any]:
    """What the page's "maximize" needs to run `designer suggest`'s search: its starts and weights."""
    from ..design.search import DISTINCT, N_STARTS, PI_WEIGHT, starts

    return {
        "starts": starts(N_STARTS, len(space.CONTINUOUS)).tolist(),
        "n_starts": N_STARTS,
        "pi_weight": PI_WEIGHT,
        "distinct": DISTINCT,
    }


@dataclass
class Profiler:
    """What the profiler page shows and computes with, as plain JSON-able data."""

    data: dict[str, Any]

    def to_html(self) -> str:
        """The self-contained page: the template with this data embedded."""
        here = resources.files("designer.plots")
        template = (here / "profile.html").read_text(encoding="utf-8")
        script = "\n".join((here / name).read_text(encoding="utf-8") for name in SCRIPTS)
        payload = json.dumps(self.data, separators=(",", ":"), allow_nan=False).replace("</", "<\\/")
        title = f"Prediction profiler, axis {self.data['axis']}"
        page = template.replace("__TITLE__", html.escape(title)).replace("__SCRIPT__", script)
        return page.replace("__DATA__", payload)


def _calibrated(surrogate: Surrogate, responses: list[dict[str, Any]]) -> dict[str, list] | None:
    """On a calibrated surrogate: the user's prints (factor and response columns, None where not
    measured), and each response's calibration figures put on it (`calibrated`); else None."""
    if surrogate.calibration is None:
        return None
    from ..model.calibration import report as calibration_report

    report = calibration_report(surrogate)["responses"]
    table = surrogate.calibration["table"]
    for r in responses:
        r["calibrated"] = report.get(r["name"]) if report.get(r["name"], {}).get("n_runs") else None
    return {
        c: [None if pd.isna(v) else float(v) for v in table[c]]
        for c in [*space.FACTOR_NAMES, *(r["name"] for r in responses)]
        if c in table
    }


def _surrogate_flag(surrogate: Surrogate, surrogate_file: str | Path | None) -> str:
    """The `--surrogate FILE` the page's command lines (suggest, export) carry, "" for the shipped
    surrogate: without it they would answer from the study's surrogate, not the page's. A surrogate
    of no known file is named by its id in a form no shell runs unchanged."""
    if surrogate_file is not None:
        return "--surrogate " + shlex.quote(str(surrogate_file))
    if surrogate.id == json.loads(default_path().read_text(encoding="utf-8")).get("id"):
        return ""
    return f"--surrogate <the file of surrogate {surrogate.id}>"


def _factors() -> list[dict[str, Any]]:
    """The six factors as the page's sliders and boxes read them."""
    return [
        {
            "name": f.name,
            "unit": f.unit,
            "label": f.label,
            "low": float(f.low),
            "high": float(f.high),
            "levels": [float(v) for v in f.levels],
            "categorical": f.categorical,
            "step": float(f.resolution),
            "printable_min": PRINTABLE_MIN_MM if f.name in ("width", "height") else None,
        }
        for f in space.FACTORS
    ]


def _check_axis(surrogate: Surrogate, axis: str) -> None:
    """Refuse an axis the surrogate has no k and c of (a rotational one is derived by suggest, next
    and export, not by the page)."""
    units.check_axis(axis)
    if axis in surrogate.axes:
        return
    derived = units.is_rotational(axis) and "x" in surrogate.axes
    why = "; suggest, next and export derive a rotational axis from x, the page does not" if derived else ""
    raise DesignerError(
        f"the profiler shows the axes the surrogate has ({', '.join(surrogate.axes) or 'none'}), "
        f"and {axis} is not one of them{why}",
        f"profile the {surrogate.axes[0]} axis"
        if surrogate.axes
        else "fit a surrogate with k and c of an axis",
    )


def build_profiler(
    surrogate: Surrogate,
    *,
    axis: str = "x",
    targets: Mapping[str, float] | None = None,
    tolerance: float | None = None,
    suggestion: Any = None,
    design: Mapping[str, float] | None = None,
    surrogate_file: str | Path | None = None,
) -> Profiler:
    """Gather what the profiler page needs for k and c of one axis.

    Args:
        surrogate: the fitted surrogate whose coefficients the page evaluates.
        axis: the axis of the responses (x y z theta phi psi).
        targets: goals by quantity: a target in rig units, e.g. {"k": 0.8} (N/mm), or "min" or "max".
        tolerance: relative tolerance of "meeting the target" (0.1: within 10 %); default the
            suggestion's, else `TOLERANCE`.
        suggestion: a `Suggestion`, its `to_dict()` or the path of a JSON file of it (what the
            suggest command writes with its JSON option).
        design: factors the page opens at (the rest from `DEFAULT_DESIGN`), within the tested ranges.
        surrogate_file: the file `surrogate` was read from, as a shell in the user's folder reaches
            it: the page's suggest and export command lines carry `--surrogate` with it.

    Raises:
        DesignerError: unknown axis, quantity or factor; a value outside the tested ranges; a
            target that is not positive; a tolerance outside (0, 1); an unreadable suggestion.
    """
    _check_axis(surrogate, axis)
    suggestion = None if suggestion is None else suggestion_data(suggestion)
    found = _suggestion_goals(suggestion)
    # opened from a suggestion: its goals and tolerance unless given, its first candidate unless a
    # design is given (and the candidate lies in the tested ranges)
    if not targets and found:
        targets = {q: v for q, v in found["targets"].items() if v is not None}
    if tolerance is None:
        tolerance = found["tolerance"] if found else TOLERANCE
    candidates = _suggestions(suggestion)
    opened_from = None
    if design is None and candidates and candidates[0]["inside"]:
        design, opened_from = candidates[0]["params"], "suggestion #1"
    targets = dict(targets or {})
    for q in targets:
        if q not in ("k", "c"):
            raise DesignerError(f"targets has unknown quantity '{q}'", "give targets={'k': 0.8}, for k or c")
    if not (isinstance(tolerance, int | float) and 0 < tolerance < 1):
        raise DesignerError(
            f"tolerance={tolerance!r} is not a fraction between 0 and 1", "give e.g. tolerance=0.1"
        )
    start = space.check_design(DEFAULT_DESIGN | dict(design or {}))
    from ..design.suggestions import predictability

    info = predictability(surrogate, axis)
    responses = [
        _response(surrogate, f"{q}_{axis}", info[q]["statement"], targets.get(q)) for q in ("k", "c")
    ]
    mine = _calibrated(surrogate, responses)
    runs = {n: [float(v) for v in surrogate.training[n]] for n in space.FACTOR_NAMES}
    runs |= {r["name"]: [float(v) for v in surrogate.training[r["name"]]] for r in responses}
    return Profiler(
        {
            "axis": axis,
            "surrogate_id": surrogate.id,
            "surrogate_flag": _surrogate_flag(surrogate, surrogate_file),
            "factors": _factors(),
            "design": start,
            "responses": responses,
            "runs": runs,
            "tolerance": float(tolerance),
            "suggestions": candidates,
            "suggestion_goals": found,
            "opened_from": opened_from,
            "mine": mine,
            "wall_mm": space.WALL_MM,
            "nozzle_mm": space.NOZZLE_MM,
            "search": _search_data(),
            "noise": PRINT_NOISE,
            "mc_draws": MC_DRAWS,
        }
    )


def write_profiler(profiler: Profiler, path: str | Path) -> Path:
    """Write the page atomically; the path must end in .html.

    Raises:
        DesignerError: the path does not end in .html or .htm, or its folder is missing.
    """
    p = Path(path)
    if p.suffix.lower() not in (".html", ".htm"):
        raise DesignerError(f"cannot write the profiler page to '{p.name}'", "end the file name in .html")
    with atomic_write(p, "w", encoding="utf-8") as fh:
        fh.write(profiler.to_html())
    return p
