"""A sensor whose offset wanders below the excitation band: told from the joint, and filtered out.

The fit low-passes r, r', r'' and the load alike and models a constant and a straight trend, so a
sensor offset that drifts along a curve (a displacement sensor warming up, a load cell's zero
creeping) stays in one channel and not the other. The load does not follow a position sensor's
drift, so the fit takes it for motion the specimen resisted weakly: on a force-driven chirp (k 0.8
N/mm, 1.5 mm, 60 s at 1 kHz) an exponential offset drift of 1 / 3 mm gave k 0.768 / 0.617 N/mm, a
wander of 0.5 + 0.3 mm gave 0.553 N/mm, and the drift test named "k drifts as a warm-up, +100 %".

What tells it: the joint's residual below the motion is white noise like the residual just above
the motion's top, whatever the joint does (friction, a nonlinear spring and backlash leave their
residual at the motion's harmonics, viscoelastic damping and a drifting k at the motion's own
frequencies); a drifting offset leaves its power below the motion. Its mean power there over the
residual's median just above the band's top was 0.3-4.7 on clean logs and every departure of the
physics tests, 23 on a k warming up 5 % with a 12 s settling, and 1 700 - 170 000 on the drifting
offsets above. Beyond `RATIO`, both channels go through the same high-pass (so its gain cancels in
the regression as the low-pass's does) and the fit is made again: k 0.801, 0.801, 0.794 N/mm.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from . import band as bandlib

#: the residual's mean power below the cut over its median power above the band's top beyond which
#: a channel's offset drifts
RATIO = 200.0
#: the cut, as a fraction of the band's top (0.09 Hz for the study's chirp of 0.2-1.85 Hz): the
#: high-pass is zero below half of it and flat above it
CUT = 1 / 20


@dataclass(frozen=True)
class Drift:
    """A drifting offset found: the high-pass cut (Hz), the residual's power ratio, the column that
    drifts and its course below the cut that the other channel does not follow, peak to peak (in
    that column's unit)."""

    cut_hz: float
    ratio: float
    column: str
    span: float

    def to_dict(self) -> dict:
        return {"cut_hz": self.cut_hz, "ratio": self.ratio, "column": self.column, "span": self.span}


def _highpass(freqs: np.ndarray, cut: float) -> np.ndarray:
    """Zero below cut / 2, raised cosine to 1 at the cut."""
    x = np.clip((freqs - cut / 2) / (cut / 2), 0.0, 1.0)
    return 0.5 - 0.5 * np.cos(np.pi * x)


def residual_ratio(ch: bandlib.Channels, design: np.ndarray, beta: np.ndarray, top: float) -> float:
    """The fit's residual: its mean power below CUT x `top` over its median power between `top` and
    the filter's pass edge (there, only noise)."""
    e = np.where(ch.keep, ch.y - design @ beta, 0.0)
    power = np.abs(np.fft.rfft(e)) ** 2
    freqs = np.fft.rfftfreq(e.size, 1.0 / ch.rate)
    slow = power[(freqs > 0) & (freqs <= CUT * top)]
    noise = power[(freqs >= top) & (freqs <= ch.pass_edge)]
    if not slow.size or not noise.size or np.median(noise) <= 0:
        return 0.0
    return float(slow.mean() / np.median(noise))


def remove(spec: bandlib.Spectra, ratio: float, axis: str, k: float) -> tuple[bandlib.Spectra, Drift]:
    """Both channels through the high-pass at CUT x the band's top, the band starting there at the
    lowest, and the drift found. Which channel drifts: below the cut the chirp's own start leaks into
    both, the load following it by k (rig units, the first fit's); the drifting one holds more than
    that, and its course the other does not follow is the difference."""
    from .logs import LOAD

    cut = CUT * spec.band.high
    gain = _highpass(spec.freqs, cut)
    below = 1.0 - gain
    slow_r = np.fft.irfft(spec.position * below, n=spec.n)[: spec.samples] * spec.scale_r
    slow_f = np.fft.irfft(spec.load * below, n=spec.n)[: spec.samples] * spec.scale_f
    unfollowed = slow_r - slow_f / k
    if np.std(slow_r) * k >= np.std(slow_f):
        column, span = axis, float(np.ptp(unfollowed))
    else:
        column, span = LOAD[axis], float(np.ptp(unfollowed * k))
    band = bandlib.Band(low=max(spec.band.low, cut), high=spec.band.high)
    filtered = replace(spec, position=spec.position * gain, load=spec.load * gain, band=band)
    return filtered, Drift(cut, ratio, column, span)


def describe(drift: Drift, axis: str) -> str:
    """The warning: which channel's offset drifts, by how much, what was done, and the fix."""
    from .logs import UNITS

    return (
        f"the offset of '{drift.column}' drifts below the excitation band, {drift.span:.3g} "
        f"{UNITS[drift.column]} peak to peak off a straight line, and the other channel does not "
        f"follow (the fit's residual below {drift.cut_hz:.2g} Hz is {drift.ratio:.3g} times its "
        "noise): a sensor's zero wandering (warming up, creeping), not the joint; both channels were "
        f"high-passed alike at {drift.cut_hz:.2g} Hz and fitted again. Let the sensors warm up or "
        "re-zero them before logging"
    )
