"""The virtual rig through the FMU: the study's hub chirp drives a joint FMU's body interface.

The hub is a position servo on the specimen's free coordinate, F = K (q - s) + C (q' - v), with
K = 4 k and C giving a critically damped loop; the force sensor reads F. The log it writes is the
rig's schema, so `designer identify` can be run on it. The reference is the same closed loop solved
in one piece by scipy at tight tolerance.
"""

from __future__ import annotations

import ctypes
from collections.abc import Mapping
from ctypes import c_double, c_int64

import numpy as np

from ..errors import DesignerError
from . import binding as kb
from .references import Chirp

#: hub servo stiffness as a multiple of the specimen's k
HUB_GAIN = 4.0


class ServoStruct(ctypes.Structure):
    """kernel.h ks_servo: the hub as the compiled kernel runs it."""

    _fields_ = [
        ("chirp", kb.Reference),
        ("stiffness", c_double),
        ("damping", c_double),
        ("out", c_double * 2),
        ("steps", c_int64),
        ("h", c_double),
    ]


class HubServo:
    """The hub: inputs s, v of the specimen (SI); outputs the load F on it and the hub position q."""

    feedthrough = True
    inputs = ["s", "v"]
    outputs = ["f", "q"]

    def __init__(self, chirp: Chirp, stiffness: float, damping: float) -> None:
        self.chirp = chirp
        self.stiffness = stiffness
        self.damping = damping
        self._out = np.zeros(2)
        self.reset()

    def reset(self) -> None:
        """Back to t = 0."""
        self._steps = 0
        self._h = 0.0
        self._out[:] = 0.0

    def set(self, values: np.ndarray) -> None:
        q, dq = self.chirp(self._steps * self._h)
        self._out[0] = self.stiffness * (q - values[0]) + self.damping * (dq - values[1])
        self._out[1] = q

    def get(self) -> np.ndarray:
        return self._out.copy()

    def do_step(self, h: float) -> None:
        self._h = h
        self._steps += 1

    def tune(self, law: Mapping[str, float], step: float) -> None:
        """Set the servo's gains for a joint with SI `law` m, c, k (servo_gains).

        Raises:
            DesignerError: the sampled loop would be unstable at macro step `step` (s).
        """
        check_stable(law["m"], law["c"], law["k"], step)
        self.stiffness, self.damping = servo_gains(law["m"], law["c"], law["k"])

    def binding(self) -> kb.Binding:
        """The hub for the compiled kernel (see designer.cosim.binding)."""
        keep: list = []
        struct = ServoStruct(kb.reference(self.chirp, keep))
        keep.append(struct)

        def start(step: float) -> int:
            struct.stiffness, struct.damping = self.stiffness, self.damping
            struct.out[:] = list(self._out)
            struct.steps, struct.h, struct.chirp.cursor = self._steps, self._h, 0
            return self._steps

        def finish(steps: int) -> None:
            self._steps, self._h, self._out[:] = struct.steps, struct.h, list(struct.out)

        return kb.Binding(kb.SERVO, ctypes.addressof(struct), start, finish, keep=keep, struct=struct)


def servo_gains(m: float, c: float, k: float) -> tuple[float, float]:
    """Hub stiffness and damping (SI) for a critically damped loop around the specimen."""
    stiffness = HUB_GAIN * k
    return stiffness, max(2.0 * np.sqrt((k + stiffness) * m) - c, 0.0)


def check_stable(m: float, c: float, k: float, step: float) -> None:
    """Raise a DesignerError if the sampled hub servo would be unstable at this macro step."""
    from scipy.linalg import expm

    stiffness, damping = servo_gains(m, c, k)
    a = np.array([[0.0, 1.0, 0.0], [-k / m, -c / m, 1.0 / m], [0.0, 0.0, 0.0]])
    phi = expm(a * step)
    closed = phi[:2, :2] - phi[:2, 2:] @ np.array([[stiffness, damping]])
    radius = max(abs(np.linalg.eigvals(closed)))
    if radius >= 1.0:
        limit = 1.0 / np.sqrt((k + stiffness) / m)
        raise DesignerError(
            f"the rig's hub servo is unstable at step {step:g} s for this joint "
            f"(natural frequency {np.sqrt(k / m) / 2 / np.pi:.4g} Hz)",
            f"use a step below about {limit:.2g} s",
        )


def reference(m: float, c: float, k: float, chirp: Chirp, time: np.ndarray) -> np.ndarray:
    """The specimen's coordinate s(t) (SI) of the hub and specimen solved together (DOP853, rtol 1e-11)."""
    from scipy.integrate import solve_ivp

    stiffness, damping = servo_gains(m, c, k)

    def rhs(t, y):
        q, dq = chirp(t)
        force = stiffness * (q - y[0]) + damping * (dq - y[1])
        return [y[1], (force - c * y[1] - k * y[0]) / m]

    sol = solve_ivp(
        rhs,
        (0.0, float(time[-1])),
        [0.0, 0.0],
        method="DOP853",
        t_eval=time,
        rtol=1e-11,
        atol=1e-14,
        max_step=0.05 / max(chirp.f0, chirp.f1),
    )
    if not sol.success:
        raise DesignerError(f"the rig reference did not solve: {sol.message}", "shorten the validation span")
    return sol.y[0]
