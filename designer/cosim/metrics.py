"""Per-joint metrics of a robot run: tracking, deflection, overshoot, settling, energy dissipated."""

from __future__ import annotations

import numpy as np

from .references import Reference, Step

#: settling band, fraction of the step
SETTLE_BAND = 0.02


def joint_metrics(
    time: np.ndarray, q: np.ndarray, motor: np.ndarray, v: np.ndarray, c: float, ref: Reference
) -> dict:
    """Metrics of one joint: angles rad, times s, energy J (c in N.m.s/rad, v the deflection rate)."""
    s = q - motor
    power = c * v**2
    out = {
        "tracking_rms_rad": float(np.sqrt(np.mean(s**2))),
        "peak_deflection_rad": float(np.max(np.abs(s))),
        "energy_dissipated_J": float(np.sum(0.5 * (power[1:] + power[:-1]) * np.diff(time))),
        "overshoot_pct": None,
        "settling_time_s": None,
    }
    if isinstance(ref, Step) and ref.amplitude != 0 and time[-1] > ref.at:
        after = time >= ref.at
        target = ref.initial + ref.amplitude
        beyond = (q[after] - target) * np.sign(ref.amplitude)
        out["overshoot_pct"] = float(max(beyond.max(), 0.0) / abs(ref.amplitude) * 100.0)
        outside = np.flatnonzero(np.abs(q[after] - target) > SETTLE_BAND * abs(ref.amplitude))
        if len(outside) == 0:
            out["settling_time_s"] = 0.0
        elif outside[-1] < after.sum() - 1:
            out["settling_time_s"] = float(time[after][outside[-1] + 1] - ref.at)
    return out
