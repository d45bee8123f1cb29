"""A coarse position encoder: what its steps alone do to k, c and the departure tests.

An encoder reads the position rounded to its step. Its error is no white noise but a sawtooth of
the position itself: the fit regresses the load on a staircase of the motion, whose fundamental is
N(A) times the motion's, N the quantizer's describing function at the motion's amplitude A (the
first Fourier coefficient of Q(A sin th) over A sin th's). So k and c come out 1/N(A) - 1 off, and,
as N varies with the amplitude, k seems to depend on the deflection: a "spring". Measured on a
1.5 mm force-driven chirp (k 0.8 N/mm, 60 s at 1 kHz): steps of 0.2 / 0.1 / 0.05 / 0.02 mm gave k
+2.0 / -0.19 / -0.07 / -0.02 %, where 1/N(1.5 mm) - 1 is +1.85 / -0.19 / -0.07 / -0.02 %, and the
0.2 and 0.1 mm ones were named a stiffening or softening spring (secant +5 % / -0.8 %).

N(A) swings with where the peak falls between two steps, which the reading itself cannot tell
within half a step; so k and c get the largest |1/N - 1| over peaks within half a step of the
motion's in their standard errors, and a spring whose secant change lies within the span of
1/N - 1 over amplitudes from half the peak up, or a dead band under half a step, is the encoder's.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import units
from .departures import Departure

#: a channel is read through an encoder when it takes at most this share of distinct values
#: (a noisy analogue reading takes nearly one per sample)
DISTINCT_SHARE = 0.5
#: an encoder with at least this many steps to the motion's peak is not looked at: its bias is
#: under 0.02 % of k (and 75 steps of 0.02 mm moved k by 0.02 %, within a clean log's error)
MAX_STEPS = 200
#: fewer steps to the peak than this, and the axis is refused: a staircase of a few steps bends every
#: departure test (7 steps of 0.2 mm on 1.5 mm: k +2 %, a stiffening spring and a warm-up drift)
MIN_STEPS = 10
#: samples read to find the step
PROBE = 20_000
#: points of the describing function's quadrature over one period, and amplitudes of its span
_ANGLES = np.sin(np.linspace(0.0, 2 * np.pi, 4096, endpoint=False))
_SPAN_POINTS = 200


@dataclass(frozen=True)
class Effect:
    """A coarse encoder's share of a fit: its step, the motion's peak in steps, the largest relative
    bias of k and c for a peak within half a step of the motion's, and the range of that bias over
    amplitudes from half the peak up (what it can make k's amplitude dependence look like)."""

    step: float
    peak: float
    bias: float
    span: tuple[float, float]

    def to_dict(self) -> dict:
        return {
            "step": self.step,
            "steps_to_peak": self.steps_to_peak,
            "bias": self.bias,
            "span": self.span,
        }

    @property
    def steps_to_peak(self) -> float:
        return self.peak / self.step

    def fakes(self, dep: Departure, k: float) -> bool:
        """Whether the encoder's steps alone can make this departure: a spring whose secant change at
        the peak lies within the span, or a dead band under half a step (a 0.1 mm encoder alone made
        one of 0.008 mm; a real one of 0.1 mm read by it is backlash, k within 0.7 %)."""
        if dep.name == "spring":
            return abs(dep.value) * self.peak**2 / k <= max(abs(self.span[0]), abs(self.span[1]))
        if dep.name == "backlash":
            return 2 * abs(dep.value) / k < self.step / 2
        return False


def step(values: np.ndarray) -> float | None:
    """The step of a channel read in steps (the smallest difference between its levels), or None
    when it takes nearly as many values as samples (an analogue reading)."""
    sample = values[:: max(values.size // PROBE, 1)]
    sample = sample[np.isfinite(sample)]
    levels = np.unique(sample)
    if levels.size < 2 or levels.size > DISTINCT_SHARE * sample.size:
        return None
    return float(np.diff(levels).min())


def _bias(amplitude: float, size: float, offset: float) -> float:
    """1/N - 1: the relative error of k and c when a motion of this amplitude about its centre is
    read in steps of `size` on a grid `offset` from that centre (N the describing function)."""
    read = offset + size * np.round((amplitude * _ANGLES - offset) / size)
    fundamental = 2 * float(np.mean(read * _ANGLES))
    return amplitude / fundamental - 1.0 if fundamental > 0 else np.inf


def effect(position: np.ndarray) -> Effect | None:
    """A coarse encoder's `Effect` on a fit of this position channel (rig units); None for an
    analogue channel or a fine encoder (MAX_STEPS or more to the peak). The peak is half the span of
    the levels read: the motion's own lies within half a step of it."""
    size = step(position)
    finite = position[np.isfinite(position)]
    peak = 0.5 * (float(finite.max()) - float(finite.min())) if finite.size else 0.0
    if size is None or size <= 0 or peak / size >= MAX_STEPS:
        return None
    centre = 0.5 * (float(finite.max()) + float(finite.min()))
    offset = (float(finite[0]) - centre) % size
    near = [abs(_bias(a, size, offset)) for a in np.linspace(peak - size / 2, peak + size / 2, 21)]
    spread = [_bias(a, size, offset) for a in np.linspace(peak / 2, peak, _SPAN_POINTS)]
    return Effect(size, peak, float(max(near)), (float(min(spread)), float(max(spread))))


def describe(encoder: Effect, axis: str, faked: list[Departure], k: float) -> str:
    """The warning on a coarse encoder: its step, its bias, the departures it made, and the fix."""
    ru = units.rig_unit("r", axis)
    lo, hi = (100 * v for v in encoder.span)
    made = [
        f"the {'stiffening' if d.value > 0 else 'softening'} spring (secant "
        f"{100 * d.value * encoder.peak**2 / k:+.2g} %)"
        if d.name == "spring"
        else f"the dead band of {2 * abs(d.value) / k:.2g} {ru}"
        for d in faked
    ]
    return (
        f"{axis} is read in steps of {encoder.step:.3g} {ru} ({encoder.steps_to_peak:.3g} to the motion's "
        f"peak): read this coarsely, a linear joint fits k and c up to {100 * encoder.bias:.2g} % off (the "
        f"steps' describing function, for a peak within half a step of {encoder.peak:.3g} {ru}), and its k "
        "seems "
        f"to vary from {lo:+.2g} % to {hi:+.2g} % over amplitudes from half the peak up"
        + (
            f": {' and '.join(made)} {'lie' if len(made) > 1 else 'lies'} within that, the encoder's, not "
            "the specimen's"
            if made
            else ""
        )
        + "; k's and c's standard errors include that bias. Read the position with a finer encoder "
        f"(at least {MAX_STEPS} steps to the peak) or a larger motion"
    )


def too_coarse(encoder: Effect, axis: str) -> str | None:
    """Why an axis read in under MIN_STEPS steps to its peak is refused; None when it is not."""
    if encoder.steps_to_peak >= MIN_STEPS:
        return None
    ru = units.rig_unit("r", axis)
    return (
        f"{axis} is read in steps of {encoder.step:.3g} {ru}, only {encoder.steps_to_peak:.3g} to the "
        f"motion's peak of {encoder.peak:.3g} {ru}: a staircase that coarse bends k (up to "
        f"{100 * encoder.bias:.2g} %) and fakes a nonlinear spring, backlash or drift; read the position "
        f"with a finer encoder (at least {MAX_STEPS} steps to the peak) or a larger motion"
    )
