"""Response-surface surrogate of c and k per axis, fitted with CasADi and chosen by leave-one-out.

Each response gets the candidate forms below, each a linear-in-parameters expression of the factors
(continuous factors coded to [-1, 1] over their tested range, categorical levels as offsets):

- ``mean``: the average of the runs, the baseline every form must beat;
- ``linear``, ``interactions`` (plus two-factor products), ``quadratic`` (plus squares; the
  Box-Behnken classic), fitted to the raw response with positivity enforced on the tested grid;
- ``powerlaw``: log y linear in the logs of the factors (a beam's k ~ E b h^3 / L^3), raster as offset.

The fit is ridge-regularised least squares solved as a QP by CasADi (``conic``/qrqp). The ridge
penalty is chosen inside the cross-validation (closed-form LOO on each training fold), so the
reported leave-one-out metrics are honest. Predictions carry 95 % prediction intervals.
"""

from __future__ import annotations

import functools
import hashlib
import itertools
import json
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

import casadi as ca
import numpy as np

from . import space, units
from .errors import DesignerError, check_type, names_argument, path_argument
from .files import atomic_write

FORMAT = "flexjoint-surrogate/1"
FORMS: tuple[str, ...] = ("mean", "linear", "interactions", "quadratic", "powerlaw")
#: ridge penalties tried inside each training fold (features are coded to unit scale)
ALPHAS: tuple[float, ...] = (0.0, 1e-3, 1e-2, 1e-1, 1.0, 10.0, 100.0)
DEFAULT_NAME = "default.json"

_CONT = [f.name for f in space.CONTINUOUS]
_PAIRS = list(itertools.combinations(range(len(_CONT)), 2))


class _NumpyOps:
    """Array operations for vectorised prediction."""

    log = staticmethod(np.log)

    @staticmethod
    def is_level(a: Any, level: float) -> Any:
        return np.isclose(np.asarray(a, dtype=float), level).astype(float)


class _CasadiOps:
    """The same operations on CasADi symbols, for optimisation."""

    log = staticmethod(ca.log)

    @staticmethod
    def is_level(a: Any, level: float) -> Any:
        return ca.if_else(ca.fabs(a - level) < 1e-9, 1, 0)


def _coded(x: Any, f: space.Factor, ops: Any, log: bool) -> Any:
    lo, hi = (np.log(f.low), np.log(f.high)) if log else (f.low, f.high)
    return ((ops.log(x) if log else x) - (lo + hi) / 2) / ((hi - lo) / 2)


def _columns(form: str, x: Mapping[str, Any], ops: Any) -> list[Any]:
    """Feature columns of a form, without the intercept, as expressions of the factors in `x`."""
    if form == "mean":
        return []
    raster45 = ops.is_level(x["raster"], 45.0)
    if form == "powerlaw":
        logs = [_coded(x[f.name], f, ops, log=True) for f in space.CONTINUOUS]
        return logs + [_coded(x["layer"], space.BY_NAME["layer"], ops, log=True), raster45]
    z = [_coded(x[f.name], f, ops, log=False) for f in space.CONTINUOUS]
    offsets = [ops.is_level(x["layer"], 0.16), ops.is_level(x["layer"], 0.2), raster45]
    cols = list(z)
    if form in ("interactions", "quadratic"):
        cols += [z[i] * z[j] for i, j in _PAIRS]
    if form == "quadratic":
        cols += [zi * zi for zi in z]
    return cols + offsets


def _as_columns(X: Any) -> dict[str, np.ndarray]:
    """Factor columns as float arrays from a DataFrame, a mapping of arrays, or one design."""
    try:
        cols = {n: np.atleast_1d(np.asarray(X[n], dtype=float)) for n in space.FACTOR_NAMES}
    except KeyError as exc:
        raise DesignerError(f"missing factor {exc}", "give all six factors") from None
    n = max(len(v) for v in cols.values())
    return {k: np.broadcast_to(v, (n,)) for k, v in cols.items()}


def design_matrix(form: str, X: Any) -> np.ndarray:
    """The (n, p) design matrix of `form` at the designs X, intercept first."""
    cols = _as_columns(X)
    n = len(cols["density"])
    return np.column_stack([np.ones(n)] + [np.broadcast_to(c, (n,)) for c in _columns(form, cols, _NumpyOps)])


def _grid() -> dict[str, np.ndarray]:
    """Every combination of the factors' tested levels: where positivity is enforced."""
    combos = np.array(list(itertools.product(*[f.levels for f in space.FACTORS])), dtype=float)
    return {n: combos[:, i] for i, n in enumerate(space.FACTOR_NAMES)}


def _penalty(p: int) -> np.ndarray:
    P = np.eye(p)
    P[0, 0] = 0.0  # the intercept is not shrunk
    return P


def _best_alpha(Z: np.ndarray, y: np.ndarray) -> float:
    """The ridge penalty in ALPHAS with the smallest closed-form leave-one-out residual sum of squares.

    With the intercept unpenalised, ridge on Z = [1, W] is ridge on the centred Wc plus the mean,
    so with Wc = U S V' the hat matrix is 11'/n + U diag(s^2 / (s^2 + alpha)) U': one SVD gives
    every penalty's PRESS. alpha = 0 is skipped when Wc is rank deficient (fewer distinct designs
    than terms), where the unpenalised fit is not unique.
    """
    n = len(y)
    Wc = Z[:, 1:] - Z[:, 1:].mean(axis=0)
    if Wc.shape[1] == 0:
        U, s2 = np.zeros((n, 0)), np.zeros(0)
    else:
        U, s, _ = np.linalg.svd(Wc, full_matrices=False)
        s2 = s**2
    tol = (max(Wc.shape) * np.finfo(float).eps) ** 2
    full_rank = len(s2) == 0 or (len(s2) == Wc.shape[1] and s2.min() > s2.max() * tol)
    alphas = np.array([a for a in ALPHAS if a > 0 or full_rank])
    keep = s2 > s2.max(initial=0.0) * tol
    U, s2 = U[:, keep], s2[keep]
    shrink = s2[None, :] / (s2[None, :] + alphas[:, None])  # (n_alpha, rank)
    Uy = U.T @ (y - y.mean())
    fitted = y.mean() + (shrink * Uy) @ U.T  # (n_alpha, n)
    h = np.clip(1.0 / n + shrink @ (U**2).T, None, 1 - 1e-12)
    press = np.sum(((y - fitted) / (1 - h)) ** 2, axis=1)
    return float(alphas[int(np.argmin(press))])


def _ridge_fit(Z: np.ndarray, y: np.ndarray, alpha: float, Zg: np.ndarray | None, lower: float) -> np.ndarray:
    """Ridge least squares, held >= `lower` at the grid rows Zg, solved as a QP by CasADi's qrqp.

    Cutting planes: the QP is solved with only the grid points found violated so far as
    constraints, adding the newly violated ones until none is; the result is the optimum of the
    fully constrained problem, with a few rows instead of hundreds. The QP is solved for y scaled
    to unit mean magnitude (qrqp's tolerances are absolute: damping in N.s/mm is ~1e-3).

    Raises:
        DesignerError: the constraints cannot be met (the runs contradict positivity).
    """
    p = Z.shape[1]
    H = 2 * (Z.T @ Z + alpha * _penalty(p))
    beta = np.linalg.solve(H, 2 * Z.T @ y)
    if Zg is None:
        return beta
    scale = float(np.mean(np.abs(y))) or 1.0
    g = -2 * Z.T @ (y / scale)
    beta, lower = beta / scale, lower / scale
    active = np.zeros(len(Zg), dtype=bool)
    opts = {"print_iter": False, "print_header": False, "print_info": False, "error_on_fail": False}
    for _ in range(len(Zg)):
        # rows already constrained count as held (within the QP's tolerance)
        violated = (Zg @ beta < lower * (1 - 1e-9)) & ~active
        if not violated.any():
            return beta * scale
        active |= violated
        A = Zg[active]
        solver = ca.conic(
            "ridge", "qrqp", {"h": ca.Sparsity.dense(p, p), "a": ca.Sparsity.dense(*A.shape)}, opts
        )
        sol = solver(h=H, g=g, a=A, lba=lower, uba=np.inf, x0=beta)
        # qrqp can cycle on degenerate grid rows: then the exact NNLS route on the same rows
        beta = np.asarray(sol["x"]).ravel() if solver.stats()["success"] else _qp_by_nnls(H, g, A, lower)
        if beta is None:
            break
    raise DesignerError(
        "the surrogate cannot be held positive over the tested grid for this table",
        "check the table for extreme or mistyped values",
    )


class _Fit:
    """One form fitted to some rows: coefficients now, the interval terms when first asked for.

    Most fits of a nested cross-validation only give a point prediction to compare forms; the
    prediction interval's terms (an inverse and a t quantile) are computed only where needed.
    """

    def __init__(self, form: str, Z: np.ndarray, y: np.ndarray) -> None:
        self.log = form == "powerlaw"
        self._Z = Z
        self._yt = np.log(y) if self.log else y
        self.alpha = _best_alpha(Z, self._yt)
        self.coef = _ridge_fit(
            Z, self._yt, self.alpha, _positivity_grid(form), _lower_bound(y, "log" if self.log else "none")
        )

    @functools.cached_property
    def _interval(self) -> tuple[np.ndarray, float, float, float]:
        from scipy.special import stdtrit

        Z = self._Z
        A_inv = np.linalg.inv(Z.T @ Z + self.alpha * _penalty(Z.shape[1]))
        dof = max(len(Z) - float(np.einsum("ij,jk,ik->", Z, A_inv, Z)), 1.0)
        sigma = float(np.sqrt(np.sum((self._yt - Z @ self.coef) ** 2) / dof))
        return A_inv @ Z.T @ Z @ A_inv, sigma, dof, float(stdtrit(dof, 0.975))

    @property
    def vcov(self) -> np.ndarray:
        """A^-1 Z'Z A^-1 with A = Z'Z + alpha P: the coefficients' covariance divided by sigma^2."""
        return self._interval[0]

    @property
    def sigma(self) -> float:
        return self._interval[1]

    @property
    def dof(self) -> float:
        return self._interval[2]

    @property
    def t95(self) -> float:
        return self._interval[3]

    def value(self, Z: np.ndarray) -> np.ndarray:
        """Predicted values at the feature rows Z, raw units."""
        mean = Z @ self.coef
        return np.exp(mean) if self.log else mean

    def predict(self, Z: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Value and 95 % PI at the feature rows Z, raw units."""
        return _interval(Z, self.coef, self.vcov, self.sigma, self.t95, self.log)


def _interval(
    Z: np.ndarray, coef: np.ndarray, vcov: np.ndarray, sigma: float, t95: float, log: bool
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Value and 95 % PI (mean +- t95 sigma sqrt(1 + z' vcov z) in fit space) in raw units."""
    mean = Z @ coef
    half = t95 * sigma * np.sqrt(1.0 + np.einsum("ij,jk,ik->i", Z, vcov, Z))
    out = (mean, mean - half, mean + half)
    return tuple(np.exp(v) for v in out) if log else out


def fit_arrays(form: str, Z: np.ndarray, y: np.ndarray) -> _Fit:
    """Fit `form` (feature rows Z, responses y in rig units); ridge penalty by closed-form LOO.

    The whole fit of one form: a deterministic function of (Z, y), so a fold of any
    cross-validation is this same call on fewer rows.
    """
    return _Fit(form, Z, np.asarray(y, dtype=float))


@dataclass(frozen=True)
class Prediction:
    """Predicted values and their 95 % prediction interval (`low`, `high`), in rig units.

    Arrays of shape (n,) for n designs, or floats for one design (`at(i)`). The one shape of a
    prediction everywhere: surrogate, suggest, joint provenance, exports and JSON (`to_dict`).
    """

    value: Any
    low: Any
    high: Any

    def at(self, i: int) -> Prediction:
        """The prediction for design `i` as floats."""
        return Prediction(float(self.value[i]), float(self.low[i]), float(self.high[i]))

    def scaled(self, factor: float) -> Prediction:
        """The same prediction in other units: every bound times `factor` (> 0)."""
        return Prediction(self.value * factor, self.low * factor, self.high * factor)

    def to_dict(self) -> dict[str, Any]:
        """{"value", "low", "high"}: floats, or lists for several designs."""

        def plain(v: Any) -> Any:
            return np.asarray(v, dtype=float).tolist()

        return {"value": plain(self.value), "low": plain(self.low), "high": plain(self.high)}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any], *, where: str = "prediction") -> Prediction:
        """Read back `to_dict` output; raise DesignerError when a key is missing or not a number."""
        try:
            values = [d[k] for k in ("value", "low", "high")]
            if all(np.ndim(v) == 0 for v in values):
                return cls(*(float(v) for v in values))
            return cls(*(np.asarray(v, dtype=float) for v in values))
        except (KeyError, TypeError, ValueError) as exc:
            raise DesignerError(
                f"{where} is not a prediction ({exc})", 'expected {"value": .., "low": .., "high": ..}'
            ) from None


@dataclass
class ResponseSurface:
    """One response's fitted form: coefficients, ridge penalty, and what its intervals need."""

    response: str
    form: str = "mean"
    alpha: float = 0.0
    coef: np.ndarray = field(default_factory=lambda: np.zeros(1))
    #: A^-1 Z'Z A^-1 with A = Z'Z + alpha P: the coefficients' covariance divided by sigma^2
    vcov: np.ndarray = field(default_factory=lambda: np.ones((1, 1)))
    sigma: float = 0.0
    dof: float = 0.0
    t95: float = 0.0
    loo: dict[str, float] = field(default_factory=dict)
    loo_predictions: Prediction | None = None
    candidates: dict[str, dict[str, float]] = field(default_factory=dict)
    observed_range: tuple[float, float] = (0.0, 0.0)
    #: nested LOO metrics: the whole selection repeated without each run (the honest accuracy)
    loo_nested: dict[str, float] = field(default_factory=dict)
    nested_predictions: Prediction | None = None
    #: runs whose removal changes the chosen form or moves its LOO Q2 by more than 0.05
    influence: list[dict[str, Any]] = field(default_factory=list)
    #: pure-error / lack-of-fit test when the table has replicated designs, else None
    lack_of_fit: dict[str, Any] | None = None

    @property
    def transform(self) -> str:
        return "log" if self.form == "powerlaw" else "none"

    @property
    def quantity(self) -> str:
        return self.response.split("_", 1)[0]

    @property
    def axis(self) -> str:
        return self.response.split("_", 1)[1]

    @property
    def unit(self) -> str:
        return units.rig_unit(self.quantity, self.axis)

    @property
    def fitted(self) -> bool:
        """Whether fit (or loading) gave this surface a residual scale and dof."""
        return self.dof > 0

    @property
    def predictable(self) -> bool:
        """Whether a form other than the mean is chosen and beats the mean under (nested) LOO."""
        return self.form != "mean" and self.accuracy.get("q2", 0.0) > 0.0

    @property
    def accuracy(self) -> dict[str, float]:
        """The honest accuracy figures: nested LOO when computed, else the chosen form's own LOO."""
        return self.loo_nested or self.loo

    def features(self, X: Any) -> np.ndarray:
        return design_matrix(self.form, X)

    def fit(self, X: Any, y: np.ndarray) -> ResponseSurface:
        """Fit this form; the ridge penalty is chosen by closed-form LOO on the given rows."""
        y = np.asarray(y, dtype=float)
        return self.set_fit(fit_arrays(self.form, self.features(X), y), y)

    def set_fit(self, f: _Fit, y: np.ndarray) -> ResponseSurface:
        """Take the coefficients and interval terms of a fit to the runs `y`."""
        self.alpha, self.coef, self.vcov = f.alpha, f.coef, f.vcov
        self.sigma, self.dof, self.t95 = f.sigma, f.dof, f.t95
        self.observed_range = (float(np.min(y)), float(np.max(y)))
        return self

    def predict(self, X: Any) -> Prediction:
        """Value and 95 % PI at the designs X (mapping or DataFrame of factor columns, shape (n,))."""
        if not self.fitted:
            raise DesignerError(
                f"the surface of {self.response} is not fitted", "call fit(X, y) first, or load a surrogate"
            )
        Z = self.features(X)
        return Prediction(*_interval(Z, self.coef, self.vcov, self.sigma, self.t95, self.transform == "log"))

    def casadi_function(self) -> ca.Function:
        """value, lo, hi of the 95 % PI as a CasADi function of the six factors (factor order)."""
        x = ca.SX.sym("x", len(space.FACTOR_NAMES))
        xs = {n: x[i] for i, n in enumerate(space.FACTOR_NAMES)}
        z = ca.vertcat(1, *_columns(self.form, xs, _CasadiOps))
        mean = ca.dot(z, ca.DM(self.coef))
        half = self.t95 * self.sigma * ca.sqrt(1 + ca.bilin(ca.DM(self.vcov), z, z))
        out = [mean, mean - half, mean + half]
        if self.transform == "log":
            out = [ca.exp(e) for e in out]
        return ca.Function(self.response, [x], out, ["x"], ["value", "lo", "hi"])

    def to_dict(self) -> dict[str, Any]:
        return {
            "form": self.form,
            "transform": self.transform,
            "unit": self.unit,
            "alpha": self.alpha,
            "coef": self.coef.tolist(),
            "vcov": self.vcov.tolist(),
            "sigma": self.sigma,
            "dof": self.dof,
            "t95": self.t95,
            "observed_range": list(self.observed_range),
            "loo": self.loo,
            "loo_nested": self.loo_nested,
            "loo_predictions": None if self.loo_predictions is None else self.loo_predictions.to_dict(),
            "nested_predictions": None
            if self.nested_predictions is None
            else self.nested_predictions.to_dict(),
            "influence": self.influence,
            "lack_of_fit": self.lack_of_fit,
            "candidates": self.candidates,
        }

    @classmethod
    def from_dict(cls, response: str, d: Mapping[str, Any]) -> ResponseSurface:
        if d.get("form") not in FORMS:
            raise DesignerError(
                f"surrogate response {response} has unknown form {d.get('form')!r}",
                "refit it with designer fit",
            )
        return cls(
            response=response,
            form=d["form"],
            alpha=float(d["alpha"]),
            coef=np.asarray(d["coef"], dtype=float),
            vcov=np.asarray(d["vcov"], dtype=float),
            sigma=float(d["sigma"]),
            dof=float(d["dof"]),
            t95=float(d["t95"]),
            loo=dict(d["loo"]),
            loo_predictions=Prediction.from_dict(d["loo_predictions"], where=f"{response} LOO predictions"),
            candidates=dict(d["candidates"]),
            observed_range=tuple(d["observed_range"]),
            loo_nested=dict(d.get("loo_nested") or {}),
            nested_predictions=None
            if d.get("nested_predictions") is None
            else Prediction.from_dict(d["nested_predictions"], where=f"{response} nested predictions"),
            influence=list(d.get("influence") or []),
            lack_of_fit=d.get("lack_of_fit"),
        )


def _lower_bound(y: np.ndarray, transform: str) -> float:
    """Positivity floor on the tested grid for raw-space forms: a thousandth of the smallest run."""
    return -np.inf if transform == "log" else 1e-3 * float(np.min(y))


def _qp_by_nnls(H: np.ndarray, g: np.ndarray, A: np.ndarray, lower: float) -> np.ndarray | None:
    """min 1/2 b'Hb + g'b subject to A b >= lower, through least distance programming and NNLS.

    The fallback when qrqp cycles on degenerate grid constraints (Lawson and Hanson, Solving Least
    Squares Problems, ch. 23): with H = R'R and b0 = -H^-1 g, u = R (b - b0) turns the problem into
    min |u| subject to G u >= h (G = A R^-1, h = lower - A b0), whose solution is u = -r[:p] / r[p]
    for the residual r of the non-negative least squares min |E w - f|, E = [G'; h'], f = e_(p+1).
    Returns None when the constraints are infeasible.
    """
    from scipy.optimize import nnls

    R = np.linalg.cholesky(H).T
    b0 = np.linalg.solve(H, -g)
    G = np.linalg.solve(R.T, A.T).T
    h = lower - A @ b0
    E = np.vstack([G.T, h[None, :]])
    f = np.zeros(len(E))
    f[-1] = 1.0
    w = nnls(E, f, maxiter=50 * E.shape[1])[0]
    r = E @ w - f
    if abs(r[-1]) < 1e-12:
        return None
    return b0 + np.linalg.solve(R, -r[:-1] / r[-1])


@functools.cache
def _positivity_grid(form: str) -> np.ndarray | None:
    """Where a raw-space form must stay positive: its features at every tested level combination."""
    return None if form in ("mean", "powerlaw") else design_matrix(form, _grid())


def _point_metrics(y: np.ndarray, value: np.ndarray) -> dict[str, float]:
    """RMSE, MAPE (%) and Q2 of predictions `value` of the runs `y`."""
    err = y - value
    return {
        "rmse": float(np.sqrt(np.mean(err**2))),
        "mape": float(100 * np.mean(np.abs(err / y))),
        "q2": float(1 - np.sum(err**2) / np.sum((y - y.mean()) ** 2)),
    }


def _metrics(y: np.ndarray, pred: Prediction) -> dict[str, float]:
    """`_point_metrics` and the share of runs inside their 95 % PI."""
    inside = (y >= pred.low) & (y <= pred.high)
    return _point_metrics(y, pred.value) | {"coverage95": float(np.mean(inside))}


class _Folds:
    """Fits of each form to subsets of one response's runs, cached by the rows left out.

    Nested leave-one-out fits every form to the runs without {i, j} for each pair, once from
    outer fold i and once from j; the cache makes that one fit. A fit depends only on the rows it
    sees (in table order), so a cached fit is the same numbers a fresh call gives.
    """

    def __init__(self, X: Mapping[str, np.ndarray], y: np.ndarray, forms: tuple[str, ...]) -> None:
        self.y = y
        self.Z = {form: design_matrix(form, X) for form in forms}
        self._cache: dict[tuple[str, frozenset[int]], _Fit] = {}

    def fit(self, form: str, out: frozenset[int]) -> _Fit:
        key = (form, out)
        if key not in self._cache:
            keep = np.ones(len(self.y), dtype=bool)
            keep[list(out)] = False
            self._cache[key] = fit_arrays(form, self.Z[form][keep], self.y[keep])
        return self._cache[key]

    def loo(self, form: str, rows: np.ndarray, out: frozenset[int] = frozenset()) -> np.ndarray:
        """Predicted value of each of `rows` from a fit to the runs without it (and without `out`)."""
        return np.array([self.fit(form, out | {int(i)}).value(self.Z[form][i : i + 1])[0] for i in rows])

    def loo_interval(self, form: str, rows: np.ndarray) -> Prediction:
        """As `loo`, with each prediction's 95 % PI."""
        preds = [self.fit(form, frozenset({int(i)})).predict(self.Z[form][i : i + 1]) for i in rows]
        return Prediction(*(np.array([p[k][0] for p in preds]) for k in range(3)))


@dataclass(frozen=True)
class Selection:
    """The outcome of the selection procedure on some runs: the form and every form's LOO."""

    form: str
    fit: _Fit
    #: every form's LOO predicted values over the runs, shape (n,)
    loo: dict[str, np.ndarray]
    n_params: dict[str, int]


def usable_forms(X: Mapping[str, np.ndarray], forms: tuple[str, ...] = FORMS) -> tuple[str, ...]:
    """The forms with fewer terms than the runs have distinct designs (the rest cannot be tested)."""
    rows = np.column_stack([np.asarray(X[n], dtype=float) for n in space.FACTOR_NAMES])
    distinct = len(np.unique(rows, axis=0))
    return tuple(f for f in forms if design_matrix(f, {k: v[:1] for k, v in X.items()}).shape[1] < distinct)


def select_on(
    folds: _Folds, rows: np.ndarray, forms: tuple[str, ...], out: frozenset[int] = frozenset()
) -> Selection:
    """Run the selection procedure on `rows` (the runs without `out`): LOO per form, one-SE rule.

    The one-standard-error rule (Breiman et al., Hastie et al.) on paired squared LOO errors: a
    richer form must beat a simpler one by more than the noise of the comparison, so a response
    the factors do not explain falls back to the mean instead of a form that fits noise.
    """
    y = folds.y[rows]
    preds = {form: folds.loo(form, rows, out) for form in forms}
    sq = {form: (y - p) ** 2 for form, p in preds.items()}
    best = min(forms, key=lambda f: sq[f].mean())
    n_params = {form: folds.Z[form].shape[1] for form in forms}

    def within_one_se(form: str) -> bool:
        d = sq[form] - sq[best]
        return form == best or d.mean() <= d.std(ddof=1) / np.sqrt(len(y))

    chosen = min((f for f in forms if within_one_se(f)), key=lambda f: (n_params[f], forms.index(f)))
    return Selection(chosen, folds.fit(chosen, out), preds, n_params)


def leave_one_out(form: str, X: Mapping[str, np.ndarray], y: np.ndarray, response: str) -> Prediction:
    """Predict each run from a fit to all the others (penalty re-chosen inside every fold)."""
    y = np.asarray(y, dtype=float)
    return _Folds(X, y, (form,)).loo_interval(form, np.arange(len(y)))


def select(
    X: Mapping[str, np.ndarray],
    y: np.ndarray,
    response: str,
    forms: tuple[str, ...] = FORMS,
    *,
    nested: bool = True,
) -> ResponseSurface:
    """Fit every usable form and keep the one the selection procedure picks (see `select_on`).

    `loo` holds the chosen form's leave-one-out figures (optimistic: the form was chosen by
    looking at them); with `nested`, `loo_nested` holds those of the whole procedure repeated
    without each run (form and penalty chosen inside every outer fold), and `influence` the runs
    whose removal changes the chosen form or moves the chosen form's Q2 by more than 0.05.
    """
    from .validation import lack_of_fit, nested_loo

    y = np.asarray(y, dtype=float)
    forms = usable_forms(X, forms)
    folds = _Folds(X, y, forms)
    rows = np.arange(len(y))
    sel = select_on(folds, rows, forms)
    model = ResponseSurface(response, sel.form).set_fit(sel.fit, y)
    loo = {f: folds.loo_interval(f, rows) for f in forms}
    model.loo = _metrics(y, loo[sel.form])
    model.loo_predictions = loo[sel.form]
    model.candidates = {f: _metrics(y, loo[f]) | {"n_params": sel.n_params[f]} for f in forms}
    if nested:
        model.nested_predictions, model.influence = nested_loo(folds, sel, forms)
        model.loo_nested = _metrics(y, model.nested_predictions)
    model.lack_of_fit = lack_of_fit(X, y, folds.Z[sel.form], sel.fit, sel.form == "powerlaw")
    return model


@dataclass
class Surrogate:
    """Per-response surfaces over the six factors, with the table they were fitted to."""

    models: dict[str, ResponseSurface] = field(default_factory=dict)
    table_hash: str = ""
    #: the training runs: the six factors and the responses, in rig units
    training: dict[str, list[float]] = field(default_factory=dict)
    #: the study surrogate a calibrated one was updated from (`designer.calibrate`), else None
    prior: Surrogate | None = None
    #: a calibrated surrogate's user runs ("table", a DataFrame) and settings, else None
    calibration: dict[str, Any] | None = None

    @property
    def responses(self) -> list[str]:
        return list(self.models)

    @property
    def axes(self) -> list[str]:
        return [a for a in units.AXES if f"k_{a}" in self.models and f"c_{a}" in self.models]

    @property
    def id(self) -> str:
        """Content hash of the fitted surrogate (form, coefficients and training table).

        Numbers enter the hash at 10 significant digits, so a refit on another machine (another
        BLAS, last-bit differences) gets the same id as the file it reproduces.
        """
        payload = _rounded(json.loads(self._payload_json(include_id=False)))
        return hashlib.sha256(json.dumps(payload, sort_keys=True).encode()).hexdigest()[:16]

    @property
    def table(self):  # -> pandas.DataFrame; pandas imported lazily to keep `suggest` fast
        import pandas as pd

        return pd.DataFrame(self.training)

    def fit(
        self,
        table: Any,
        *,
        responses: list[str] | None = None,
        nested: bool = True,
        progress: Callable[[float], None] | None = None,
    ) -> Surrogate:
        """Fit c and k of every axis in a coefficient table (path or DataFrame, rig units).

        The table goes through `designer.load_table`, so its problems are named with column and row.
        `responses` picks columns such as ["k_x"]; None fits c and k of every axis present.
        `nested` False skips the nested leave-one-out (a report, not part of the fit: the fitted
        surfaces are the same), for callers that refit many times. `progress` is called with the
        fraction of responses fitted (0..1) after each.

        Raises:
            DesignerError: a malformed table (missing factor, NaN, non-positive k), an unknown
                response, fewer than 8 runs, or a factor that takes one value in every run.
        """
        from .data import axes_present, check_table_argument, coefficient_columns, load_table, table_hash

        check_table_argument(table, "table")
        table = load_table(table)
        axes = axes_present(table)
        if responses is None:
            responses = [f"{q}_{a}" for a in axes for q in ("c", "k")]
        responses = names_argument(responses, "responses", example='["k_x"]')
        unknown = [r for r in responses if r not in coefficient_columns(table)]
        if unknown or not responses:
            raise DesignerError(
                f"responses={responses} names column(s) the table lacks: "
                f"{', '.join(unknown) or 'none given'}",
                f"the table has {', '.join(coefficient_columns(table))}",
            )
        if len(table) < 8:
            raise DesignerError(f"the table has {len(table)} runs", "a surrogate needs at least 8")
        X = {n: table[n].to_numpy(dtype=float) for n in space.FACTOR_NAMES}
        _check_varied(X)
        self.models = {}
        for i, r in enumerate(responses):
            self.models[r] = select(X, table[r].to_numpy(dtype=float), r, nested=nested)
            if progress is not None:
                progress((i + 1) / len(responses))
        self.prior = self.calibration = None
        self.table_hash = table_hash(table)
        self.training = {c: table[c].astype(float).tolist() for c in list(space.FACTOR_NAMES) + responses}
        self.training["run"] = (
            table["run"].astype(float).tolist()
            if "run" in table.columns
            else list(map(float, range(1, len(table) + 1)))
        )
        return self

    def model(self, response: str) -> ResponseSurface:
        try:
            return self.models[response]
        except KeyError:
            raise DesignerError(
                f"the surrogate has no response '{response}'",
                f"it has {', '.join(self.models)}; fit one on a table with that axis: Surrogate().fit(table)",
            ) from None

    def predict(
        self, designs: Any, *, responses: list[str] | None = None, allow_extrapolation: bool = False
    ) -> dict[str, Prediction]:
        """Predictions with 95 % PIs per response at the designs (rig units).

        Args:
            designs: the six factors, as a DataFrame, a mapping of arrays of shape (n,), or one design
                as a mapping of numbers.
            responses: which responses (e.g. ["k_x"]); None: all.
            allow_extrapolation: accept designs outside the tested ranges (flagged by the caller).

        Returns:
            {response: Prediction} with arrays of shape (n,).

        Raises:
            DesignerError: the surrogate is not fitted, a factor is missing, not a number or out of
                range, or a response is unknown.
        """
        if not self.models:
            raise DesignerError("the surrogate is not fitted", "call fit(table) or Surrogate.load() first")
        X = _as_printed(_check_designs(designs, allow_extrapolation))
        if responses is not None:
            responses = names_argument(responses, "responses", example='["k_x"]')
        return {r: self.model(r).predict(X) for r in (responses or self.responses)}

    def _payload_json(self, include_id: bool = True) -> str:
        payload: dict[str, Any] = {"format": FORMAT}
        if include_id:
            payload["id"] = self.id
        payload |= {
            "table_hash": self.table_hash,
            "n_runs": len(next(iter(self.training.values()), [])),
            "factors": {
                f.name: {
                    "unit": f.unit,
                    "low": f.low,
                    "high": f.high,
                    "levels": list(f.levels),
                    "categorical": f.categorical,
                }
                for f in space.FACTORS
            },
            "alphas": list(ALPHAS),
            "responses": {r: m.to_dict() for r, m in self.models.items()},
            "training": self.training,
        }
        if self.calibration is not None:
            payload["calibration"] = _calibration_payload(self)
        return json.dumps(payload, indent=1)

    def report(self) -> dict[str, Any]:
        """What the fit found, as plain data: per response its form, nested and own leave-one-out
        accuracy (labelled), influential runs, lack of fit where the table has replicates."""
        runs = self.training["run"]
        return {
            "surrogate_id": self.id,
            "table_hash": self.table_hash,
            "n_runs": len(runs),
            "responses": {
                r: {
                    "form": m.form,
                    "unit": m.unit,
                    "alpha": m.alpha,
                    "predictable": m.predictable,
                    "loo_nested": m.loo_nested,
                    "loo": m.loo,
                    "loo_label": "the selected form's own leave-one-out (optimistic: the form was chosen on "
                    "these errors); loo_nested repeats the whole selection without each run",
                    "influence": [d | {"run": int(runs[d["row"]])} for d in m.influence],
                    "lack_of_fit": m.lack_of_fit,
                    "candidates": m.candidates,
                }
                for r, m in self.models.items()
            },
        }

    def save(self, path: str | Path) -> Path:
        path = path_argument(path, "path", what="a .json file")
        with atomic_write(path) as fh:
            fh.write(self._payload_json() + "\n")
        return Path(path)

    @classmethod
    def load(cls, path: str | Path | None = None) -> Surrogate:
        """Read a surrogate saved by `save` (None: the one shipped, fitted to the bundled table).

        Raises:
            DesignerError: the file is missing, unreadable or not a surrogate.
        """
        p = default_path() if path is None else path_argument(path, "path", what="a surrogate .json file")
        try:
            d = json.loads(p.read_text())
        except FileNotFoundError:
            raise DesignerError(f"no such surrogate: {p}", "give a file written by designer fit") from None
        except (OSError, ValueError) as exc:
            raise DesignerError(f"cannot read surrogate {p}: {exc}", "refit it with designer fit") from None
        if not isinstance(d, dict) or d.get("format") != FORMAT:
            raise DesignerError(f"{p} is not a {FORMAT} surrogate", "refit it with designer fit")
        try:
            models = {r: ResponseSurface.from_dict(r, m) for r, m in d["responses"].items()}
            surrogate = cls(models=models, table_hash=d["table_hash"], training=d["training"])
        except (KeyError, TypeError, ValueError) as exc:
            raise DesignerError(
                f"surrogate {p} is incomplete ({exc})", "refit it with designer fit"
            ) from None
        if "calibration" not in d:
            return surrogate
        return _recalibrate(surrogate, d["calibration"], p)


def _calibration_payload(surrogate: Surrogate) -> dict[str, Any]:
    """A calibrated surrogate's user runs and settings, as saved beside the study's surfaces."""
    cal = surrogate.calibration or {}
    table = cal["table"]
    settings = {r: m.settings() for r, m in surrogate.models.items() if hasattr(m, "settings")}
    return {
        "printer_sd": cal["printer_sd"],
        "runs": {c: [None if v != v else float(v) for v in table[c]] for c in table.columns},
        "settings": settings,
    }


def _recalibrate(prior: Surrogate, d: Any, path: Path) -> Surrogate:
    """Rebuild a saved calibrated surrogate: its study surfaces updated again by its saved runs."""
    import pandas as pd

    from .calibration import calibrate

    try:
        table = pd.DataFrame(d["runs"], dtype=float)
        return calibrate(prior, table, printer_sd=float(d["printer_sd"]))
    except (KeyError, TypeError, ValueError) as exc:
        raise DesignerError(
            f"the calibration block of {path} is incomplete ({exc})",
            "recalibrate it with designer calibrate",
        ) from None


def _rounded(obj: Any) -> Any:
    """`obj` (parsed JSON) with every float rounded to 10 significant digits."""
    if isinstance(obj, float):
        return float(f"{obj:.10g}")
    if isinstance(obj, dict):
        return {k: _rounded(v) for k, v in obj.items()}
    if isinstance(obj, list):
        return [_rounded(v) for v in obj]
    return obj


def _check_varied(X: Mapping[str, np.ndarray]) -> None:
    """Raise when a factor takes one value in every run: no form can tell its effect."""
    for f in space.FACTORS:
        values = np.unique(X[f.name])
        if len(values) == 1:
            raise DesignerError(
                f"factor {f.name} is {values[0]:g} {f.unit} in every run of the table, so its effect "
                "cannot be estimated",
                f"add runs at other {f.name} values ({f.describe_range()}), or fit a table that varies it",
            )


def _as_printed(X: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Designs as printed: where the walls fill the section (width or height <= 2.0 mm) the infill
    has no effect and the part is solid, so it is predicted at 100 % whatever the nominal infill."""
    core = np.minimum(X["width"], X["height"]) - 2 * space.WALL_MM
    return X | {"density": np.where(core > space.NOZZLE_MM + 1e-9, X["density"], 100.0)}


def _check_designs(designs: Any, allow_extrapolation: bool) -> dict[str, np.ndarray]:
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
    for n, v in X.items():
        for value in v:
            space.check_value(n, float(value), allow_extrapolation)
    return X


def default_path() -> Path:
    return Path(str(resources.files("designer.surrogates") / DEFAULT_NAME))


def check_surrogate(value: Any, name: str = "surrogate") -> None:
    """Raise unless `value` is a fitted Surrogate.

    Raises:
        DesignerError: naming the argument `name`, e.g. for `designer.suggest(None)`.
    """
    fix = "give Surrogate.load() (the shipped one) or Surrogate().fit(table)"
    check_type(value, Surrogate, name, expected="a Surrogate", fix=fix)
    if not value.models:
        raise DesignerError(f"{name} is not fitted", fix)
