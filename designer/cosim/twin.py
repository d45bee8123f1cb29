"""The compiled kernel's own copy of a robot's MuJoCo model and data, made through MuJoCo's public API.

mujoco's Python bindings give no public pointer to the mjModel and mjData they wrap (only the private
`_address`). The kernel therefore steps a twin: the model written by `mj_saveModel` into a buffer and
read back by libmujoco's `mj_loadModelBuffer` (the binary MJB format holds every field of the model,
so the copy is exact), a `mj_makeData` of its own, and the integration state (mjSTATE_INTEGRATION:
time, qpos, qvel, act, controls, applied forces, mocap, user data, warm start) copied in before a run
and back out after it with `mj_getState` / `mj_setState`. A MuJoCo step reads nothing else, so the
twin steps bit for bit as the Python robot does (tests/test_cosim_kernel.py checks it). The libmujoco
called through ctypes is the one the bindings loaded (the same file: one copy of its globals).
"""

from __future__ import annotations

import ctypes
import functools
import weakref
from ctypes import c_int, c_int64, c_void_p

import numpy as np

from ..errors import DesignerError


@functools.cache
def libmujoco() -> ctypes.CDLL:
    """The `mujoco` wheel's libmujoco with the C functions the twin calls declared.

    Raises:
        DesignerError: the library cannot load a model from memory (mujoco older than 3.2).
    """
    from .kernel_build import mujoco_paths

    lib = ctypes.CDLL(str(mujoco_paths()[1]))
    if not hasattr(lib, "mj_loadModelBuffer"):
        raise DesignerError(
            "this mujoco cannot load a model from memory (mj_loadModelBuffer)",
            "update mujoco, or use engine='python'",
        )
    lib.mj_loadModelBuffer.argtypes, lib.mj_loadModelBuffer.restype = [c_void_p, c_int64], c_void_p
    lib.mj_makeData.argtypes, lib.mj_makeData.restype = [c_void_p], c_void_p
    lib.mj_resetData.argtypes, lib.mj_resetData.restype = [c_void_p, c_void_p], None
    for name in ("mj_getState", "mj_setState"):
        getattr(lib, name).argtypes, getattr(lib, name).restype = [c_void_p, c_void_p, c_void_p, c_int], None
    lib.mj_deleteData.argtypes, lib.mj_deleteData.restype = [c_void_p], None
    lib.mj_deleteModel.argtypes, lib.mj_deleteModel.restype = [c_void_p], None
    return lib


def _free(lib: ctypes.CDLL, model: int, data: int) -> None:
    lib.mj_deleteData(data)
    lib.mj_deleteModel(model)


class Twin:
    """A copy of `model` (MjModel) and a data of its own for the kernel; `model` and `data` here are
    the copy's C addresses. `load()` copies `data`'s (MjData) state in, `store()` copies it back.
    The copy is freed when the Twin is collected.

    Raises:
        DesignerError: libmujoco cannot load the model from memory.
    """

    def __init__(self, model, data) -> None:
        import mujoco

        self._lib = lib = libmujoco()
        self._sig = int(mujoco.mjtState.mjSTATE_INTEGRATION)
        self._source = (model, data)
        buffer = np.empty(mujoco.mj_sizeModel(model), dtype=np.uint8)
        mujoco.mj_saveModel(model, None, buffer)
        self.model = lib.mj_loadModelBuffer(buffer.ctypes.data, buffer.size)
        if not self.model:
            raise DesignerError("libmujoco could not read back the robot model", "use engine='python'")
        self.data = lib.mj_makeData(self.model)
        self._state = np.empty(mujoco.mj_stateSize(model, self._sig))
        weakref.finalize(self, _free, lib, self.model, self.data)

    def load(self) -> None:
        """The Python data's state into the copy (which is reset first: no warning is left over)."""
        import mujoco

        mujoco.mj_getState(*self._source, self._state, self._sig)
        self._lib.mj_resetData(self.model, self.data)
        self._lib.mj_setState(self.model, self.data, self._state.ctypes.data, self._sig)

    def store(self) -> None:
        """The copy's state back into the Python data."""
        import mujoco

        self._lib.mj_getState(self.model, self.data, self._state.ctypes.data, self._sig)
        mujoco.mj_setState(*self._source, self._state, self._sig)
