"""Run a Master's fixed-step loop in the compiled kernel (fmus/kernel/): same exchange, same bits, C speed.

Python keeps everything but the loop: the Master checks the wiring and orders the exchange
(`Master.schedule`), fmpy instantiates the FMUs, the Robot compiles the MuJoCo model. This module
hands the kernel their raw pointers (each FMU's instance and its fmi2/fmi3 Set/Get/DoStep functions,
mjModel and mjData, the motor references' numbers) and a preallocated output array, then reads the
array. `run_master` picks the engine: the kernel when it can run every system, else the Python master
(`Trace.engine` says which ran).
"""

from __future__ import annotations

import ctypes
import functools
from collections.abc import Callable
from ctypes import POINTER, c_double, c_int32, c_int64, c_uint32, c_void_p

import numpy as np

from ..errors import DesignerError
from .fmu import FmuSystem
from .master import Master, Trace, diverged, steps
from .references import Chirp, Sine, Step, Trajectory
from .rig import HubServo
from .robot import Robot
from .robot import diverged as robot_diverged

ENGINES = ("auto", "kernel", "python")
#: rows per kernel call without a progress callback
CHUNK = 10000
_ROBOT, _FMI2, _FMI3, _SERVO = 0, 1, 2, 3
_OK, _FMU_STATUS, _DIVERGED, _ROBOT_DIVERGED, _EVENT, _TERMINATE = 0, 1, 2, 3, 4, 5
_CALLS = {2: ("SetReal", "GetReal", "DoStep"), 3: ("SetFloat64", "GetFloat64", "DoStep")}
_P_DOUBLE = POINTER(c_double)
_P_INT = POINTER(c_int32)


class _Reference(ctypes.Structure):
    _fields_ = [
        ("kind", c_int32),
        ("n", c_int32),
        ("p", c_double * 4),
        ("t", _P_DOUBLE),
        ("q", _P_DOUBLE),
        ("cursor", c_int64),
    ]


class _Robot(ctypes.Structure):
    _fields_ = [
        ("model", c_void_p),
        ("data", c_void_p),
        ("n_joints", c_int32),
        ("n_inputs", c_int32),
        ("qposadr", _P_INT),
        ("dofadr", _P_INT),
        ("input_dof", _P_INT),
        ("refs", POINTER(_Reference)),
        ("motor_q", _P_DOUBLE),
        ("motor_v", _P_DOUBLE),
        ("steps", c_int64),
        ("time", c_double),
        ("n_engine", c_int32),
        ("pad", c_int32),
        ("engine_actuator", _P_INT),
        ("engine_joint", _P_INT),
        ("engine_law", _P_DOUBLE),
    ]


class _Servo(ctypes.Structure):
    _fields_ = [
        ("chirp", _Reference),
        ("stiffness", c_double),
        ("damping", c_double),
        ("out", c_double * 2),
        ("steps", c_int64),
        ("h", c_double),
    ]


class _System(ctypes.Structure):
    _fields_ = [
        ("kind", c_int32),
        ("n_in", c_int32),
        ("n_out", c_int32),
        ("out_offset", c_int32),
        ("src", _P_INT),
        ("in_buf", _P_DOUBLE),
        ("instance", c_void_p),
        ("set_fn", c_void_p),
        ("get_fn", c_void_p),
        ("step_fn", c_void_p),
        ("time_fn", c_void_p),
        ("completed_fn", c_void_p),
        ("in_vr", POINTER(c_uint32)),
        ("out_vr", POINTER(c_uint32)),
        ("steps", c_int64),
        ("asked", c_int32),
        ("failed", c_int32),
    ]


class _Run(ctypes.Structure):
    _fields_ = [
        ("n_systems", c_int32),
        ("n_ops", c_int32),
        ("n_cols", c_int32),
        ("pad", c_int32),
        ("systems", POINTER(_System)),
        ("ops", _P_INT),
        ("values", _P_DOUBLE),
        ("step", c_double),
        ("n", c_int64),
        ("error_system", c_int32),
        ("error_call", c_int32),
        ("error_status", c_int32),
        ("pad2", c_int32),
        ("error_time", c_double),
        ("event_row", c_int64),
    ]


@functools.cache
def library() -> ctypes.CDLL:
    """The kernel's shared library, built on first use (see kernel_build).

    Raises:
        DesignerError: no C compiler, the build failed, or its structs differ from the mirrors here.
    """
    from .kernel_build import build_kernel

    lib = ctypes.CDLL(str(build_kernel()))
    lib.ks_run_rows.argtypes = [POINTER(_Run), c_int64, c_int64]
    lib.ks_run_rows.restype = c_int32
    lib.ks_reference_eval.argtypes = [POINTER(_Reference), c_double, _P_DOUBLE, _P_DOUBLE]
    lib.ks_reference_eval.restype = None
    sizes = (c_int64 * 5)()
    lib.ks_sizes(sizes)
    mirror = [ctypes.sizeof(t) for t in (_Reference, _Robot, _Servo, _System, _Run)]
    if list(sizes) != mirror:
        raise DesignerError(
            f"the kernel's structs ({list(sizes)} bytes) do not match their Python mirror ({mirror})",
            "use engine='python', and report this with your platform",
        )
    return lib


def _ints(values) -> np.ndarray:
    return np.ascontiguousarray(values, dtype=np.int32)


def _ptr(array: np.ndarray, kind=_P_DOUBLE):
    return array.ctypes.data_as(kind)


def reference(ref, keep: list) -> _Reference:
    """A motor reference as the kernel's struct; arrays it points to are appended to `keep`.

    Raises:
        DesignerError: a reference type the kernel does not know (a Python callable), or a
            trajectory without samples.
    """
    out = _Reference()
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
        out.kind, params, out.n, out.t, out.q = 3, (), len(t), _ptr(t), _ptr(q)
    else:
        raise DesignerError(
            f"the kernel has no motor reference of type {type(ref).__name__}",
            "use a step, sine, chirp or trajectory reference, or engine='python'",
        )
    out.p[: len(params)] = [float(p) for p in params]
    return out


def _robot(robot: Robot, keep: list) -> _Robot:
    """The robot as the kernel's struct: MuJoCo's mjModel/mjData pointers, its joints and motors,
    the spring-dampers MuJoCo computes itself (the validation reference).

    Raises:
        DesignerError: mujoco's bindings too old to give raw pointers.
    """
    if not hasattr(robot.model, "_address"):  # the raw pointers came with mujoco's 3.x bindings
        raise DesignerError(
            "this mujoco's Python bindings give no raw model pointers",
            "update mujoco, or use engine='python'",
        )
    refs = (_Reference * len(robot.motors))(*[reference(r, keep) for r in robot.motors])
    qposadr, dofadr, inputs = _ints(robot.qpos), _ints(robot.dof), _ints(robot._input_dof)
    engine_act = _ints(robot.actuators)
    engine_joint = _ints([robot.joints.index(j) for j in robot.in_engine])
    engine_law = np.array([(v.k, v.c, v.offset) for v in robot.in_engine.values()], float).reshape(-1, 3)
    keep += [refs, qposadr, dofadr, inputs, engine_act, engine_joint, engine_law]
    return _Robot(
        model=robot.model._address,
        data=robot.data._address,
        n_joints=len(robot.joints),
        n_inputs=len(inputs),
        qposadr=_ptr(qposadr, _P_INT),
        dofadr=_ptr(dofadr, _P_INT),
        input_dof=_ptr(inputs, _P_INT),
        refs=refs,
        motor_q=_ptr(robot.motor_q),
        motor_v=_ptr(robot.motor_v),
        steps=robot._steps,
        time=robot.time,
        n_engine=len(engine_act),
        engine_actuator=_ptr(engine_act, _P_INT),
        engine_joint=_ptr(engine_joint, _P_INT),
        engine_law=_ptr(engine_law),
    )


def _function(fmu, name: str) -> int:
    return ctypes.cast(getattr(fmu.dll, name), c_void_p).value


def _fmu(system: FmuSystem, out: _System) -> None:
    """An FMU instance: co-simulation (DoStep) or Model Exchange without states (SetTime, and
    CompletedIntegratorStep when the FMU needs it), as FmuSystem.do_step drives it."""
    fmu, v = system.fmu, system.version
    out.kind = _FMI3 if v == 3 else _FMI2
    out.instance = fmu.component
    p = f"fmi{v}"
    out.set_fn = _function(fmu, p + ("SetFloat64" if v == 3 else "SetReal"))
    out.get_fn = _function(fmu, p + ("GetFloat64" if v == 3 else "GetReal"))
    if system.kind == "co-simulation":
        out.step_fn = _function(fmu, p + "DoStep")
    else:
        out.time_fn = _function(fmu, p + "SetTime")
        if system.needs_completed_step:
            out.completed_fn = _function(fmu, p + "CompletedIntegratorStep")
    out.in_vr = ctypes.cast(system._in_vr, POINTER(c_uint32))
    out.out_vr = ctypes.cast(system._out_vr, POINTER(c_uint32))
    out.steps = system._steps


def _systems(master: Master, keep: list) -> ctypes.Array:
    """The master's systems as kernel structs, in its order.

    Raises:
        DesignerError: a system the kernel cannot run (not a Robot, FmuSystem or HubServo).
    """
    structs = (_System * len(master.systems))()
    for out, (name, system) in zip(structs, master.systems.items(), strict=True):
        src = _ints(master._src[name])
        buf = np.zeros(len(src))
        keep += [src, buf]
        out.n_in, out.n_out = len(system.inputs), len(system.outputs)
        out.out_offset = master._out[name].start
        out.src, out.in_buf = _ptr(src, _P_INT), _ptr(buf)
        if isinstance(system, Robot):
            robot = _robot(system, keep)
            keep.append(robot)
            out.kind, out.instance = _ROBOT, ctypes.addressof(robot)
        elif isinstance(system, FmuSystem):
            _fmu(system, out)
        elif isinstance(system, HubServo):
            servo = _Servo(
                reference(system.chirp, keep),
                system.stiffness,
                system.damping,
                (c_double * 2)(*system._out),
                system._steps,
                system._h,
            )
            keep.append(servo)
            out.kind, out.instance = _SERVO, ctypes.addressof(servo)
        else:
            raise DesignerError(
                f"the kernel cannot run system {name} ({type(system).__name__})",
                "use engine='python' for systems written in Python",
            )
    return structs


def _fail(master: Master, run: _Run, rc: int) -> DesignerError:
    """The error for the kernel's outcome `rc`: divergence, a stop request, an FMU's error status."""
    if rc == _DIVERGED:
        return diverged(run.error_time)
    if rc == _ROBOT_DIVERGED:
        return robot_diverged(run.error_time)
    name = list(master.systems)[run.error_system]
    system = master.systems[name]
    if rc == _TERMINATE:
        return system._terminated()
    call = (*_CALLS[system.version], "SetTime", "CompletedIntegratorStep")[run.error_call]
    return system.status_error(f"fmi{system.version}{call}", run.error_status, run.error_time)


def _events(master: Master, structs: ctypes.Array) -> None:
    """Run the event iterations the Model Exchange instances asked for in their last step."""
    for out, system in zip(structs, master.systems.values(), strict=True):
        if out.asked:
            out.asked = 0
            system._steps = out.steps
            system.completed(True, False)


def _loop(lib: ctypes.CDLL, master: Master, state: _Run, structs: ctypes.Array, chunk: int, progress) -> None:
    """Rows 0..n in chunks of `chunk` rows, progress after each; events handled between rows."""
    n, first = state.n, 0
    while first <= n:
        last = min(first + chunk, n + 1)
        rc = lib.ks_run_rows(ctypes.byref(state), first, last)
        if rc == _EVENT:
            _events(master, structs)
            first = state.event_row + 1
            continue
        if rc != _OK:
            raise _fail(master, state, rc)
        if progress is not None:
            progress(min(last, n) / n)
        first = last


def _sync(master: Master, structs: ctypes.Array) -> None:
    """Hand the step counts and times the kernel advanced back to the Python systems."""
    for out, system in zip(structs, master.systems.values(), strict=True):
        if isinstance(system, Robot):
            robot = _Robot.from_address(out.instance)
            system._steps, system.time = robot.steps, robot.time
        elif isinstance(system, HubServo):
            servo = _Servo.from_address(out.instance)
            system._steps, system._h, system._out[:] = servo.steps, servo.h, list(servo.out)
        else:
            system._steps = out.steps


def run(
    master: Master, duration: float, step: float, *, progress: Callable[[float], None] | None = None
) -> Trace:
    """Run `master`'s systems from 0 to `duration` (s) at macro step `step` (s) in the compiled kernel.

    The result is bit for bit the one `master.run` gives, with `engine="kernel"`.

    Raises:
        DesignerError: the kernel cannot be built or cannot run a system; an FMU returned Discard,
            Error or Fatal; the co-simulation diverged.
    """
    n = steps(duration, step)
    lib = library()
    keep: list = []
    structs = _systems(master, keep)
    index = {name: i for i, name in enumerate(master.systems)}
    ops = _ints([(0 if op == "get" else 1, index[name]) for op, name in master.schedule()]).ravel()
    values = np.empty((n + 1, len(master.columns)))
    state = _Run(
        n_systems=len(structs),
        n_ops=len(ops) // 2,
        n_cols=values.shape[1],
        systems=structs,
        ops=_ptr(ops, _P_INT),
        values=_ptr(values),
        step=step,
        n=n,
    )
    # back in Python every chunk: for the progress, and so that Ctrl-C stops a long run within ms
    chunk = CHUNK if progress is None else max(1, n // 200)
    try:
        _loop(lib, master, state, structs, chunk, progress)
    finally:
        _sync(master, structs)
    return Trace(
        time=np.arange(n + 1) * step,
        columns=master.columns,
        values=values,
        delays=master.delays(),
        engine="kernel",
    )


def run_master(
    master: Master,
    duration: float,
    step: float,
    *,
    progress: Callable[[float], None] | None = None,
    engine: str = "auto",
) -> Trace:
    """Run `master` with `engine`: "kernel", "python" (Master.run), or "auto" (the kernel when it can).

    "auto" falls back to the Python master when there is no C compiler or a system is one the kernel
    cannot run (a system written in Python); `Trace.engine` says which ran.

    Raises:
        DesignerError: unknown engine; with engine="kernel", the kernel cannot run; any run error.
    """
    if engine not in ENGINES:
        raise DesignerError(f"unknown engine '{engine}'", f"use one of: {', '.join(ENGINES)}")
    if engine == "auto":
        try:
            library()
            _systems(master, [])
        except DesignerError:
            engine = "python"
    if engine == "python":
        return master.run(duration, step, progress)
    return run(master, duration, step, progress=progress)
