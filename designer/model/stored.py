"""The values and shapes of a surrogate file, checked as it is read.

A surrogate file is plain JSON that a user can open and edit. Unchecked, a hand-edited number becomes
a NaN or infinite stiffness with exit 0, a reversed or infinite interval, or a crash deep inside numpy
or CasADi (a matrix product of mismatched shapes, an overflow). Every value `ResponseSurface` and the
calibration compute with is checked here against what `designer fit` writes: its type, its shape for
the response's form, and its range. Each message names the key, what it holds and what it must be;
the fix is always to refit.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from .. import units
from ..errors import DesignerError
from ..study import space
from .forms import FORMS, design_matrix

FIX = "refit it with designer fit"
#: the 97.5 % quantile of Student's t for 1 degree of freedom (the fewest a fit reports) and for
#: infinitely many: every fitted surface's t95 lies between
T95_RANGE = (1.959963984540054, 12.706204736174696)
#: a prediction at a training run more than this many times the largest observed value is an edit,
#: never a fit (least squares with an intercept stays near its data at its own runs)
MAX_RATIO = 1e6


def bad(where: str, what: str) -> DesignerError:
    """The error for a surrogate file's value: `where` (key path) holds `what`."""
    return DesignerError(f"{where} {what}", FIX)


def number(value: Any, where: str, *, low: float = -math.inf, strict: bool = False) -> float:
    """A JSON number (not a string, not a boolean), finite, at least `low` (above it if `strict`)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise bad(where, f"is {value!r:.40}, not a number")
    try:
        x = float(value)
    except OverflowError:
        raise bad(where, "is an integer too large for a number") from None
    if not math.isfinite(x):
        raise bad(where, f"is {x}, not a finite number")
    if x < low or (strict and x == low):
        raise bad(where, f"is {x:g}, must be {'above' if strict else 'at least'} {low:g}")
    return x


def array(value: Any, where: str, shape: tuple[int, ...]) -> np.ndarray:
    """A nested list of finite numbers of exactly `shape`."""
    try:
        kind = np.asarray(value).dtype.kind
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        kind = "O"
    if kind not in "iuf":  # text, booleans, nulls, objects, or rows of different lengths
        raise bad(where, "is not a list of numbers (with rows of one length)")
    if a.shape != shape:
        raise bad(where, f"has shape {a.shape}, the form needs {shape}")
    if not np.all(np.isfinite(a)):
        raise bad(where, "holds a value that is not a finite number")
    return a


def mapping(value: Any, where: str) -> Mapping[str, Any]:
    if not isinstance(value, Mapping):
        raise bad(where, f"is {type(value).__name__}, not an object")
    return value


@functools.cache
def n_terms(form: str) -> int:
    """How many coefficients `form` has (its design matrix's columns, intercept included)."""
    one = {f.name: f.low for f in space.FACTORS}
    return design_matrix(form, one).shape[1]


def check_response_name(response: Any) -> None:
    """`response` is a coefficient name such as k_x: c or k, an underscore, an axis."""
    q, _, axis = str(response).partition("_")
    if not isinstance(response, str) or q not in ("c", "k") or axis not in units.AXES:
        raise bad(f"response {response!r:.40}", f"is not c_<axis> or k_<axis> ({', '.join(units.AXES)})")


def surface_values(response: str, d: Any) -> dict[str, Any]:
    """The numbers of one response's surface, checked: {form, alpha, coef, vcov, sigma, dof, t95,
    observed_range} as `ResponseSurface` takes them.

    Raises:
        DesignerError: a value of the wrong type, shape or range, named with its key.
    """
    check_response_name(response)
    d = mapping(d, f"response {response}")
    form = d.get("form")
    if form not in FORMS:
        raise bad(f"response {response} form", f"is {form!r:.40}, not one of {', '.join(FORMS)}")
    where = f"response {response}"
    for key in ("alpha", "coef", "vcov", "sigma", "dof", "t95", "observed_range"):
        if key not in d:
            raise bad(where, f"has no '{key}'")
    p = n_terms(form)
    out: dict[str, Any] = {"form": form}
    out["alpha"] = number(d["alpha"], f"{where} alpha", low=0.0)
    out["coef"] = array(d["coef"], f"{where} coef", (p,))
    vcov = array(d["vcov"], f"{where} vcov", (p, p))
    scale = float(np.max(np.abs(vcov))) or 1.0
    if not np.allclose(vcov, vcov.T, rtol=0.0, atol=1e-9 * scale):
        raise bad(f"{where} vcov", "is not symmetric, as a covariance is")
    if np.linalg.eigvalsh((vcov + vcov.T) / 2).min() < -1e-9 * scale:
        raise bad(f"{where} vcov", "has a negative eigenvalue, which a covariance cannot have")
    out["vcov"] = vcov
    out["sigma"] = number(d["sigma"], f"{where} sigma", low=0.0)
    out["dof"] = number(d["dof"], f"{where} dof", low=1.0)
    t95 = number(d["t95"], f"{where} t95")
    lo, hi = T95_RANGE
    if not lo * (1 - 1e-9) <= t95 <= hi * (1 + 1e-9):
        raise bad(f"{where} t95", f"is {t95:g}, not a 97.5 % t quantile (between {lo:.3f} and {hi:.3f})")
    out["t95"] = t95
    rng = array(d["observed_range"], f"{where} observed_range", (2,))
    if not 0 <= rng[0] <= rng[1]:
        raise bad(f"{where} observed_range", f"is {rng.tolist()}, not [low, high] with 0 <= low <= high")
    out["observed_range"] = (float(rng[0]), float(rng[1]))
    return out


def report_values(response: str, d: Mapping[str, Any], n_runs: int | None) -> None:
    """Check the report's parts a command computes with: leave-one-out and candidate figures are
    objects of numbers (NaN allowed: a figure can be undefined), influential rows index a run, and
    a lack-of-fit test's pure error is a finite, non-negative sum."""
    where = f"response {response}"
    for key in ("loo", "loo_nested"):
        figures(d.get(key) or {}, f"{where} {key}")
    for form, c in mapping(d.get("candidates", {}), f"{where} candidates").items():
        figures(c, f"{where} candidates {form}")
    influence = d.get("influence") or []
    if not isinstance(influence, list):
        raise bad(f"{where} influence", "is not a list")
    for item in influence:
        row = mapping(item, f"{where} influence").get("row")
        if isinstance(row, bool) or not isinstance(row, int) or not 0 <= row < (n_runs or 0):
            raise bad(f"{where} influence row", f"is {row!r:.40}, not a run of the {n_runs} in the file")
    lof = d.get("lack_of_fit")
    if lof is not None:
        lof = mapping(lof, f"{where} lack_of_fit")
        for key in ("df_pure_error", "ss_pure_error"):
            number(lof.get(key), f"{where} lack_of_fit {key}", low=0.0)


def figures(value: Any, where: str) -> None:
    """An object of named numbers, or nulls."""
    for k, v in mapping(value, where).items():
        if v is not None and (isinstance(v, bool) or not isinstance(v, (int, float))):
            raise bad(f"{where} {k}", f"is {v!r:.40}, not a number")


def training_values(training: Any, responses: list[str]) -> dict[str, list[float]]:
    """The training runs: equal-length lists of finite numbers for the six factors (not negative),
    the responses (k above 0, c not negative, as `load_table` holds them) and the run numbers; at
    least 8 runs, as fit needs.

    Raises:
        DesignerError: a missing or ragged column, or a value out of its range.
    """
    training = mapping(training, "training")
    n = None
    out: dict[str, list[float]] = {}
    for name in [*space.FACTOR_NAMES, *responses, "run"]:
        column = training.get(name)
        if not isinstance(column, list):
            raise bad("training", f"has no column '{name}' (a list of numbers)")
        if n is not None and len(column) != n:
            raise bad(f"training {name}", f"has {len(column)} values, the other columns {n}")
        n = len(column)
        low, strict = (-math.inf, False) if name == "run" else (0.0, name.startswith("k_"))
        out[name] = [number(v, f"training {name}[{i}]", low=low, strict=strict) for i, v in enumerate(column)]
    if (n or 0) < 8:
        raise bad("training", f"has {n} runs, a surrogate is fitted to at least 8")
    return out


def check_predictions(surface: Any, training: Mapping[str, list[float]]) -> None:
    """The surface's prediction at every training run: finite, ordered low <= value <= high, and
    within MAX_RATIO of the largest observed value (a fit stays near its data at its own runs)."""
    from .forms import as_printed

    X = as_printed({n: np.asarray(training[n], dtype=float) for n in space.FACTOR_NAMES})
    with np.errstate(all="ignore"):
        p = surface.predict(X)
    value, low, high = (np.asarray(v, dtype=float) for v in (p.value, p.low, p.high))
    top = MAX_RATIO * surface.observed_range[1] if surface.observed_range[1] > 0 else math.inf
    ok = np.isfinite(value) & np.isfinite(low) & np.isfinite(high) & (low <= value) & (value <= high)
    ok &= np.abs(value) <= top
    if not ok.all():
        i = int(np.argmin(ok))
        raise bad(
            f"response {surface.response} coef, vcov, sigma and t95",
            f"predict {value[i]:.3g} [{low[i]:.3g}, {high[i]:.3g}] {surface.unit} at training run {i + 1}, "
            f"whose runs span {surface.observed_range[0]:g} to {surface.observed_range[1]:g}",
        )


def calibration_runs(runs: Any, responses: list[str]) -> dict[str, np.ndarray]:
    """A calibrated file's user runs (its "calibration" block's "runs"), checked as `load_table`
    checks a runs table's values, without pandas (the loop's commands read them on every call):
    the six factors and the surrogate's responses it holds, equal-length lists of at least one
    finite number, every factor printable (`space.check_value`, tested levels for layer and raster),
    k above 0 and c not negative. Returns float arrays by column.

    Raises:
        DesignerError: naming the column and run, with the fix (recalibrate).
    """
    try:
        return _checked_runs(mapping(runs, "calibration runs"), responses)
    except DesignerError as exc:
        raise DesignerError(exc.problem, "recalibrate it with designer calibrate") from None


def _checked_runs(runs: Mapping[str, Any], responses: list[str]) -> dict[str, np.ndarray]:
    measured = [r for r in responses if r in runs]
    if not measured:
        raise bad("calibration runs", f"hold none of the responses {', '.join(responses)}")
    out: dict[str, np.ndarray] = {}
    for name in [*space.FACTOR_NAMES, *measured]:
        column = runs.get(name)
        n = len(out[space.FACTOR_NAMES[0]]) if out else None
        if column is None:
            raise bad("calibration runs", f"have no column '{name}'")
        if not isinstance(column, list) or not column or len(column) != (n or len(column)):
            raise bad(f"calibration runs {name}", f"is not a list of {n or 'the'} runs' values")
        low, strict = (0.0, name.startswith("k_")) if name in measured else (-math.inf, False)
        where = f"calibration runs {name}"
        out[name] = np.array(
            [number(v, f"{where}[{i}]", low=low, strict=strict) for i, v in enumerate(column)]
        )
        for i, v in enumerate(out[name] if name in space.FACTOR_NAMES else []):
            try:
                space.check_value(name, v, allow_extrapolation=True)
            except DesignerError as exc:
                raise bad(f"calibration run {i + 1}:", exc.problem) from None
    return out
