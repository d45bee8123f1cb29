"""The kernel contract: what a system hands the compiled stepping kernel (fmus/kernel/kernel.h).

A system the kernel can run has, besides the master's `System` protocol, a `binding() -> Binding`:
its kind (the C switch in fmus/kernel/systems.c), the address of its instance (its own C struct, or
an FMU instance with its FMI functions), its input and output value references, and the calls the
kernel makes around a run (`start` before, `finish` after, `event` and `error` when the C loop
stops for them). The kernel (`designer.cosim.kernel`) binds a master's systems once, through this
description only: a new kind of system is its own module (its struct mirror and `binding()`) plus
its C case, nothing in the kernel's Python.

Also here: the C struct of a motor reference (`Reference`, `reference()`), shared by the robot's
motors and the rig's hub chirp.
"""

from __future__ import annotations

import ctypes
from collections.abc import Callable, Mapping
from ctypes import POINTER, c_double, c_int32, c_int64
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import DesignerError
from .references import Chirp, Sine, Step, Trajectory

#: kinds of system (kernel.h: KS_ROBOT, KS_FMI2, KS_FMI3, KS_SERVO)
ROBOT, FMI2, FMI3, SERVO = 0, 1, 2, 3
#: which call failed, as the kernel reports it (kernel.h: KS_CALL_*)
CALLS = ("set", "get", "step", "time", "completed")
P_DOUBLE = POINTER(c_double)
P_INT = POINTER(c_int32)


class Reference(ctypes.Structure):
    """kernel.h ks_reference: a motor reference (step, sine, chirp or a sampled table)."""

    _fields_ = [
        ("kind", c_int32),
        ("n", c_int32),
        ("p", c_double * 4),
        ("t", P_DOUBLE),
        ("q", P_DOUBLE),
        ("cursor", c_int64),
    ]


def ints(values) -> np.ndarray:
    """`values` as a contiguous int32 array (what the C side's `const int32_t *` point to)."""
    return np.ascontiguousarray(values, dtype=np.int32)


def pointer(array: np.ndarray, kind=P_DOUBLE):
    """A ctypes pointer to `array`'s data (keep the array alive as long as the pointer)."""
    return array.ctypes.data_as(kind)


def reference(ref, keep: list) -> Reference:
    """A motor reference as the kernel's struct; arrays it points to are appended to `keep`.

    Raises:
        DesignerError: a reference type the kernel does not know (a Python callable), or a
            trajectory without samples.
    """
    out = Reference()
    if isinstance(ref, Step):
        out.kind, params = 0, (ref.amplitude, ref.at, ref.initial)
    elif isinstance(ref, Sine):
        out.kind, params = 1, (ref.amplitude, ref.frequency, ref.offset, ref.phase)
    elif isinstance(ref, Chirp):
        out.kind, params = 2, (ref.amplitude, ref.f0, ref.f1, ref.sweep)
    elif isinstance(ref, Trajectory):
        t, q = np.ascontiguousarray(ref.t, float), np.ascontiguousarray(ref.q, float)
        if t.ndim != 1 or len(t) < 1 or q.shape != t.shape:
            raise DesignerError(
                f"the trajectory has {t.size} times and {q.size} angles",
                "give one angle per time, at least one sample",
            )
        keep += [t, q]
        out.kind, params, out.n, out.t, out.q = 3, (), len(t), pointer(t), pointer(q)
    else:
        raise DesignerError(
            f"the kernel has no motor reference of type {type(ref).__name__}",
            "use a step, sine, chirp or trajectory reference, or engine='python'",
        )
    out.p[: len(params)] = [float(p) for p in params]
    return out


def _no_error(call: int, status: int, t: float) -> DesignerError:
    return DesignerError(f"the kernel reported call {call} failing (status {status}) at t = {t:g} s")


@dataclass(eq=False)
class Binding:
    """A system as the kernel runs it.

    `kind` one of ROBOT, FMI2, FMI3, SERVO; `instance` the address the C side receives: `struct`
    (the system's own ctypes mirror of its C struct, whose size the kernel checks) or an FMU
    instance; `functions` the FMI functions' addresses by CALLS name; `in_vr`, `out_vr` ctypes
    uint32 arrays of value references (FMUs) or None; `keep` what must stay alive while bound.
    `start(step)` brings the C side to the system's state before a run at macro step `step` (s) and
    returns its step count; `finish(steps)` hands the kernel's count (and whatever the system's
    struct advanced) back after a run; `event()` runs an event iteration the instance asked for;
    `error(call, status, t)` and `terminated()` give the DesignerError for a failed call (for the
    robot: MuJoCo's divergence warning at time t) or a terminate request.
    """

    kind: int
    instance: int
    start: Callable[[float], int]
    finish: Callable[[int], None]
    functions: Mapping[str, int] = field(default_factory=dict)
    in_vr: Any = None
    out_vr: Any = None
    keep: list = field(default_factory=list)
    event: Callable[[], None] | None = None
    error: Callable[[int, int, float], DesignerError] = _no_error
    terminated: Callable[[], DesignerError] | None = None
    struct: ctypes.Structure | None = None
