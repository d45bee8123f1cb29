"""Identification: per axis, the least-squares fit of F = m r'' + c r' + k r (the study's Eq 5).

Velocity and acceleration come from Savitzky-Golay differentiation of the coordinate; rows in or
near a dropout segment are left out. A constant sensor offset is fitted alongside and reported.
At the study's frequencies a gram-scale specimen's inertial force is about a thousandth of its
spring force, so m is often not identifiable: the result says so and gives the mass computed
from the specimen's geometry, walls, infill and TPU density instead.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import asdict, dataclass
from functools import cache
from pathlib import Path

import numpy as np
import pandas as pd

from .. import space, units
from ..errors import DesignerError
from ..mass import specimen_mass
from .logs import LOAD, RigLog, read_log

#: longest Savitzky-Golay window, s: short against the fastest period of the study's chirp (0.54 s)
WINDOW_S = 0.05
#: the window spans at most this fraction of the shortest period carrying the coordinate's power
WINDOW_PERIODS = 0.1
POLYORDER = 5
#: m counts as identified when its standard error is at most this fraction of it
M_REL_SE = 0.1
#: FFT block of the overlap-save derivative filter and of the low-band power test (fits in cache)
BLOCK = 16384


@dataclass(frozen=True)
class AxisFit:
    """One axis: m, c, k in rig units (m in kg or kg.m^2) with standard errors and fit quality."""

    axis: str
    m: float
    c: float
    k: float
    m_se: float
    c_se: float
    k_se: float
    offset: float
    r2: float
    #: RMS residual over the range of the load
    nrmse: float
    samples: int
    m_identified: bool
    #: mass from geometry (kg, translational axes with known factors) when m is not identified
    m_geometric: float | None
    #: inertial force against spring force at this excitation (RMS m r'' over RMS k r)
    inertia_ratio: float

    def mass(self) -> float | None:
        """The mass to use: the identified one, else the geometric one (None if neither)."""
        return self.m if self.m_identified else self.m_geometric

    def statement(self) -> str:
        """One sentence on the mass, for people."""
        unit = units.rig_unit("m", self.axis)
        fit = f"m = {self.m:.4g} +/- {self.m_se:.2g} {unit}"
        if self.m_identified:
            return f"{fit} (identified)"
        why = (
            f"m is not identifiable from this excitation ({fit}; inertial force about "
            f"{100 * self.inertia_ratio:.2g} % of the spring force)"
        )
        if self.m_geometric is not None:
            return (
                f"{why}; use the mass from geometry, walls, infill and TPU density: "
                f"{1e3 * self.m_geometric:.3g} g"
            )
        if units.is_rotational(self.axis):
            return f"{why}; take the inertia from CAD"
        return f"{why}; give the specimen's factors in the log's sidecar to get the mass from geometry"


@dataclass(frozen=True)
class Identification:
    """The fits of one log, keyed by axis, with where the log came from and its factors."""

    path: Path | None
    factors: dict[str, float] | None
    rate: float
    axes: dict[str, AxisFit]

    def to_dict(self) -> dict:
        return {
            "path": None if self.path is None else str(self.path),
            "factors": self.factors,
            "rate_hz": self.rate,
            "axes": {a: asdict(f) | {"statement": f.statement()} for a, f in self.axes.items()},
        }


def _top_frequency(r: np.ndarray, rate: float) -> float:
    """Frequency below which 99 % of the coordinate's power lies, Hz."""
    from scipy.fft import next_fast_len, rfft

    n = next_fast_len(r.size, real=True)
    power = np.abs(rfft(r - r.mean(), n=n)) ** 2
    cumulative = np.cumsum(power)
    if cumulative[-1] == 0:
        return rate / 2
    return float(np.searchsorted(cumulative, 0.99 * cumulative[-1]) * rate / n)


@cache
def _twiddles(n: int, cols: int, top: int) -> np.ndarray:
    """exp(-2 pi i j k / n) for the columns j < cols and the bins k <= top of the four-step FFT."""
    return np.exp(-2j * np.pi * (np.arange(cols)[:, None] * np.arange(top + 1) % n) / n)


def _below_99(r: np.ndarray, rate: float, f_cap: float) -> bool:
    """Whether 99 % of the coordinate's power lies at or below f_cap: `_top_frequency <= f_cap`.

    Same spectrum, same bins, at a fraction of the cost: the bins up to f_cap come from one
    four-step pass (batched in-cache FFTs over the columns of the padded signal, then twiddles),
    and the total power from Parseval in the time domain. False when that cannot be decided cheaply.
    """
    from scipy.fft import next_fast_len, rfft

    n = next_fast_len(r.size, real=True)
    top = int(np.floor(f_cap * n / rate))
    while (top + 1) * rate / n <= f_cap:
        top += 1
    while top >= 0 and top * rate / n > f_cap:
        top -= 1
    cols = next((c for c in range(64, 1024) if n % c == 0 and n // c > 2 * (top + 1)), None)
    if top < 0 or cols is None:
        return False
    x = np.zeros(n)
    np.subtract(r, r.mean(), out=x[: r.size])
    # X[k] = sum_j exp(-2 pi i j k / n) * FFT_{n/cols}(x[j::cols])[k], for k < n / cols
    inner = rfft(x.reshape(n // cols, cols).T, axis=1)[:, : top + 1]
    low = np.einsum("jk,jk->k", inner, _twiddles(n, cols, top))
    spectrum0, nyquist = x.sum(), x[::2].sum() - x[1::2].sum()
    total = (n * float(x @ x) + spectrum0**2 + nyquist**2) / 2
    return total == 0 or float(np.sum(low.real**2 + low.imag**2)) >= 0.99 * total


def _window(r: np.ndarray, rate: float, window_s: float | None, polyorder: int) -> int:
    """Odd Savitzky-Golay window length in samples; by default from the excitation's top frequency."""
    if window_s is None:
        f_cap = WINDOW_PERIODS / WINDOW_S
        if _below_99(r, rate, f_cap):
            window_s = WINDOW_S
        else:
            window_s = min(WINDOW_S, WINDOW_PERIODS / max(_top_frequency(r, rate), 1e-9))
    return max(int(round(window_s * rate)) | 1, (polyorder + 2) | 1)


@cache
def _kernel_spectra(win: int, polyorder: int, dt: float, block: int) -> np.ndarray:
    """Spectra of the Savitzky-Golay kernels (r'', r', r) as circular correlations on one block."""
    from scipy.fft import rfft
    from scipy.signal import savgol_coeffs

    half = win // 2
    g = np.zeros((3, block))
    for i, d in enumerate((2, 1, 0)):
        g[i, -np.arange(-half, half + 1) % block] = savgol_coeffs(
            win, polyorder, deriv=d, delta=dt, use="dot"
        )
    return rfft(g, axis=1)


def _derivatives(r: np.ndarray, win: int, polyorder: int, dt: float) -> np.ndarray:
    """Savitzky-Golay r'', r', r (rows) by overlap-save FFT filtering in cache-sized blocks.

    Equal to `savgol_filter` away from the first and last win // 2 rows (which the fit leaves out),
    and closer to the exact sums than its direct convolution.
    """
    from numpy.lib.stride_tricks import sliding_window_view
    from scipy.fft import irfft, rfft

    half = win // 2
    block = max(BLOCK, 1 << (4 * win - 1).bit_length())
    step = block - 2 * half
    blocks = -(-r.size // step)
    padded = np.zeros(blocks * step + 2 * half)
    padded[half : half + r.size] = r
    spectra = rfft(sliding_window_view(padded, block)[::step], axis=1)
    out = np.empty((3, blocks * step))
    for i, kernel in enumerate(_kernel_spectra(win, polyorder, dt, block)):
        filtered = irfft(spectra * kernel, n=block, axis=1)
        out[i].reshape(blocks, step)[:] = filtered[:, half : block - half]
    return out[:, : r.size]


def _dilate(mask: np.ndarray, size: int) -> np.ndarray:
    """Rows within size // 2 of a True row (a 1-D maximum filter of a sparse mask)."""
    rows = np.flatnonzero(mask)
    edges = np.zeros(mask.size + 1, dtype=np.int32)
    np.add.at(edges, np.clip(rows - size // 2, 0, mask.size), 1)
    np.add.at(edges, np.clip(rows + size // 2 + 1, 0, mask.size), -1)
    return np.cumsum(edges[:-1]) > 0


def fit_axis(log: RigLog, axis: str, window_s: float | None = None, polyorder: int = POLYORDER) -> AxisFit:
    """Least-squares m, c, k (and offset) of one axis of a validated log."""
    if axis not in log.axes:
        raise DesignerError(f"axis {axis} is not in the log", f"the log has {', '.join(log.axes)}")
    r_filled = np.where(log.dropouts[axis], 0.0, log.data[axis].to_numpy())
    win = _window(r_filled, log.rate, window_s, polyorder)
    if win > len(log.data):
        raise DesignerError(
            f"the log has {len(log.data)} rows, fewer than the {win}-sample derivative window",
            "record a longer run",
        )
    dt = 1.0 / log.rate
    force = log.data[LOAD[axis]].to_numpy()
    bad = _dilate(log.dropouts[axis], 2 * win + 1)
    bad[: win // 2] = bad[-(win // 2) :] = True
    keep = ~bad
    if keep.sum() < 10 * win:
        raise DesignerError(
            f"axis {axis}: only {int(keep.sum())} samples outside dropouts",
            "the log has too little valid data to identify; record again",
        )
    y = force[keep]
    # columns r'', r', r (rows here) and the constant; left-out rows zeroed instead of copied out
    bad_rows = np.flatnonzero(bad)
    d = _derivatives(r_filled, win, polyorder, dt)
    d[:, bad_rows] = 0.0
    y0 = np.where(keep, force, 0.0)
    gram = np.empty((4, 4))
    gram[:3, :3] = d @ d.T
    gram[:3, 3] = gram[3, :3] = d.sum(axis=1)
    gram[3, 3] = y.size
    moment = np.append(d @ y0, y.sum())
    scale = np.sqrt(np.diag(gram) / y.size)
    scale[scale == 0] = 1.0
    # normal equations of the column-scaled problem: four well-scaled columns
    gram_inv = np.linalg.pinv(gram / np.outer(scale, scale))
    beta_s = gram_inv @ (moment / scale)
    beta = beta_s / scale
    resid = y0 - beta[:3] @ d - beta[3]
    resid[bad_rows] = 0.0
    rss = float(resid @ resid)
    dof = max(y.size - gram.shape[0], 1)
    sigma2 = rss / dof
    se = np.sqrt(np.diag(sigma2 * gram_inv)) / scale
    ss_tot = float(np.sum((y - y.mean()) ** 2))
    r2 = 1.0 - rss / ss_tot if ss_tot > 0 else float("nan")
    span = float(y.max() - y.min())
    nrmse = float(np.sqrt(rss / y.size) / span) if span > 0 else float("nan")
    m_log, c, k, offset = (float(v) for v in beta)
    m = units.to_si("m_log", axis, m_log)
    m_se = units.to_si("m_log", axis, float(se[0]))
    identified = m > 0 and m_se <= M_REL_SE * m
    geometric = (
        specimen_mass(log.factors) if log.factors is not None and not units.is_rotational(axis) else None
    )
    spring = abs(k) * float(scale[2])
    inertia_ratio = abs(m_log) * float(scale[0]) / spring if spring > 0 else float("inf")
    return AxisFit(
        axis=axis,
        m=m,
        c=c,
        k=k,
        m_se=m_se,
        c_se=float(se[1]),
        k_se=float(se[2]),
        offset=offset,
        r2=r2,
        nrmse=nrmse,
        samples=int(len(y)),
        m_identified=bool(identified),
        m_geometric=None if identified else geometric,
        inertia_ratio=inertia_ratio,
    )


def identify(
    log_or_path: RigLog | str | Path,
    axes: list[str] | None = None,
    window_s: float | None = None,
    progress: Callable[[float], None] | None = None,
) -> Identification:
    """Identify every axis of a log (or the listed ones): m, c, k with standard errors, R2, NRMSE."""
    log = log_or_path if isinstance(log_or_path, RigLog) else read_log(log_or_path)
    chosen = log.axes if axes is None else axes
    # one thread per axis: the FFTs and array arithmetic release the GIL
    with ThreadPoolExecutor(max_workers=min(len(chosen), os.cpu_count() or 1)) as pool:
        futures = [pool.submit(fit_axis, log, axis, window_s) for axis in chosen]
        fits = {}
        for i, (axis, future) in enumerate(zip(chosen, futures, strict=True)):
            fits[axis] = future.result()
            if progress is not None:
                progress((i + 1) / len(chosen))
    return Identification(path=log.path, factors=log.factors, rate=log.rate, axes=fits)


def results_table(results: list[Identification]) -> pd.DataFrame:
    """The coefficient table `designer fit` reads: factors, c and k per axis, m where identified.

    An axis's m column appears only when m was identified in every log; fit quality (`r2_<axis>`,
    `nrmse_<axis>`) and the log's path ride along as extra columns.
    """
    rows = []
    for res in results:
        if res.factors is None:
            raise DesignerError(
                f"{res.path}: no factors", "write them to the log's JSON sidecar to build a coefficient table"
            )
        rows.append(dict(res.factors))
    axes = [a for a in units.AXES if all(a in r.axes for r in results)]
    if not axes:
        raise DesignerError("the logs share no axis", "identify logs of the same axes together")
    for row, res in zip(rows, results, strict=True):
        for a in axes:
            f = res.axes[a]
            row[f"c_{a}"], row[f"k_{a}"] = f.c, f.k
            if all(r.axes[a].m_identified for r in results):
                row[f"m_{a}"] = f.m
            row[f"r2_{a}"], row[f"nrmse_{a}"] = f.r2, f.nrmse
        row["log"] = str(res.path)
    table = pd.DataFrame(rows)
    front = list(space.FACTOR_NAMES) + [
        f"{q}_{a}" for a in axes for q in units.QUANTITIES if f"{q}_{a}" in table
    ]
    return table[front + [col for col in table.columns if col not in front]]
