"""Ridge least squares of one form, held positive on the tested grid, with its prediction interval.

The fit is ridge-regularised least squares solved as a QP by CasADi (``conic``/qrqp). The ridge
penalty is chosen by closed-form leave-one-out on the rows given, so a fold of any cross-validation
is the same call on fewer rows.
"""

from __future__ import annotations

import functools

import casadi as ca
import numpy as np

from ..errors import DesignerError
from .forms import design_matrix, level_grid

#: ridge penalties tried inside each training fold (features are coded to unit scale)
ALPHAS: tuple[float, ...] = (0.0, 1e-3, 1e-2, 1e-1, 1.0, 10.0, 100.0)


def penalty(p: int) -> np.ndarray:
    P = np.eye(p)
    P[0, 0] = 0.0  # the intercept is not shrunk
    return P


def best_alpha(Z: np.ndarray, y: np.ndarray) -> float:
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


def ridge_fit(Z: np.ndarray, y: np.ndarray, alpha: float, Zg: np.ndarray | None, lower: float) -> np.ndarray:
    """Ridge least squares, held >= `lower` at the grid rows Zg, solved as a QP by CasADi's qrqp.

    Cutting planes: the QP is solved with only the grid points found violated so far as
    constraints, adding the newly violated ones until none is; the result is the optimum of the
    fully constrained problem, with a few rows instead of hundreds. The QP is solved for y scaled
    to unit mean magnitude (qrqp's tolerances are absolute: damping in N.s/mm is ~1e-3).

    Raises:
        DesignerError: the constraints cannot be met (the runs contradict positivity).
    """
    p = Z.shape[1]
    H = 2 * (Z.T @ Z + alpha * penalty(p))
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
        beta = np.asarray(sol["x"]).ravel() if solver.stats()["success"] else qp_by_nnls(H, g, A, lower)
        if beta is None:
            break
    raise DesignerError(
        "the surrogate cannot be held positive over the tested grid for this table",
        "check the table for extreme or mistyped values",
    )


class Fit:
    """One form fitted to some rows: coefficients now, the interval terms when first asked for.

    Most fits of a nested cross-validation only give a point prediction to compare forms; the
    prediction interval's terms (an inverse and a t quantile) are computed only where needed.
    """

    def __init__(self, form: str, Z: np.ndarray, y: np.ndarray) -> None:
        self.log = form == "powerlaw"
        self._Z = Z
        self._yt = np.log(y) if self.log else y
        self.alpha = best_alpha(Z, self._yt)
        self.coef = ridge_fit(
            Z, self._yt, self.alpha, positivity_grid(form), lower_bound(y, "log" if self.log else "none")
        )

    @functools.cached_property
    def _terms(self) -> tuple[np.ndarray, float, float, float]:
        from scipy.special import stdtrit

        Z = self._Z
        A_inv = np.linalg.inv(Z.T @ Z + self.alpha * penalty(Z.shape[1]))
        dof = max(len(Z) - float(np.einsum("ij,jk,ik->", Z, A_inv, Z)), 1.0)
        sigma = float(np.sqrt(np.sum((self._yt - Z @ self.coef) ** 2) / dof))
        return A_inv @ Z.T @ Z @ A_inv, sigma, dof, float(stdtrit(dof, 0.975))

    @property
    def vcov(self) -> np.ndarray:
        """A^-1 Z'Z A^-1 with A = Z'Z + alpha P: the coefficients' covariance divided by sigma^2."""
        return self._terms[0]

    @property
    def sigma(self) -> float:
        return self._terms[1]

    @property
    def dof(self) -> float:
        return self._terms[2]

    @property
    def t95(self) -> float:
        return self._terms[3]

    def value(self, Z: np.ndarray) -> np.ndarray:
        """Predicted values at the feature rows Z, raw units."""
        mean = Z @ self.coef
        return np.exp(mean) if self.log else mean

    def predict(self, Z: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Value and 95 % PI at the feature rows Z, raw units."""
        return interval(Z, self.coef, self.vcov, self.sigma, self.t95, self.log)


def interval(
    Z: np.ndarray, coef: np.ndarray, vcov: np.ndarray, sigma: float, t95: float, log: bool
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Value and 95 % PI (mean +- t95 sigma sqrt(1 + z' vcov z) in fit space) in raw units."""
    mean = Z @ coef
    half = t95 * sigma * np.sqrt(1.0 + np.einsum("ij,jk,ik->i", Z, vcov, Z))
    out = (mean, mean - half, mean + half)
    return tuple(np.exp(v) for v in out) if log else out


def fit_arrays(form: str, Z: np.ndarray, y: np.ndarray) -> Fit:
    """Fit `form` (feature rows Z, responses y in rig units); ridge penalty by closed-form LOO.

    The whole fit of one form: a deterministic function of (Z, y), so a fold of any
    cross-validation is this same call on fewer rows.
    """
    return Fit(form, Z, np.asarray(y, dtype=float))


def lower_bound(y: np.ndarray, transform: str) -> float:
    """Positivity floor on the tested grid for raw-space forms: a thousandth of the smallest run."""
    return -np.inf if transform == "log" else 1e-3 * float(np.min(y))


def qp_by_nnls(H: np.ndarray, g: np.ndarray, A: np.ndarray, lower: float) -> np.ndarray | None:
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
def positivity_grid(form: str) -> np.ndarray | None:
    """Where a raw-space form must stay positive: its features at every tested level combination."""
    return None if form in ("mean", "powerlaw") else design_matrix(form, level_grid())
