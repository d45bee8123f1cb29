"""The study's excitation (section 3.2): the hub's chirp, apart from the rig simulator so that the
co-simulation's references can use it without importing pandas."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

HUB_AMPLITUDE = 1.0
F0 = 0.2
F1 = 1.85
DURATION = 2200.0


@dataclass(frozen=True)
class Chirp:
    """q(t) = sin(2 pi (f0 t + (f1 - f0) t^2 / (2 T))) and its exact derivatives."""

    f0: float = F0
    f1: float = F1
    duration: float = DURATION

    def __call__(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """q, q' and q'' at the times t."""
        sweep = (self.f1 - self.f0) / self.duration
        phase = 2 * np.pi * (self.f0 * t + sweep * t**2 / 2)
        omega = 2 * np.pi * (self.f0 + sweep * t)
        s, c = np.sin(phase), np.cos(phase)
        return s, omega * c, 2 * np.pi * sweep * c - omega**2 * s
