"""A joint FMU as a co-simulation system, through fmpy's FMI 2 and FMI 3 co-simulation calls.

The joint FMU's contract: per axis `a`, tunable SI parameters `a.m`, `a.c`, `a.k`, `a.offset`;
force interface inputs `a.s`, `a.v` and output `a.f` (direct feedthrough, no state); body interface
input `a.f` and outputs `a.s`, `a.v`, `a.a`. Inputs and outputs go through one pre-built
value-reference array each, so a step costs three C calls.
"""

from __future__ import annotations

import ctypes
import shutil
from collections import deque
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from ..errors import DesignerError

PARAMETERS = ("m", "c", "k", "offset")
STATUS = ("OK", "Warning", "Discard", "Error", "Fatal", "Pending")
#: the log categories the FMI standard suggests for problems, enabled where an FMU declares them
PROBLEM_CATEGORIES = ("logStatusWarning", "logStatusDiscard", "logStatusError", "logStatusFatal")
#: how many of an FMU's last log messages are kept to explain an error
LOG_LINES = 50


def _axes_of(md) -> set[str]:
    return {v.name.split(".")[0] for v in md.modelVariables if "." in v.name}


def read_parameters(path: str | Path, axis: str) -> dict[str, float]:
    """The start values of an FMU's parameters m, c, k, offset on `axis` (SI)."""
    from fmpy import read_model_description

    md = read_model_description(str(path))
    starts = {v.name: v.start for v in md.modelVariables}
    return {p: float(starts[f"{axis}.{p}"]) for p in PARAMETERS if starts.get(f"{axis}.{p}") is not None}


def check_fmu(path: str | Path, axes: Sequence[str]) -> str:
    """Raise a DesignerError unless `path` is a co-simulation FMU with these axes; return its interface."""
    from fmpy import read_model_description

    path = Path(path)
    if not path.is_file():
        raise DesignerError(
            f"FMU {path} does not exist", "export one with `designer export fmu` or fix the path"
        )
    try:
        md = read_model_description(str(path))
    except Exception as exc:  # fmpy raises several types for a broken archive
        raise DesignerError(
            f"{path} is not a readable FMU: {exc}", "give an FMU exported by designer"
        ) from None
    if md.coSimulation is None:
        raise DesignerError(f"FMU {path} has no co-simulation interface", "export it with co-simulation")
    missing = [a for a in axes if a not in _axes_of(md)]
    if missing:
        raise DesignerError(
            f"FMU {path} has no axis {', '.join(missing)}", f"it has: {', '.join(sorted(_axes_of(md)))}"
        )
    causality = {v.name: v.causality for v in md.modelVariables}
    return "force" if causality.get(f"{axes[0]}.f") == "output" else "body"


class FmuSystem:
    """One FMU instance stepped by the master; exposes only the variables of the chosen axes."""

    def __init__(
        self,
        path: str | Path,
        axes: Sequence[str],
        name: str = "joint",
        parameters: Mapping[str, float] | None = None,
    ) -> None:
        from fmpy import extract, read_model_description

        self.interface = check_fmu(path, axes)
        self.feedthrough = self.interface == "force"
        md = read_model_description(str(path))
        self.version = 3 if md.fmiVersion.startswith("3") else 2
        refs = {v.name: v.valueReference for v in md.modelVariables}
        if self.interface == "force":
            self.inputs = [f"{a}.{v}" for a in axes for v in ("s", "v")]
            self.outputs = [f"{a}.f" for a in axes]
        else:
            self.inputs = [f"{a}.f" for a in axes]
            self.outputs = [f"{a}.{v}" for a in axes for v in ("s", "v", "a")]
        self._dir = extract(str(path))
        kwargs = dict(
            guid=md.guid,
            unzipDirectory=self._dir,
            modelIdentifier=md.coSimulation.modelIdentifier,
            instanceName=name,
        )
        if self.version == 3:
            from fmpy.fmi3 import FMU3Slave

            self.fmu = FMU3Slave(**kwargs)
        else:
            from fmpy.fmi2 import FMU2Slave

            self.fmu = FMU2Slave(**kwargs)
        self.log: deque[str] = deque(maxlen=LOG_LINES)
        self._instantiate()
        problems = [c.name for c in md.logCategories if c.name in PROBLEM_CATEGORIES]
        if problems:  # only problems: an FMU logging every call would slow each step
            self.fmu.setDebugLogging(True, problems)
        for key, value in (parameters or {}).items():
            if key not in refs:
                raise DesignerError(f"FMU {path} has no parameter '{key}'", "use names such as theta.k")
            self._set_scalar(refs[key], float(value))
        if self.version == 3:
            self.fmu.enterInitializationMode(startTime=0.0)
        else:
            self.fmu.setupExperiment(startTime=0.0)
            self.fmu.enterInitializationMode()
        self.fmu.exitInitializationMode()
        vr_type = ctypes.c_uint32
        self._in_vr = (vr_type * len(self.inputs))(*[refs[v] for v in self.inputs])
        self._out_vr = (vr_type * len(self.outputs))(*[refs[v] for v in self.outputs])
        self._in = np.zeros(len(self.inputs))
        self._out = np.zeros(len(self.outputs))
        self._in_ptr = self._in.ctypes.data_as(ctypes.POINTER(ctypes.c_double))
        self._out_ptr = self._out.ctypes.data_as(ctypes.POINTER(ctypes.c_double))
        self._steps = 0
        if self.version == 3:
            f = self.fmu
            self._set = lambda: f.fmi3SetFloat64(
                f.component, self._in_vr, len(self._in), self._in_ptr, len(self._in)
            )
            self._get = lambda: f.fmi3GetFloat64(
                f.component, self._out_vr, len(self._out), self._out_ptr, len(self._out)
            )
        else:
            f = self.fmu
            self._set = lambda: f.fmi2SetReal(f.component, self._in_vr, len(self._in), self._in_ptr)
            self._get = lambda: f.fmi2GetReal(f.component, self._out_vr, len(self._out), self._out_ptr)

    def _instantiate(self) -> None:
        """Instantiate with a logger that keeps the FMU's last messages in `self.log` (none printed)."""

        def record(*args) -> None:  # FMI 2: (env, instance, status, category, message); FMI 3: (env, ...)
            status, category, message = args[-3:]
            label = STATUS[status] if 0 <= status < len(STATUS) else str(status)
            self.log.append(
                f"[{label}] {(category or b'').decode(errors='replace')}: {message.decode(errors='replace')}"
            )

        if self.version == 3:
            self.fmu.instantiate(logMessage=record)
            return
        from fmpy.fmi2 import defaultCallbacks, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE
        from fmpy.logging import addLoggerProxy

        self._callbacks = fmi2CallbackFunctions()
        self._logger = fmi2CallbackLoggerTYPE(record)  # kept alive as long as the instance
        self._callbacks.logger = self._logger
        self._callbacks.allocateMemory = defaultCallbacks.allocateMemory
        self._callbacks.freeMemory = defaultCallbacks.freeMemory
        addLoggerProxy(ctypes.byref(self._callbacks))
        self.fmu.instantiate(callbacks=self._callbacks)

    def _set_scalar(self, vr: int, value: float) -> None:
        if self.version == 3:
            self.fmu.setFloat64([vr], [value])
        else:
            self.fmu.setReal([vr], [value])

    def get(self) -> np.ndarray:
        self._get()
        return self._out.copy()

    def set(self, values: np.ndarray) -> None:
        self._in[:] = values
        self._set()

    def do_step(self, h: float) -> None:
        self.fmu.doStep(self._steps * h, h)
        self._steps += 1

    def close(self) -> None:
        """Terminate and free the instance and remove its unpacked archive."""
        try:
            self.fmu.terminate()
            self.fmu.freeInstance()
        finally:
            shutil.rmtree(self._dir, ignore_errors=True)
