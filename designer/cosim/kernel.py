"""Run a Master's fixed-step loop in the compiled kernel (fmus/kernel/): same exchange, same bits, C speed.

Python keeps everything but the loop: the Master checks the wiring and orders the exchange
(`Master.schedule`), fmpy instantiates the FMUs, the Robot compiles the MuJoCo model. Each system
describes itself to the kernel through `binding()` (the contract in designer/cosim/binding.py): the
address of its instance, its FMI functions and value references, and what to do before and after a
run. `bind(master)` turns those into the kernel's structs once; `Bound.run` then only fills a
preallocated output array. `run_master` picks the engine: the kernel when it can run every system,
else the Python master (`Trace.engine` says which ran).
"""

from __future__ import annotations

import ctypes
import functools
from collections.abc import Callable
from ctypes import POINTER, c_double, c_int32, c_int64, c_uint32, c_void_p

import numpy as np

from ..errors import DesignerError
from . import binding as kb
from .clock import without_clock
from .master import Master, Trace, diverged, steps

ENGINES = ("auto", "kernel", "python")
#: rows per kernel call without a progress callback
CHUNK = 10000
_OK, _DIVERGED, _EVENT, _TERMINATE = 0, 2, 4, 5  # else 1 (an FMU's status) or 3 (the robot's), see _fail


class _System(ctypes.Structure):
    """kernel.h ks_system: one system of the graph, as its Binding describes it."""

    _fields_ = [
        ("kind", c_int32),
        ("n_in", c_int32),
        ("n_out", c_int32),
        ("out_offset", c_int32),
        ("src", kb.P_INT),
        ("in_buf", kb.P_DOUBLE),
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
    """kernel.h ks_run: the systems, the schedule, the output rows and, after an error, what failed."""

    _fields_ = [
        ("n_systems", c_int32),
        ("n_ops", c_int32),
        ("n_cols", c_int32),
        ("pad", c_int32),
        ("systems", POINTER(_System)),
        ("ops", kb.P_INT),
        ("values", kb.P_DOUBLE),
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
    lib.ks_reference_eval.argtypes = [POINTER(kb.Reference), c_double, kb.P_DOUBLE, kb.P_DOUBLE]
    lib.ks_reference_eval.restype = None
    lib.ks_struct_size.argtypes = [c_int32]
    lib.ks_struct_size.restype = c_int64
    sizes = (c_int64 * 3)()
    lib.ks_sizes(sizes)
    mirror = [ctypes.sizeof(t) for t in (kb.Reference, _System, _Run)]
    if list(sizes) != mirror:
        raise DesignerError(
            f"the kernel's structs ({list(sizes)} bytes) do not match their Python mirror ({mirror})",
            "use engine='python', and report this with your platform",
        )
    return lib


def _describe(master: Master, name: str, system, out: _System, keep: list) -> kb.Binding:
    """Fill `out` from the system's Binding; arrays it points to go to `keep`.

    Raises:
        DesignerError: a system without `binding()` (one written in Python only).
    """
    make = getattr(system, "binding", None)
    if make is None:
        raise DesignerError(
            f"the kernel cannot run system {name} ({type(system).__name__})",
            "use engine='python' for systems written in Python",
        )
    b = make()
    if b.struct is not None and ctypes.sizeof(b.struct) != library().ks_struct_size(b.kind):
        raise DesignerError(
            f"the kernel's struct for system {name} ({library().ks_struct_size(b.kind)} bytes) does not "
            f"match its Python mirror {type(b.struct).__name__} ({ctypes.sizeof(b.struct)} bytes)",
            "use engine='python', and report this with your platform",
        )
    src = kb.ints(master.sources(name))
    buf = np.zeros(len(src))
    keep += [src, buf, b.keep]
    out.kind, out.instance = b.kind, b.instance
    out.n_in, out.n_out = len(system.inputs), len(system.outputs)
    out.out_offset = master.output_slice(name).start
    out.src, out.in_buf = kb.pointer(src, kb.P_INT), kb.pointer(buf)
    for call in kb.CALLS:
        setattr(out, f"{call}_fn", b.functions.get(call))
    if b.in_vr is not None:
        out.in_vr = ctypes.cast(b.in_vr, POINTER(c_uint32))
    if b.out_vr is not None:
        out.out_vr = ctypes.cast(b.out_vr, POINTER(c_uint32))
    return b


class Bound:
    """A master's systems bound to the kernel once (`bind`); `run` as many times as wanted, each
    after the systems were reset (or left where the last run ended).

    Raises (constructor):
        DesignerError: the kernel cannot be built or cannot run one of the systems.
    """

    def __init__(self, master: Master) -> None:
        self.master = master
        self.lib = library()
        self._keep: list = []
        self._structs = (_System * len(master.systems))()
        self._bindings = [
            _describe(master, name, system, out, self._keep)
            for out, (name, system) in zip(self._structs, master.systems.items(), strict=True)
        ]
        index = {name: i for i, name in enumerate(master.systems)}
        self._ops = kb.ints(
            [(0 if op == "get" else 1, index[name]) for op, name in master.schedule()]
        ).ravel()

    def _fail(self, run: _Run, rc: int) -> DesignerError:
        """The error for the kernel's outcome `rc`: divergence, a stop request, an FMU's error status."""
        if rc == _DIVERGED:
            return diverged(run.error_time)
        b = self._bindings[run.error_system]  # an FMU's status, or the robot's divergence
        if rc == _TERMINATE and b.terminated is not None:
            return b.terminated()
        return b.error(run.error_call, run.error_status, run.error_time)

    def _events(self) -> None:
        """Run the event iterations the Model Exchange instances asked for in their last step."""
        for out, b in zip(self._structs, self._bindings, strict=True):
            if out.asked:
                out.asked = 0
                b.finish(out.steps)
                b.event()

    def _loop(self, state: _Run, chunk: int, progress) -> None:
        """Rows 0..n in chunks of `chunk` rows, progress after each; events handled between rows."""
        n, first = state.n, 0
        while first <= n:
            last = min(first + chunk, n + 1)
            rc = self.lib.ks_run_rows(ctypes.byref(state), first, last)
            if rc == _EVENT:
                self._events()
                first = state.event_row + 1
                continue
            if rc != _OK:
                raise self._fail(state, rc)
            if progress is not None:
                progress(min(last, n) / n)
            first = last

    def run(self, duration: float, step: float, *, progress: Callable[[float], None] | None = None) -> Trace:
        """Run the bound systems from where they are for `duration` (s) at macro step `step` (s).

        Raises:
            DesignerError: an FMU returned Discard, Error or Fatal; the co-simulation diverged.
        """
        n = steps(duration, step)
        master = self.master
        for out, b in zip(self._structs, self._bindings, strict=True):
            out.steps, out.asked, out.failed = b.start(step), 0, 0
        values = np.empty((n + 1, len(master.columns)))
        state = _Run(
            n_systems=len(self._structs),
            n_ops=len(self._ops) // 2,
            n_cols=values.shape[1],
            systems=self._structs,
            ops=kb.pointer(self._ops, kb.P_INT),
            values=kb.pointer(values),
            step=step,
            n=n,
        )
        # back in Python every chunk: for the progress, and so that Ctrl-C stops a long run within ms
        chunk = CHUNK if progress is None else max(1, n // 200)
        try:
            self._loop(state, chunk, progress)
        finally:
            for out, b in zip(self._structs, self._bindings, strict=True):
                b.finish(out.steps)
        return Trace(
            time=np.arange(n + 1) * step,
            columns=master.columns,
            values=values,
            delays=master.delays(),
            engine="kernel",
        )


def bind(master: Master) -> Bound:
    """`master`'s systems bound to the compiled kernel once (see `Bound`).

    Raises:
        DesignerError: the kernel cannot be built or cannot run one of the systems.
    """
    return Bound(master)


def run(
    master: Master, duration: float, step: float, *, progress: Callable[[float], None] | None = None
) -> Trace:
    """Run `master`'s systems from 0 to `duration` (s) at macro step `step` (s) in the compiled kernel.

    The result is bit for bit the one `master.run` gives, with `engine="kernel"`.

    Raises:
        DesignerError: the kernel cannot be built or cannot run a system; an FMU returned Discard,
            Error or Fatal; the co-simulation diverged.
    """
    return bind(master).run(duration, step, progress=progress)


def run_master(
    master: Master,
    duration: float,
    step: float,
    *,
    progress: Callable[[float], None] | None = None,
    engine: str = "auto",
    bound: Bound | None = None,
) -> Trace:
    """Run `master` with `engine`: "kernel", "python" (Master.run), or "auto" (the kernel when it can).

    "auto" falls back to the Python master when there is no C compiler or a system is one the kernel
    cannot run (a system written in Python); `Trace.engine` says which ran. `bound`, the master bound
    once by `bind`, saves binding it again.

    Raises:
        DesignerError: unknown engine; with engine="kernel", the kernel cannot run; any run error.
    """
    if engine not in ENGINES:
        raise DesignerError(f"unknown engine '{engine}'", f"use one of: {', '.join(ENGINES)}")
    if engine == "python":
        with without_clock():
            return master.run(duration, step, progress)
    if bound is None:
        try:
            bound = bind(master)
        except DesignerError:
            if engine == "kernel":
                raise
            with without_clock():
                return master.run(duration, step, progress)
    return bound.run(duration, step, progress=progress)
