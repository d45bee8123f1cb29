"""The candidate forms of a response surface: features of the six factors, for numpy and CasADi.

Each form is linear in its parameters (continuous factors coded to [-1, 1] over their tested range,
categorical levels as offsets):

- ``mean``: the average of the runs, the baseline every form must beat;
- ``linear``, ``interactions`` (plus two-factor products), ``quadratic`` (plus squares; the
  Box-Behnken classic), fitted to the raw response;
- ``powerlaw``: log y linear in the logs of the factors (a beam's k ~ E b h^3 / L^3), raster as offset.

One function (`columns`) writes each form once; `NumpyOps` and `CasadiOps` evaluate it on arrays
(prediction) or on symbols (optimisation), so the two can never disagree.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping
from typing import Any

import casadi as ca
import numpy as np

from ..errors import DesignerError
from ..study import space

FORMS: tuple[str, ...] = ("mean", "linear", "interactions", "quadratic", "powerlaw")
CONTINUOUS_NAMES = [f.name for f in space.CONTINUOUS]
PAIRS = list(itertools.combinations(range(len(CONTINUOUS_NAMES)), 2))


class NumpyOps:
    """Array operations for vectorised prediction."""

    log = staticmethod(np.log)

    @staticmethod
    def is_level(a: Any, level: float) -> Any:
        return np.isclose(np.asarray(a, dtype=float), level).astype(float)


class CasadiOps:
    """The same operations on CasADi symbols, for optimisation."""

    log = staticmethod(ca.log)

    @staticmethod
    def is_level(a: Any, level: float) -> Any:
        return ca.if_else(ca.fabs(a - level) < 1e-9, 1, 0)


def coded(x: Any, f: space.Factor, ops: Any, log: bool) -> Any:
    lo, hi = (np.log(f.low), np.log(f.high)) if log else (f.low, f.high)
    return ((ops.log(x) if log else x) - (lo + hi) / 2) / ((hi - lo) / 2)


def columns(form: str, x: Mapping[str, Any], ops: Any) -> list[Any]:
    """Feature columns of a form, without the intercept, as expressions of the factors in `x`."""
    if form == "mean":
        return []
    raster45 = ops.is_level(x["raster"], 45.0)
    if form == "powerlaw":
        logs = [coded(x[f.name], f, ops, log=True) for f in space.CONTINUOUS]
        return logs + [coded(x["layer"], space.BY_NAME["layer"], ops, log=True), raster45]
    z = [coded(x[f.name], f, ops, log=False) for f in space.CONTINUOUS]
    offsets = [ops.is_level(x["layer"], 0.16), ops.is_level(x["layer"], 0.2), raster45]
    cols = list(z)
    if form in ("interactions", "quadratic"):
        cols += [z[i] * z[j] for i, j in PAIRS]
    if form == "quadratic":
        cols += [zi * zi for zi in z]
    return cols + offsets


def as_columns(X: Any) -> dict[str, np.ndarray]:
    """Factor columns as float arrays from a DataFrame, a mapping of arrays, or one design."""
    try:
        cols = {n: np.atleast_1d(np.asarray(X[n], dtype=float)) for n in space.FACTOR_NAMES}
    except KeyError as exc:
        raise DesignerError(f"missing factor {exc}", "give all six factors") from None
    n = max(len(v) for v in cols.values())
    return {k: np.broadcast_to(v, (n,)) for k, v in cols.items()}


def design_matrix(form: str, X: Any) -> np.ndarray:
    """The (n, p) design matrix of `form` at the designs X, intercept first."""
    cols = as_columns(X)
    n = len(cols["density"])
    return np.column_stack([np.ones(n)] + [np.broadcast_to(c, (n,)) for c in columns(form, cols, NumpyOps)])


def level_grid() -> dict[str, np.ndarray]:
    """Every combination of the factors' tested levels: where positivity is enforced."""
    combos = np.array(list(itertools.product(*[f.levels for f in space.FACTORS])), dtype=float)
    return {n: combos[:, i] for i, n in enumerate(space.FACTOR_NAMES)}


def check_varied(X: Mapping[str, np.ndarray]) -> None:
    """Raise when a factor takes one value in every run: no form can tell its effect."""
    for f in space.FACTORS:
        values = np.unique(X[f.name])
        if len(values) == 1:
            raise DesignerError(
                f"factor {f.name} is {values[0]:g} {f.unit} in every run of the table, so its effect "
                "cannot be estimated",
                f"add runs at other {f.name} values ({f.describe_range()}), or fit a table that varies it",
            )


def as_printed(X: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Designs as printed: where the walls fill the section (width or height <= 2.0 mm) the infill
    has no effect and the part is solid, so it is predicted at 100 % whatever the nominal infill."""
    core = np.minimum(X["width"], X["height"]) - 2 * space.WALL_MM
    return X | {"density": np.where(core > space.NOZZLE_MM + 1e-9, X["density"], 100.0)}


def check_designs(designs: Any, allow_extrapolation: bool) -> dict[str, np.ndarray]:
    """The six factor columns as float arrays of one length, each value checked against its range."""
    if hasattr(designs, "columns"):  # a DataFrame
        designs = {c: designs[c].to_numpy() for c in designs.columns}
    elif hasattr(designs, "index") and hasattr(designs, "to_dict"):  # a Series: one design
        designs = designs.to_dict()
    if not isinstance(designs, Mapping):
        raise DesignerError(
            f"designs of type {type(designs).__name__} are not designs",
            "give a DataFrame or a mapping of the six factors",
        )
    missing = [n for n in space.FACTOR_NAMES if n not in designs]
    if missing:
        raise DesignerError(
            f"designs lack factor(s) {', '.join(missing)}", f"give all of {space.FACTOR_NAMES}"
        )
    try:
        X = {n: np.atleast_1d(np.asarray(designs[n], dtype=float)) for n in space.FACTOR_NAMES}
    except (TypeError, ValueError) as exc:
        raise DesignerError(f"designs hold a value that is not a number ({exc})", "give numbers") from None
    if len({len(v) for v in X.values()}) != 1:
        raise DesignerError("the factor columns of designs differ in length", "give one value per design")
    if _block_valid(X, allow_extrapolation):
        return X
    for n, v in X.items():
        if not _all_valid(space.BY_NAME[n], v, allow_extrapolation):  # find and name the first bad one
            for value in v:
                space.check_value(n, float(value), allow_extrapolation)
    return X


def _bounds(allow_extrapolation: bool) -> tuple[np.ndarray, np.ndarray]:
    """Per continuous factor (rows, CONTINUOUS order) the lowest and highest value `space.check_value`
    accepts, as columns: its thresholds (bound -+ 1e-9), the printable limits and, unless
    extrapolating, the tested range (a value passes both bounds exactly when it passes the tighter)."""
    lows, highs = [], []
    for f in space.CONTINUOUS:
        lo, hi = space.printable_limits(f)
        lows.append([lo - 1e-9] + ([] if allow_extrapolation else [f.low - 1e-9]))
        highs.append([hi + 1e-9] + ([] if allow_extrapolation else [f.high + 1e-9]))
    return np.array([max(v) for v in lows])[:, None], np.array([min(v) for v in highs])[:, None]


#: `_bounds` for allow_extrapolation False and True
BOUNDS = {flag: _bounds(flag) for flag in (False, True)}
#: each categorical factor's levels as a column
LEVELS = {f.name: np.array(f.levels, dtype=float)[:, None] for f in space.CATEGORICAL}


def _in_bounds(block: np.ndarray, lows: np.ndarray, highs: np.ndarray) -> bool:
    """Whether every value of `block` (factors x designs) is finite and within its row's bounds."""
    return bool(np.isfinite(block).all() and (block >= lows).all() and (block <= highs).all())


def _at_levels(v: np.ndarray, levels: np.ndarray) -> bool:
    """Whether every value of `v` is finite and a level: math.isclose(v, level, rel_tol=1e-9,
    abs_tol=1e-9), as `space.check_value` asks, for some level of the column `levels`."""
    if not np.isfinite(v).all():
        return False
    close = np.abs(v - levels) <= np.maximum(1e-9 * np.maximum(np.abs(v), np.abs(levels)), 1e-9)
    return bool(close.any(axis=0).all())


def _block_valid(X: Mapping[str, np.ndarray], allow_extrapolation: bool) -> bool:
    """Whether `space.check_value` accepts every value of X, by its own comparisons on whole blocks:
    the continuous factors at once, each categorical factor's levels at once (the loop predicts
    hundreds of times: `next` checked 10 440 values one by one, then 6 columns a call at 55 us)."""
    cont = np.array([X[n] for n in CONTINUOUS_NAMES])
    if cont.ndim != 2 or not _in_bounds(cont, *BOUNDS[bool(allow_extrapolation)]):
        return False
    return all(_at_levels(X[name], levels) for name, levels in LEVELS.items())


def _all_valid(f: space.Factor, v: np.ndarray, allow_extrapolation: bool) -> bool:
    """Whether `space.check_value` accepts every value of one factor's column `v`; False sends the
    column through `check_value`, which raises on the first bad one."""
    v = v.reshape(1, -1)
    if f.categorical:
        return _at_levels(v, LEVELS[f.name])
    i = CONTINUOUS_NAMES.index(f.name)
    lows, highs = BOUNDS[bool(allow_extrapolation)]
    return _in_bounds(v, lows[i : i + 1], highs[i : i + 1])
