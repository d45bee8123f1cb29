"""A joint FMU as a system of the master, through fmpy's FMI 2 and FMI 3 calls, within the standard.

The joint FMU's contract: per axis `a`, tunable SI parameters `a.m`, `a.c`, `a.k`, `a.offset`;
force interface inputs `a.s`, `a.v` and output `a.f` (direct feedthrough, no state); body interface
input `a.f` and outputs `a.s`, `a.v`, `a.a`. Inputs and outputs go through one pre-built
value-reference array each, so an exchange costs two C calls.

How each FMU is driven (FMI 2.0 sections 3.2.3 and 4.2.4, FMI 3.0 sections 3.2 and 4.2):
- a feedthrough element (force interface) with a Model Exchange interface and no continuous states
  or event indicators runs as Model Exchange in Continuous-Time Mode: at each instant t the master
  sets the inputs and reads the outputs (what ME defines); `do_step(h)` calls SetTime(t + h) and,
  if the FMU needs it, CompletedIntegratorStep (event mode when the FMU asks for it);
- a feedthrough element offering co-simulation only is stepped as co-simulation and treated as a
  state system: its outputs are read after its DoStep, before its inputs are set, so they lag the
  inputs by one step, and `delay` says so (co-simulation defines no Get after Set without a DoStep);
- a body (state) runs as co-simulation: outputs read at t, inputs set, DoStep(t, h).
"""

from __future__ import annotations

import contextlib
import ctypes
import functools
import importlib
import itertools
import shutil
import threading
from abc import ABC, abstractmethod
from collections import deque
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from ..errors import DesignerError
from . import binding as kb

_CONSTRUCTING = threading.Lock()  # fmpy's FMU constructor changes the working directory: one at a time
PARAMETERS = ("m", "c", "k", "offset")
STATUS = ("OK", "Warning", "Discard", "Error", "Fatal", "Pending")
#: the log categories the FMI standard suggests for problems, enabled where an FMU declares them
PROBLEM_CATEGORIES = ("logStatusWarning", "logStatusDiscard", "logStatusError", "logStatusFatal")
#: how many of an FMU's last log messages are kept to explain an error
LOG_LINES = 50


#: FMI 2 instances' logs by their componentEnvironment token
_LOGS: dict[int, deque[str]] = {}
_TOKENS = itertools.count(1)


def log_line(status: int, category: bytes | None, message: bytes | None) -> str:
    """One FMU log message as a line: [status] category: message."""
    label = STATUS[status] if 0 <= status < len(STATUS) else str(status)
    text = (message or b"").decode(errors="replace")
    return f"[{label}] {(category or b'').decode(errors='replace')}: {text}"


@functools.cache
def _fmi2_router():
    """The process's one FMI 2 logger: a message goes to the log its componentEnvironment names;
    one from an instance made elsewhere (fmpy's own callbacks) is printed as fmpy would."""
    from fmpy.fmi1 import printLogMessage
    from fmpy.fmi2 import fmi2CallbackLoggerTYPE

    def route(env, instance, status, category, message) -> None:
        log = _LOGS.get(env or 0)
        if log is None:
            printLogMessage(env, instance, status, category, message)
        else:
            log.append(log_line(status, category, message))

    return fmi2CallbackLoggerTYPE(route)


def _axes_of(md) -> set[str]:
    return {v.name.split(".")[0] for v in md.modelVariables if "." in v.name}


@functools.lru_cache(maxsize=64)
def _model_description(path: str, mtime_ns: int, size: int):
    """fmpy's parse of an FMU's modelDescription.xml, once per file version in a process (a scenario
    check, a prepare and a sweep worker's sessions read it once). Treat it as read-only."""
    from fmpy import read_model_description

    return read_model_description(path)


class FmuDescription:
    """An FMU's modelDescription.xml, read once: what a run needs from it.

    `path` the archive (or the folder of an unpacked one), `md` fmpy's ModelDescription, `version`
    2 or 3, `interface` "force" or "body" (of `axes`), `refs` variable name -> value reference,
    `starts` variable name -> start value (as written), `axes` the axes the FMU has.

    Raises:
        DesignerError: the file is missing, not a readable FMU, without co-simulation, or lacks an axis.
    """

    def __init__(self, path: str | Path, axes: Sequence[str]) -> None:
        path = Path(path)
        if not path.exists():
            raise DesignerError(
                f"FMU {path} does not exist", "export one with `designer export fmu` or fix the path"
            )
        try:
            xml = path / "modelDescription.xml" if path.is_dir() else path
            stat = xml.stat()
            md = _model_description(str(path), stat.st_mtime_ns, stat.st_size)
        except Exception as exc:  # fmpy raises several types for a broken archive
            raise DesignerError(
                f"{path} is not a readable FMU: {exc}", "give an FMU exported by designer"
            ) from None
        if md.coSimulation is None:
            raise DesignerError(f"FMU {path} has no co-simulation interface", "export it with co-simulation")
        self.path, self.md = path, md
        self.axes = sorted(_axes_of(md))
        missing = [a for a in axes if a not in self.axes]
        if missing:
            want = missing[0]
            raise DesignerError(
                f"FMU {path} has no axis {', '.join(missing)}",
                f"it has: {', '.join(self.axes)}; export the joint on axis {want}: export_fmu of a Joint "
                f"with axes=['{want}']",
            )
        self.version = 3 if md.fmiVersion.startswith("3") else 2
        self.refs = {v.name: v.valueReference for v in md.modelVariables}
        self.starts = {v.name: v.start for v in md.modelVariables}
        self.kinds = {v.name: v.type for v in md.modelVariables}  # Real/Float64, Boolean, ...
        causality = {v.name: v.causality for v in md.modelVariables}
        self.interface = "force" if causality.get(f"{axes[0]}.f") == "output" else "body"

    def parameters(self, axis: str) -> dict[str, float]:
        """The start values of the parameters m, c, k, offset on `axis` (SI), those it declares."""
        starts = self.starts
        return {p: float(starts[f"{axis}.{p}"]) for p in PARAMETERS if starts.get(f"{axis}.{p}") is not None}


def read_parameters(path: str | Path, axis: str) -> dict[str, float]:
    """The start values of an FMU's parameters m, c, k, offset on `axis` (SI)."""
    return FmuDescription(path, [axis]).parameters(axis)


def check_fmu(path: str | Path, axes: Sequence[str]) -> str:
    """Raise a DesignerError unless `path` is a co-simulation FMU with these axes; return its interface."""
    return FmuDescription(path, axes).interface


def library_path(
    folder: Path, fmi_version: int, model_identifier: str, platform: str | None = None
) -> str | None:
    """The binary of `platform` (an FMI 3 tuple; default this machine) in an unpacked FMU `folder`.

    FMI 3 names binaries/ folders by the tuple; FMI 2.0.4 names only 64-bit x86 (linux64, win64,
    darwin64), so other platforms use the FMI 3 tuple there too (aarch64-linux, aarch64-darwin, as
    designer's exports do). FMPy 0.3.32 looks for an FMI 2 binary in linux64 or darwin64 on any 64-bit
    machine, an x86_64 binary on aarch64 Linux and Apple Silicon: so the binary is named for it.
    None when the FMU has no such file (or the platform is not one designer knows): FMPy then chooses,
    and its error names what it missed.
    """
    from ..export.build import host_platform, platform_folder

    try:
        platform = platform or host_platform()
    except DesignerError:
        return None
    extension = {"windows": ".dll", "darwin": ".dylib"}.get(platform.split("-", 1)[1], ".so")
    path = folder / "binaries" / platform_folder(fmi_version, platform) / (model_identifier + extension)
    return str(path) if path.is_file() else None


def unpack(path: str | Path, folder: str | Path) -> Path:
    """Extract what an importer loads from an FMU (binaries/ and resources/, as FMPy's simulate_fmu
    does) into `folder`: not the sources or documentation."""
    from fmpy import extract

    return Path(extract(str(path), str(folder), include=lambda n: n.startswith(("binaries/", "resources/"))))


def fmi_function(fmu, name: str) -> int:
    """The address of FMI function `name` in an fmpy FMU's loaded library."""
    return ctypes.cast(getattr(fmu.dll, name), ctypes.c_void_p).value


def _same_instant_capable(md) -> bool:
    """True if the FMU's Model Exchange interface can evaluate its outputs at one instant without
    integration: it has the interface, no continuous states and no event indicators."""
    return (
        md.modelExchange is not None
        and md.numberOfContinuousStates == 0
        and (md.numberOfEventIndicators or 0) == 0
    )


class FmiMode(ABC):
    """How an FMU is driven (the master's view of one FMI interface): `name`, `feedthrough`, its
    model description element (`element`) and fmpy's class (FMU2<fmpy>, FMU3<fmpy>)."""

    name: str
    feedthrough: bool
    element: str
    fmpy: str

    def interface(self, md):
        """The model description's element of this interface."""
        return getattr(md, self.element)

    def fmpy_class(self, version: int) -> type:
        """fmpy's class for an instance of this interface in FMI `version`."""
        return getattr(importlib.import_module(f"fmpy.fmi{version}"), f"FMU{version}{self.fmpy}")

    @abstractmethod
    def initialized(self, system: FmuSystem) -> None:
        """What follows Initialization Mode."""

    @abstractmethod
    def step(self, system: FmuSystem, h: float) -> None:
        """One macro step of `h` s."""

    @abstractmethod
    def kernel_calls(self) -> list[str]:
        """The FMI calls the compiled kernel makes per step besides set and get (binding.CALLS)."""


class CoSimulation(FmiMode):
    """Driving an FMU through its Co-Simulation interface: a step is DoStep(n h, h); its outputs are
    those of its last step (not feedthrough)."""

    name, feedthrough, element, fmpy = "co-simulation", False, "coSimulation", "Slave"

    def initialized(self, system: FmuSystem) -> None:
        """Nothing to do: the instance is in Step Mode."""

    def step(self, system: FmuSystem, h: float) -> None:
        """DoStep(n h, h)."""
        system.fmu.doStep(system.steps * h, h)
        system.steps += 1

    def kernel_calls(self) -> list[str]:
        return ["step"]


class ModelExchange(FmiMode):
    """Driving an FMU without states through its Model Exchange interface, so that its outputs follow
    inputs set at the same instant (feedthrough): a step is SetTime((n + 1) h), then
    CompletedIntegratorStep when the FMU needs it (`completed`), and an event iteration if it asks."""

    name, feedthrough, element, fmpy = "model-exchange", True, "modelExchange", "Model"

    def __init__(self, completed: bool) -> None:
        self.completed = completed

    def initialized(self, system: FmuSystem) -> None:
        """The event iteration after Initialization Mode, into Continuous-Time Mode."""
        system.event_iteration()

    def step(self, system: FmuSystem, h: float) -> None:
        """SetTime((n + 1) h), then CompletedIntegratorStep if the FMU needs it."""
        system.steps += 1
        system.fmu.setTime(system.steps * h)
        if self.completed:
            system.completed(*system.fmu.completedIntegratorStep())

    def kernel_calls(self) -> list[str]:
        return ["time", "completed"] if self.completed else ["time"]


class FmuSystem:
    """One FMU instance driven by the master; exposes only the variables of the chosen axes.

    Attributes: `inputs`, `outputs` (variable names), `mode` (how it is driven: `ModelExchange` for a
    force element whose Model Exchange interface needs no integration, else `CoSimulation`),
    `feedthrough` (outputs follow inputs at the same instant), `kind` (the mode's name,
    "model-exchange" or "co-simulation"), `delay` (None, or a sentence saying which outputs lag
    their inputs by one step and why), `steps` (macro steps since t = 0).
    """

    def __init__(
        self,
        fmu: str | Path | FmuDescription,
        axes: Sequence[str],
        name: str = "joint",
        parameters: Mapping[str, float] | None = None,
        *,
        folder: str | Path | None = None,
    ) -> None:
        """Instantiate `fmu` (a path, or its description read once), set `parameters` (SI, keyed
        "axis.field"), initialise it; unpacked into `folder` (kept by its owner) or a temporary
        folder removed by `close` (an FMU already unpacked, a folder, is used where it is).

        Raises:
            DesignerError: not a usable FMU, an unknown parameter, or the FMU refused to start.
        """
        import tempfile

        md = fmu if isinstance(fmu, FmuDescription) else FmuDescription(fmu, axes)
        self.description, self.name = md, name
        self.interface, self.version = md.interface, md.version
        if self.interface == "force" and _same_instant_capable(md.md):
            self.mode: FmiMode = ModelExchange(bool(md.md.modelExchange.needsCompletedIntegratorStep))
        else:
            self.mode = CoSimulation()
        self.kind, self.feedthrough = self.mode.name, self.mode.feedthrough
        self.delay = None
        if self.interface == "force":
            self.inputs = [f"{a}.{v}" for a in axes for v in ("s", "v")]
            self.outputs = [f"{a}.f" for a in axes]
            if not self.feedthrough:
                self.delay = (
                    f"{name}: {', '.join(self.outputs)} lag(s) the inputs by one step: the FMU offers "
                    "co-simulation only, which defines no output for inputs set since its last step"
                )
        else:
            self.inputs = [f"{a}.f" for a in axes]
            self.outputs = [f"{a}.{v}" for a in axes for v in ("s", "v", "a")]
        self.parameters = dict(parameters or {})
        unpacked = md.path.is_dir()
        self._owned = folder is None and not unpacked
        if unpacked:
            self._dir = str(md.path)
        else:
            self._dir = tempfile.mkdtemp(prefix="designer-fmu-") if folder is None else str(folder)
        self.log: deque[str] = deque(maxlen=LOG_LINES)
        try:
            if not unpacked:
                unpack(md.path, self._dir)
            self.fmu = self._instantiate(md.md, name)
            self._start(self.parameters)
            self._bind(md.refs)
        except BaseException as exc:  # a half-built instance frees what it holds, then reports
            self._abandon()
            self._refused(exc, name, self.parameters)
            raise

    def _start(self, parameters: Mapping[str, float]) -> None:
        """Set `parameters` and initialise (the instance is in its Instantiated state)."""
        refs = self.description.refs
        for key, value in parameters.items():
            if key not in refs:
                raise DesignerError(
                    f"FMU {self.description.path} has no parameter '{key}'", "use names such as theta.k"
                )
            if self.description.kinds[key] == "Boolean":
                self._set_boolean(refs[key], bool(value))
            else:
                self._set_scalar(refs[key], float(value))
        self._initialize()

    def reset(self, parameters: Mapping[str, float] | None = None) -> None:
        """Back to t = 0 for a new run: FMI Reset, the constructor's parameters updated with
        `parameters` (SI, "axis.field"), initialised again; counters cleared.

        Raises:
            DesignerError: an unknown parameter, or the FMU refused the values (naming them).
        """
        given = self.parameters | dict(parameters or {})
        self.log.clear()
        self.steps, self._h = 0, 0.0
        try:
            self.fmu.reset()
            self._start(given)
        except Exception as exc:
            self._refused(exc, self.name, given)
            raise

    def _refused(self, exc: BaseException, name: str, parameters: Mapping[str, float]) -> None:
        """Raise a DesignerError naming the joint and its parameters when the FMU refused to start
        (fmpy's exception for a status above Warning, with the FMU's own log)."""
        from fmpy.fmi1 import FMICallException

        if isinstance(exc, FMICallException):
            given = ", ".join(f"{k} = {v:g}" for k, v in parameters.items()) or "its exported values"
            log = "; ".join(self.log) or "the FMU logged nothing"
            raise DesignerError(
                f"joint {name}: the FMU refused to start with {given} ({exc.function}: {log})",
                "give physical values (k > 0, c >= 0, m >= 0, in SI) in the joint's parameters",
            ) from None

    def _abandon(self) -> None:
        """Free a partly built instance and remove its unpacked archive (construction failed)."""
        fmu = getattr(self, "fmu", None)
        if fmu is not None:
            with contextlib.suppress(Exception):
                fmu.freeInstance()
        _LOGS.pop(getattr(self, "_token", None), None)
        if self._owned:
            shutil.rmtree(self._dir, ignore_errors=True)

    def _instantiate(self, md, name: str):
        """An fmpy FMU2/FMU3 Model or Slave (as the mode drives it), instantiated from this machine's
        own binary (`library_path`)."""
        iface = self.mode.interface(md)
        with _CONSTRUCTING:  # two at once could leave the process in a folder a session removes
            fmu = self.mode.fmpy_class(self.version)(
                guid=md.guid,
                unzipDirectory=self._dir,
                modelIdentifier=iface.modelIdentifier,
                instanceName=name,
                libraryPath=library_path(Path(self._dir), self.version, iface.modelIdentifier),
            )
        self._instantiate_logging(fmu)
        problems = [c.name for c in md.logCategories if c.name in PROBLEM_CATEGORIES]
        if problems:  # only problems: an FMU logging every call would slow each step
            fmu.setDebugLogging(True, problems)
        return fmu

    def _initialize(self) -> None:
        """Initialization Mode at t = 0, then Step Mode (CS) or Continuous-Time Mode (ME)."""
        if self.version == 3:
            self.fmu.enterInitializationMode(startTime=0.0)
        else:
            self.fmu.setupExperiment(startTime=0.0)
            self.fmu.enterInitializationMode()
        self.fmu.exitInitializationMode()
        self.mode.initialized(self)

    def event_iteration(self) -> None:
        """In Event Mode: update discrete states until settled, then enter Continuous-Time Mode."""
        update = self.fmu.updateDiscreteStates if self.version == 3 else self.fmu.newDiscreteStates
        for _ in range(1000):
            more, terminate, *_ = update()
            if terminate:
                raise self.terminated()
            if not more:
                break
        else:
            raise DesignerError(
                f"FMU instance {self.fmu.instanceName} kept asking for discrete-state updates (1000 times)",
                "check the FMU: its event iteration does not settle",
            )
        self.fmu.enterContinuousTimeMode()

    def _bind(self, refs: Mapping[str, int]) -> None:
        """Pre-built value-reference and value arrays; `_set` and `_get` are one C call each."""
        vr_type = ctypes.c_uint32
        self._in_vr = (vr_type * len(self.inputs))(*[refs[v] for v in self.inputs])
        self._out_vr = (vr_type * len(self.outputs))(*[refs[v] for v in self.outputs])
        self._in = np.zeros(len(self.inputs))
        self._out = np.zeros(len(self.outputs))
        self._in_ptr = self._in.ctypes.data_as(ctypes.POINTER(ctypes.c_double))
        self._out_ptr = self._out.ctypes.data_as(ctypes.POINTER(ctypes.c_double))
        self.steps = 0
        self._h = 0.0  # the last macro step, s (0 before the first)
        f, ni, no = self.fmu, len(self.inputs), len(self.outputs)
        if self.version == 3:
            self._set = lambda: f.fmi3SetFloat64(f.component, self._in_vr, ni, self._in_ptr, ni)
            self._get = lambda: f.fmi3GetFloat64(f.component, self._out_vr, no, self._out_ptr, no)
        else:
            self._set = lambda: f.fmi2SetReal(f.component, self._in_vr, ni, self._in_ptr)
            self._get = lambda: f.fmi2GetReal(f.component, self._out_vr, no, self._out_ptr)

    def _instantiate_logging(self, fmu) -> None:
        """Instantiate with a logger that keeps the FMU's last messages in `self.log` (none printed)."""
        if self.version == 3:  # fmpy keeps one callback per instance

            def record(env, status, category, message) -> None:
                self.log.append(log_line(status, category, message))

            fmu.instantiate(logMessage=record)
            return
        from fmpy.fmi2 import defaultCallbacks, fmi2CallbackFunctions
        from fmpy.logging import addLoggerProxy

        # fmpy's proxy (it formats FMI 2's printf-style messages) keeps ONE logger for the process, so
        # the instance is told apart by its componentEnvironment, a token naming its log
        self._token = next(_TOKENS)
        _LOGS[self._token] = self.log
        self._callbacks = fmi2CallbackFunctions()
        self._callbacks.logger = _fmi2_router()
        self._callbacks.allocateMemory = defaultCallbacks.allocateMemory
        self._callbacks.freeMemory = defaultCallbacks.freeMemory
        self._callbacks.componentEnvironment = self._token
        addLoggerProxy(ctypes.byref(self._callbacks))
        fmu.instantiate(callbacks=self._callbacks)

    def _set_scalar(self, vr: int, value: float) -> None:
        if self.version == 3:
            self.fmu.setFloat64([vr], [value])
        else:
            self.fmu.setReal([vr], [value])

    def _set_boolean(self, vr: int, value: bool) -> None:
        self.fmu.setBoolean([vr], [value])

    def get(self) -> np.ndarray:
        try:
            self._get()
        except Exception as exc:
            self._surface(exc)
        return self._out.copy()

    def set(self, values: np.ndarray) -> None:
        self._in[:] = values
        try:
            self._set()
        except Exception as exc:
            self._surface(exc)

    def do_step(self, h: float) -> None:
        """One macro step of `h` s, as the mode drives it (`CoSimulation.step`, `ModelExchange.step`)."""
        self._h = h
        try:
            self.mode.step(self, h)
        except Exception as exc:
            self._surface(exc)

    def _surface(self, exc: Exception) -> None:
        """Called in an except block: fmpy's exception for a status above Warning becomes a
        DesignerError carrying the FMU's log; anything else goes on as it was."""
        from fmpy.fmi1 import FMICallException

        if isinstance(exc, FMICallException):
            raise self.status_error(exc.function, exc.status, self.steps * self._h) from None
        raise  # the exception being handled

    def status_error(self, call: str, status: int, t: float) -> DesignerError:
        """The error for FMI function `call` returning `status` at time `t` (s), with the FMU's log."""
        label = STATUS[status] if 0 <= status < len(STATUS) else str(status)
        log = "\n".join(f"  {line}" for line in self.log) or "  (the FMU logged nothing)"
        return DesignerError(
            f"FMU {self.fmu.instanceName}: {call} returned {label} at t = {t:g} s; its log:\n{log}",
            "check the FMU's parameters and inputs, or use a smaller step",
        )

    def completed(self, enter: bool, terminate: bool) -> None:
        """Act on CompletedIntegratorStep's answer: stop, or an event iteration (also for the kernel).

        Raises:
            DesignerError: the FMU asked to terminate the simulation, or an event-mode call returned
                an error status (with the FMU's log).
        """
        if terminate:
            raise self.terminated()
        if enter:
            try:
                self.fmu.enterEventMode()
                self.event_iteration()
            except Exception as exc:
                self._surface(exc)

    def binding(self) -> kb.Binding:
        """The instance for the compiled kernel (see designer.cosim.binding): its FMI functions,
        co-simulation (DoStep) or Model Exchange without states (SetTime, and
        CompletedIntegratorStep when the FMU needs it), as `do_step` drives it."""
        v, fmu = self.version, self.fmu
        names = {
            "set": "SetFloat64" if v == 3 else "SetReal",
            "get": "GetFloat64" if v == 3 else "GetReal",
            "step": "DoStep",
            "time": "SetTime",
            "completed": "CompletedIntegratorStep",
        }
        wanted = ["set", "get", *self.mode.kernel_calls()]

        def start(step: float) -> int:
            self._h = step  # the macro step the kernel runs, for the time in error messages
            return self.steps

        def finish(steps: int) -> None:
            self.steps = steps

        def error(call: int, status: int, t: float) -> DesignerError:
            return self.status_error(f"fmi{v}{names[kb.CALLS[call]]}", status, t)

        return kb.Binding(
            kb.FMI3 if v == 3 else kb.FMI2,
            fmu.component,
            start,
            finish,
            functions={w: fmi_function(fmu, f"fmi{v}{names[w]}") for w in wanted},
            in_vr=self._in_vr,
            out_vr=self._out_vr,
            event=lambda: self.completed(True, False),
            error=error,
            terminated=self.terminated,
        )

    def terminated(self) -> DesignerError:
        return DesignerError(
            f"FMU instance {self.fmu.instanceName} asked to terminate the simulation",
            "check the FMU's inputs and parameters",
        )

    def close(self) -> None:
        """Terminate and free the instance and remove its unpacked archive.

        An instance that returned Error may refuse Terminate (FMI 2.0 section 2.1.3); it is freed all
        the same, and the error that stopped the run is the one that surfaces.
        """
        from fmpy.fmi1 import FMICallException

        try:
            with contextlib.suppress(FMICallException):
                self.fmu.terminate()
            self.fmu.freeInstance()
        finally:
            _LOGS.pop(getattr(self, "_token", None), None)
            if self._owned:
                shutil.rmtree(self._dir, ignore_errors=True)
