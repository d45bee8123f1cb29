"""Natural frequency and the largest stable MuJoCo timestep of a spring-damper joint.

One degree of freedom with inertia M (the link about the joint axis plus armature, kg.m^2 or kg),
stiffness k and damping c (SI) obeys M q'' + c q' + k q = 0. MuJoCo's integrators step it as:

- Euler (semi-implicit, joint damping implicit, MuJoCo's default `eulerdamp`) and implicitfast
  (velocity derivatives implicit, so the joint damping again; the stiffness stays explicit):
  v+ = v + h (-k q - c v) / (M + h c), q+ = q + h v+. The step matrix has determinant M / (M + h c)
  and trace 1 + M / (M + h c) - h^2 k / (M + h c); by the Jury criterion it is stable while
  k h^2 - 2 c h - 4 M < 0, that is h < (c + sqrt(c^2 + 4 k M)) / k (2 / omega_n without damping).
- RK4 (explicit): stable while |R(h lambda)| <= 1 for both roots lambda of M s^2 + c s + k, with
  R(z) = 1 + z + z^2/2 + z^3/6 + z^4/24 (2 sqrt(2) / omega_n without damping; heavy damping makes the
  fast real root the limit, -2.785 / lambda).

tests/test_robot_formats.py checks these against MuJoCo stepping just below and above each limit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import DesignerError

#: the integrators the advice covers, by MuJoCo's option names
INTEGRATORS = ("Euler", "implicitfast", "RK4")


@dataclass(frozen=True)
class StepAdvice:
    """Natural frequency (Hz), damping ratio, the largest stable timestep (s) per integrator, and the
    inertia (kg.m^2, or kg on a slide) they were computed with, with what that inertia is (`basis`:
    about which axis, from what, other joints how): another reading of the same file moves them."""

    inertia: float
    natural_frequency: float
    damping_ratio: float
    max_timestep: dict[str, float]
    basis: str = ""

    def to_dict(self) -> dict[str, object]:
        return {
            "inertia_si": self.inertia,
            "natural_frequency_hz": self.natural_frequency,
            "damping_ratio": self.damping_ratio,
            "max_stable_timestep_s": dict(self.max_timestep),
            "inertia_basis": self.basis,
        }

    def text(self) -> str:
        """One line for an XML comment or a terminal: frequency and the three step limits."""
        steps = ", ".join(f"{n} {h * 1e3:.3g} ms" for n, h in self.max_timestep.items())
        basis = f"; {self.basis}" if self.basis else ""
        return (
            f"natural frequency {self.natural_frequency:.4g} Hz "
            f"(moving inertia {self.inertia:.4g} SI{basis}), "
            f"damping ratio {self.damping_ratio:.3g}; "
            f"largest stable timestep: {steps}"
        )


def _rk4_limit(k: float, c: float, inertia: float) -> float:
    """Largest h with |R(h lambda)| <= 1 for both roots: a scan, then bisection on the first crossing."""
    roots = np.roots([inertia, c, k])

    def stable(h: float) -> bool:
        z = h * roots
        return bool(np.all(np.abs(1 + z + z**2 / 2 + z**3 / 6 + z**4 / 24) <= 1.0))

    # the RK4 region reaches no further than |z| = 2.97 along any ray of the left half-plane
    grid = np.linspace(0.0, 3.0 / np.max(np.abs(roots)), 2001)[1:]
    first_bad = next(i for i, h in enumerate(grid) if not stable(h))
    lo, hi = (grid[first_bad - 1] if first_bad else 0.0), grid[first_bad]
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if stable(mid) else (lo, mid)
    return float(lo)


def step_advice(k: float, c: float, inertia: float, *, basis: str = "") -> StepAdvice:
    """Natural frequency, damping ratio and stable timesteps of M q'' + c q' + k q = 0 (SI); `basis`
    says what the inertia is.

    Raises:
        DesignerError: when k or inertia is not positive or c is negative.
    """
    if not (k > 0 and inertia > 0 and c >= 0 and math.isfinite(k + c + inertia)):
        raise DesignerError(
            f"no step advice for k = {k:g}, c = {c:g}, inertia = {inertia:g} (SI)",
            "k and inertia must be positive and c non-negative",
        )
    omega = math.sqrt(k / inertia)
    implicit = (c + math.sqrt(c * c + 4 * k * inertia)) / k
    return StepAdvice(
        inertia=inertia,
        natural_frequency=omega / (2 * math.pi),
        damping_ratio=c / (2 * math.sqrt(k * inertia)),
        max_timestep={"Euler": implicit, "implicitfast": implicit, "RK4": _rk4_limit(k, c, inertia)},
        basis=basis,
    )
