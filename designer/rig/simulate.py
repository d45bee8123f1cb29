"""The virtual rig: drives a joint with the study's chirp and writes a log in the rig's schema.

The hub imposes the motion r(t) = A q(t) on every simulated axis, with the study's chirp
q(t) = sin(2 pi (f0 t + (f1 - f0) t^2 / (2 T))) (hub amplitude 1 rad, f0 = 0.2 Hz, f1 = 1.85 Hz,
T the duration), and the sensor reads the load F = m r'' + c r' + k r, plus Gaussian noise and
dropout segments (the sensor reading NaN or stuck at zero), as on the real rig.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd

from .. import units
from ..chirp import F0, F1, HUB_AMPLITUDE, SWEEP, Chirp
from ..errors import DesignerError
from ..joint import AxisCoefficients
from ..limits import check_memory
from .logs import LOAD, STUCK_SAMPLES

#: the study's excitation (section 3.2), its sweep the default duration
DURATION = SWEEP
RATE = 1000.0
#: length of one simulated dropout segment, s
DROPOUT_SECONDS = 0.05


def _check(name: str, value: float, positive: bool = True) -> float:
    v = float(value)
    if not np.isfinite(v) or v < 0 or (positive and v == 0):
        raise DesignerError(
            f"{name} = {value} is not valid",
            f"give a finite {'positive' if positive else 'non-negative'} number",
        )
    return v


def footprint(n_axes: int, *, duration: float, rate: float, parquet: bool = False) -> dict[str, float]:
    """Size of a simulated log before it is made: samples, peak memory of `simulate` and the file, bytes.

    Measured on `designer rig simulate` (2 axes): 116 B of peak memory and 106 B of CSV per sample;
    the estimate, 8 B x (8 + 6 per axis) and 22 B (CSV) or 8 B (Parquet) per value, is a little above.
    """
    samples = duration * rate + 1
    return {
        "samples": samples,
        "memory": 8.0 * samples * (8 + 6 * n_axes),
        "file": samples * (1 + 2 * n_axes) * (8 if parquet else 22),
    }


def simulate(
    coefficients: Mapping[str, Mapping[str, float]],
    duration: float = DURATION,
    rate: float = RATE,
    amplitude: float = 1.0,
    noise: float = 0.01,
    dropouts: float = 0.0,
    seed: int | None = None,
    f0: float = F0,
    f1: float = F1,
) -> pd.DataFrame:
    """A rig log of the joint `{axis: {"m", "c", "k"}}` (rig units, m in kg or kg.m^2).

    `amplitude` is the motion of each axis in its unit (mm or rad) per radian of hub; `noise` the
    force noise as a fraction of the RMS load; `dropouts` the fraction of samples in dropout segments.
    """
    duration, rate = _check("duration", duration), _check("rate", rate)
    amplitude, noise, dropouts = (
        _check("amplitude", amplitude),
        _check("noise", noise, False),
        _check("dropouts", dropouts, False),
    )
    _check("f0", f0), _check("f1", f1)
    Chirp(1.0, f0, f1, duration).check_sampling(rate)
    if dropouts >= 0.5:
        raise DesignerError(f"dropouts = {dropouts:g} is too large", "give a fraction below 0.5, e.g. 0.001")
    if not coefficients:
        raise DesignerError("no axis to simulate", "give m, c, k for at least one axis")
    check_memory(
        footprint(len(coefficients), duration=duration, rate=rate)["memory"],
        what=f"a {duration:g} s log at {rate:g} Hz on {len(coefficients)} axis/axes",
        fix="shorten the duration or lower the rate",
    )
    n = int(round(duration * rate)) + 1
    if n < 3 * STUCK_SAMPLES:
        raise DesignerError(f"{n} samples is too short a run", "raise duration or rate")
    rng = np.random.default_rng(seed)
    t = np.arange(n) / rate
    q, dq, ddq = Chirp(1.0, f0, f1, duration).motion(t)
    cols: dict[str, np.ndarray] = {"t": t}
    for axis, coef in coefficients.items():
        units.check_axis(axis)
        m = units.from_si("m_log", axis, _check(f"m on axis {axis}", coef.get("m", 0.0), False))
        c = _check(f"c on axis {axis}", coef["c"], False)
        k = _check(f"k on axis {axis}", coef["k"])
        AxisCoefficients(axis=axis, k=k, c=c)  # a joint's bounds: k = 5e-324 or 1e308 N/mm is refused
        r = amplitude * q
        load = m * amplitude * ddq + c * amplitude * dq + k * r
        load = load + noise * np.sqrt(np.mean(load**2)) * rng.standard_normal(n)
        _drop(rng, load, r, dropouts, max(2 * STUCK_SAMPLES, int(DROPOUT_SECONDS * rate)))
        cols[axis], cols[LOAD[axis]] = r, load
    cols["hub"] = HUB_AMPLITUDE * q
    return pd.DataFrame(cols)


def _drop(rng: np.random.Generator, load: np.ndarray, r: np.ndarray, fraction: float, length: int) -> None:
    """Blank `fraction` of the samples in segments: alternately NaN (load and coordinate) and zero load."""
    count = int(round(fraction * load.size / length))
    for i, start in enumerate(rng.integers(0, max(load.size - length, 1), size=count)):
        span = slice(start, start + length)
        if i % 2:
            load[span] = 0.0
        else:
            load[span] = np.nan
            r[span] = np.nan
