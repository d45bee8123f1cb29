"""The study's excitation: the hub's linear chirp, one class for the virtual rig and the co-simulation.

q(t) = A sin(2 pi (f0 t + (f1 - f0) t^2 / (2 T))): A = 1 rad, f0 = 0.2 Hz, f1 = 1.85 Hz, T = 2200 s
(the study's section 3.2).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: the study's excitation
HUB_AMPLITUDE = 1.0
F0 = 0.2
F1 = 1.85
SWEEP = 2200.0
#: samples per period of the highest frequency a log or a co-simulation must carry (identification
#: needs the same: below it the chirp's top is aliased or too coarse to differentiate)
SAMPLES_PER_PERIOD = 10


@dataclass(frozen=True)
class Chirp:
    """The hub angle: `amplitude` (rad) sweeping from `f0` to `f1` (Hz) over `sweep` (s)."""

    amplitude: float = HUB_AMPLITUDE
    f0: float = F0
    f1: float = F1
    sweep: float = SWEEP

    def motion(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """q, q' and q'' at the times `t` (arrays of the shape of t), exact."""
        rate = (self.f1 - self.f0) / self.sweep
        phase = 2 * np.pi * (self.f0 * t + rate * t**2 / 2)
        omega = 2 * np.pi * (self.f0 + rate * t)
        s, c = np.sin(phase), np.cos(phase)
        a = self.amplitude
        return a * s, a * omega * c, a * (2 * np.pi * rate * c - omega**2 * s)

    def check_sampling(self, rate: float, *, what: str = "rate") -> None:
        """Raise DesignerError unless sampling at `rate` (Hz) carries the whole chirp.

        The sampling theorem allows frequencies up to rate / 2; differentiating and identifying the
        motion needs SAMPLES_PER_PERIOD samples per period of the highest one.
        """
        from .errors import DesignerError

        top = max(self.f0, self.f1)
        if rate < SAMPLES_PER_PERIOD * top:
            aliased = "is aliased" if top >= rate / 2 else "is sampled too coarsely"
            raise DesignerError(
                f"the chirp's {top:g} Hz {aliased} at {what} = {rate:g} Hz (the sampling theorem allows "
                f"up to {rate / 2:g} Hz; identification needs {SAMPLES_PER_PERIOD} samples per period)",
                f"lower f0/f1 below {rate / SAMPLES_PER_PERIOD:g} Hz "
                f"or sample at {SAMPLES_PER_PERIOD * top:g} Hz or more",
            )

    def __call__(self, t: float) -> tuple[float, float]:
        """The angle and its rate at time `t`, as a motor reference (rad, rad/s)."""
        q, dq, _ = self.motion(np.asarray(t, dtype=float))
        return float(q), float(dq)
