"""MuJoCo's profiling clock switched off while Python drives many steps (the in-engine sweep path's
`mujoco.rollout`, the Python master).

MuJoCo's Python bindings install a clock as the global `mjcb_time`; mj_step reads it around each of
its stages to fill the profiling timers (`MjData.timer`), nothing else: the physics is the same
without it, and the engine path's rollouts of 200 example-arm cases take 0.63-0.68x the CPU
(issue 38). The compiled kernel (fmus/kernel/master.c) does the same around its loops. The clock is
given back when the last user in the process finishes, so runs in several threads do not lose it
(the kernel keeps its own count: a Python run that ends before an overlapping kernel run in another
thread of the same process would see the kernel put back the unset clock).
"""

from __future__ import annotations

import contextlib
import ctypes
import functools
import sys
import threading
from collections.abc import Iterator

from ..errors import DesignerError

_lock = threading.Lock()
_state = {"users": 0, "saved": None}


@functools.cache
def _hook() -> ctypes.c_void_p | None:
    """libmujoco's `mjcb_time` pointer, or None for a MuJoCo whose library is not where the wheel puts it."""
    from .kernel_build import mujoco_paths

    try:
        library = mujoco_paths()[1]
    except DesignerError:
        return None
    return ctypes.c_void_p.in_dll(ctypes.CDLL(str(library)), "mjcb_time")


@contextlib.contextmanager
def without_clock() -> Iterator[None]:
    """Run the block with `mjcb_time` unset (MuJoCo's timers stay still; results are unchanged).

    Nothing to do where MuJoCo is not loaded (the virtual rig's systems): it is not imported for this.
    """
    hook = _hook() if "mujoco" in sys.modules else None
    if hook is None:
        yield
        return
    with _lock:
        if _state["users"] == 0:
            _state["saved"], hook.value = hook.value, None
        _state["users"] += 1
    try:
        yield
    finally:
        with _lock:
            _state["users"] -= 1
            if _state["users"] == 0:
                hook.value = _state["saved"]
