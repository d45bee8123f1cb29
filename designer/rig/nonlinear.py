"""Beyond the linear model: k per amplitude band and c per frequency band, with a test of equality.

TPU is viscoelastic and can stiffen with strain, so the one k and one c of Eq 5 are averages. Here
the fit is repeated with the coefficient split by band: k per band of the instantaneous deflection
|r| (the secant stiffness there; a cubic spring rises with |r|), and k and c per band of the
instantaneous frequency of the motion (from its analytic signal; along the chirp that is a band of
time). Each band coefficient has a HAC standard error, and a Wald test says whether the bands
differ by more than their uncertainty.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .band import Channels
from .regress import equality_p, solve

#: bands per table
BANDS = 3
#: a band table is flagged when the equality test's p-value is below this
ALPHA = 0.01


@dataclass(frozen=True)
class BandTable:
    """Rows of {lower, upper, coefficients and standard errors, rows}; `p` tests that they are equal."""

    quantity: str
    rows: list[dict]
    p: float

    @property
    def varies(self) -> bool:
        return bool(self.p < ALPHA)

    def to_dict(self) -> dict:
        return {"rows": self.rows, "p_equal": self.p, "varies": self.varies}


def _trend(ch: Channels) -> np.ndarray:
    """Constant and linear-trend columns (offset and drift), time scaled to [-1, 1]."""
    span = max(float(ch.t[-1] - ch.t[0]), 1e-300)
    return np.stack([np.ones_like(ch.t), 2 * (ch.t - ch.t[0]) / span - 1], axis=1)


def _edges(values: np.ndarray, keep: np.ndarray) -> np.ndarray:
    """Band edges at the quantiles of `values` over the kept rows (equal rows per band)."""
    return np.quantile(values[keep], np.linspace(0.0, 1.0, BANDS + 1))


def _which(values: np.ndarray, edges: np.ndarray) -> np.ndarray:
    return np.clip(np.searchsorted(edges, values, side="right") - 1, 0, BANDS - 1)


def amplitude_table(ch: Channels, lags: int, scale: float, r_scale: float) -> BandTable:
    """k per band of |r - mean r| (secant stiffness), c and m shared; in rig units via `scale`."""
    r = ch.x[:, 2]
    deflection = r + ch.r_line
    dev = np.abs(deflection - deflection[ch.keep].mean())
    edges = _edges(dev, ch.keep)
    band = _which(dev, edges)
    split = np.stack([r * (band == b) for b in range(BANDS)], axis=1)
    x = np.concatenate([split, ch.x[:, :2], _trend(ch)], axis=1)
    noise = np.zeros((x.shape[1], x.shape[1]))
    share = np.array([np.mean(band[ch.keep] == b) for b in range(BANDS)])
    noise[np.arange(BANDS), np.arange(BANDS)] = ch.noise_cov[2, 2] * share
    noise[BANDS : BANDS + 2, BANDS : BANDS + 2] = ch.noise_cov[:2, :2]
    sol = solve(x, ch.y, ch.keep, noise, lags)
    k, se = sol.beta[:BANDS] * scale, sol.se[:BANDS] * scale
    rows = [
        {
            "from": float(edges[b] * r_scale),
            "to": float(edges[b + 1] * r_scale),
            "k": float(k[b]),
            "k_se": float(se[b]),
            "rows": int(np.sum(ch.keep & (band == b))),
        }
        for b in range(BANDS)
    ]
    return BandTable("k", rows, equality_p(sol.beta[:BANDS], sol.cov[:BANDS, :BANDS]))


def frequency_table(ch: Channels, m: float, lags: int, scale: float) -> BandTable:
    """k and c per band of instantaneous frequency, with m fixed at the headline fit (scaled units)."""
    freq = ch.inst_freq
    edges = _edges(freq, ch.keep)
    band = _which(freq, edges)
    cols = [ch.x[:, i] * (band == b) for b in range(BANDS) for i in (2, 1)]
    x = np.concatenate([np.stack(cols, axis=1), _trend(ch)], axis=1)
    noise = np.zeros((x.shape[1], x.shape[1]))
    for b in range(BANDS):
        share = np.mean(band[ch.keep] == b)
        idx = np.array([2 * b, 2 * b + 1])
        noise[np.ix_(idx, idx)] = ch.noise_cov[np.ix_([2, 1], [2, 1])] * share
    sol = solve(x, ch.y - m * ch.x[:, 0], ch.keep, noise, lags)
    beta, se = sol.beta * scale, sol.se * scale
    rows = [
        {
            "from_hz": float(edges[b]),
            "to_hz": float(edges[b + 1]),
            "k": float(beta[2 * b]),
            "k_se": float(se[2 * b]),
            "c": float(beta[2 * b + 1]),
            "c_se": float(se[2 * b + 1]),
            "rows": int(np.sum(ch.keep & (band == b))),
        }
        for b in range(BANDS)
    ]
    c_idx = np.arange(1, 2 * BANDS, 2)
    return BandTable("c", rows, equality_p(sol.beta[c_idx], sol.cov[np.ix_(c_idx, c_idx)]))
