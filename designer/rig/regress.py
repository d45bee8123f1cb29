"""Least squares that stays consistent when the regressors carry noise, with HAC standard errors.

The estimator is bias-compensated least squares (the errors-in-variables moment correction, which
total least squares reduces to when the regressor-noise covariance is known): solve
(X'X - n S) b = X'y, where S is the per-row covariance of the noise in the columns of X. Ordinary
least squares would shrink every coefficient whose column carries noise towards zero
(attenuation), and because r'' is nearly collinear with r at the study's frequencies the shrinkage
lands mostly on m. The standard errors are the sandwich A^-1 Q A^-1 with Q the Newey-West
(Bartlett kernel) long-run covariance of the moment contributions x_t e_t, so they hold for the
coloured residuals that band-limited filtering makes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Solution:
    """Coefficients, their HAC covariance, and fit quality over the rows used."""

    beta: np.ndarray
    cov: np.ndarray
    rss: float
    tss: float
    rows: int
    also_beta: np.ndarray | None = None

    @property
    def se(self) -> np.ndarray:
        return np.sqrt(np.clip(np.diag(self.cov), 0.0, None))

    @property
    def r2(self) -> float:
        return 1.0 - self.rss / self.tss if self.tss > 0 else float("nan")


def _box(a: np.ndarray, m: int) -> np.ndarray:
    """Full convolution of each column of `a` with m ones (length rows + m - 1), by cumulative sums."""
    n, p = a.shape
    upper = np.empty((n + m - 1, p))
    np.cumsum(a, axis=0, out=upper[:n])
    upper[n:] = upper[n - 1]
    out = upper.copy()
    out[m:] -= upper[: n - 1]
    return out


def newey_west(scores: np.ndarray, lags: int, rows: int) -> np.ndarray:
    """Bartlett-weighted long-run covariance of the rows of `scores` (rows in time order, mean taken out).

    sum over |l| <= lags of (1 - |l| / (lags + 1)) Gamma_l, computed as g' (T g) with T the
    triangular smoother, itself two moving sums (linear in the rows for any truncation).
    Divided by 1 - b + b^2 / 3, b = (lags + 1) / rows: the mean of the Bartlett estimate when the
    truncation is a fixed fraction b of the sample (Kiefer and Vogelsang 2005), which otherwise
    biases the standard errors low because the scores of a least-squares fit sum to zero.
    """
    g = scores - scores.mean(axis=0)
    m = lags + 1
    smooth = _box(_box(g, m), m)[m - 1 : m - 1 + g.shape[0]] / m
    out = g.T @ smooth
    out = (out + out.T) / 2
    b = min(m / max(rows, 1), 1.0)
    return out / (1.0 - b + b * b / 3.0)


def solve(
    x: np.ndarray,
    y: np.ndarray,
    keep: np.ndarray,
    noise_cov: np.ndarray,
    lags: int | None,
    *,
    also: np.ndarray | None = None,
) -> Solution:
    """Bias-compensated least squares of y on the columns of x over the rows `keep`.

    x: (rows, p) in time order; noise_cov: (p, p) covariance of the noise in one row of x (zeros
    for exact columns); lags: Newey-West truncation in rows (None: coefficients only, cov NaN).
    Rows outside `keep` count as gaps in time (their contributions are zero), so the lag
    structure of the kept rows is kept. `also`: another right-hand side, whose coefficients
    come back as `also_beta` (same normal equations, no second factorisation).

    Raises:
        numpy.linalg.LinAlgError: the scaled system is singular (a column carries no signal).
    """
    w = keep.astype(np.float64)
    xw = x * w[:, None]  # the kept rows, zeros elsewhere
    n, p = int(keep.sum()), x.shape[1]
    gram = xw.T @ x
    scale = np.sqrt(np.diag(gram) / n)
    scale[scale == 0] = 1.0
    outer = np.outer(scale, scale)
    a_inv = np.linalg.inv(gram / outer - n * noise_cov / outer) / outer
    beta = a_inv @ (xw.T @ y)
    resid = y - x @ beta
    resid *= w
    cov = np.full((p, p), np.nan)
    if lags is not None:
        xw *= resid[:, None]
        cov = a_inv @ (newey_west(xw, lags, n) * n / max(n - p, 1)) @ a_inv
    mean_y = float(w @ y) / n
    return Solution(
        beta=beta,
        cov=cov,
        rss=float(resid @ resid),
        tss=float(w @ (y - mean_y) ** 2),
        rows=n,
        also_beta=None if also is None else a_inv @ (x.T @ (also * w)),
    )


def chi2_sf(stat: float, dof: int) -> float:
    """P(chi^2_dof > stat): closed form for even dof, scipy's incomplete gamma otherwise."""
    if dof % 2:
        from scipy.special import chdtrc

        return float(chdtrc(dof, stat))
    half = stat / 2.0
    term, total = 1.0, 1.0
    for j in range(1, dof // 2):
        term *= half / j
        total += term
    return float(np.exp(-half) * total)


def equality_p(values: np.ndarray, cov: np.ndarray) -> float:
    """p-value of the Wald test that all `values` are equal, given their covariance."""
    k = values.size
    if k < 2:
        return 1.0
    contrast = np.eye(k)[1:] - np.eye(k)[:-1]
    d = contrast @ values
    v = contrast @ cov @ contrast.T
    try:
        stat = float(d @ np.linalg.solve(v, d))
    except np.linalg.LinAlgError:
        return float("nan")
    return chi2_sf(stat, k - 1)
