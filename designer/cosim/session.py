"""Prepare once, run many: a co-simulation `Session` (FMPy's efficient loops, mujoco's `Rollout`).

`prepare(scenario)` does every piece of set-up once: it checks the scenario, unpacks each joint FMU
(only `binaries/` and `resources/`; a joint given as a `Joint` is written there as its export would
archive it, without the zip) into one temporary folder, reads each modelDescription once,
instantiates the FMUs, compiles the MuJoCo model and wires the master. `Session.run(parameters)`
then resets every system (FMI Reset, `mj_resetData`, counters), applies the case's parameters and
runs the loop: the cost of a run is the loop itself.

    with designer.cosim.prepare(sc) as session:
        for k in (0.2, 0.3, 0.4):
            result = session.run({"j1": {"theta.k": k}})      # SI, keyed "axis.field"

`close()` (the end of the `with` block) frees the FMU instances and removes the temporary folder, on
every path, also when `prepare` fails halfway.
"""

from __future__ import annotations

import contextlib
from collections.abc import Mapping
from pathlib import Path

from ..errors import DesignerError, check_type, describe
from ..files import temporary_folder
from .fmu import FmuDescription, FmuSystem, unpack
from .kernel import ENGINES, Bound, bind, run_master
from .master import Master, Trace
from .result import Result
from .scenario import (
    PARAMETER_FIELDS,
    JointSource,
    Progress,
    Scenario,
    check_memory,
    parameter_value,
    positive,
)


def _unpacked(src: JointSource, interface: str, folder: Path) -> Path:
    """A joint's FMU as an importer loads it, in `folder`: an FMU file's binaries/ and resources/, or
    for a `Joint` the files its export would archive, written there directly (no zip; no sources)."""
    if src.fmu is not None:
        return unpack(src.fmu, folder)
    from ..export.fmu import archive_entries

    for name, data in archive_entries(src.joint, src.fmi_version, interface).items():
        if name.startswith(("binaries/", "resources/")) or name == "modelDescription.xml":
            target = folder / name
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(data)
            if name.startswith("binaries/"):
                target.chmod(0o755)
    return folder


class Session:
    """A prepared co-simulation: systems built once, run many times (see the module's docstring).

    Attributes: `scenario` (checked), `descriptions` (each joint FMU's modelDescription, read once),
    `systems` (the FMU systems by name), `master` (the wiring at the scenario's step). Build it with
    `prepare`; use it as a context manager or call `close()`. A session runs one case at a time:
    its FMU instances and MjData are its own; prepare one per thread.
    """

    def __init__(self, scenario: Scenario, stack: contextlib.ExitStack, folder: Path) -> None:
        self.scenario = scenario
        self._stack = stack
        self._folder = folder
        self.descriptions: dict[str, FmuDescription] = {}
        self.systems: dict[str, FmuSystem] = {}
        self._masters: dict[float, Master] = {}
        self._bound: dict[float, Bound | None] = {}
        self.closed = False
        self._load()  # what it builds is registered on `stack`, which its caller closes on failure

    @property
    def master(self) -> Master:
        """The systems wired at the scenario's step (robot or hub, and the joint FMUs).

        Raises:
            DesignerError: the session is closed.
        """
        self._open()
        return self._masters[self.scenario.step]

    def _open(self) -> None:
        if self.closed:
            raise DesignerError("the session is closed", "prepare the scenario again")

    # ------------------------------------------------------------------ set-up (prepare)

    def _load(self) -> None:
        """Unpack (or write) each joint FMU, read its description, instantiate it; wire the master."""
        sc = self.scenario
        interface = sc.interface
        for name, src in sc.sources().items():
            unpacked = _unpacked(src, interface, self._folder / name)
            md = FmuDescription(src.fmu or unpacked, [src.axis])
            if md.interface != interface:
                raise DesignerError(
                    f"the FMU of joint {name} has the {md.interface} interface",
                    f"export it with interface='{interface}'",
                )
            self.descriptions[name] = md
            system = FmuSystem(md, [src.axis], name=name, parameters=src.parameters, folder=unpacked)
            self._stack.callback(system.close)
            self.systems[name] = system
        self._masters[sc.step] = self._master(sc.step)

    def _master(self, step: float) -> Master:
        """The session's FMU systems wired to a robot (or the rig's hub) stepping at `step` (s)."""
        return self.scenario.wire(self.systems, step)

    # ------------------------------------------------------------------ one run

    def parameters(
        self, parameters: Mapping[str, Mapping[str, float | bool]] | None
    ) -> dict[str, dict[str, float | bool]]:
        """A case's parameters checked: {system: {"axis.field": SI value, or a bool for "axis.enabled"}}
        (systems as in `laws`).

        Raises:
            DesignerError: an unknown system or parameter, a value that is not a finite number, or an
                `enabled` that is not a bool.
        """
        out: dict[str, dict[str, float]] = {name: {} for name in self.systems}
        example = 'give {"j1": {"theta.k": 0.3, "theta.c": 8e-4}} (SI, by joint)'
        if parameters is not None and not isinstance(parameters, Mapping):
            raise DesignerError(f"parameters is {describe(parameters)}, not a mapping", example)
        for name, values in (parameters or {}).items():
            if name not in self.systems:
                raise DesignerError(
                    f"parameters name '{name}', which is not a joint of the scenario",
                    f"its joints: {', '.join(self.systems)}",
                )
            axis = self.scenario.sources()[name].axis
            if not isinstance(values, Mapping):
                raise DesignerError(f"parameters['{name}'] is {describe(values)}, not a mapping", example)
            for key, value in values.items():
                field = str(key).partition(".")[2]
                if not str(key).startswith(f"{axis}.") or field not in PARAMETER_FIELDS:
                    raise DesignerError(
                        f"parameters['{name}'] has '{key}', not a parameter of axis {axis}",
                        f"use {', '.join(f'{axis}.{f}' for f in PARAMETER_FIELDS)}",
                    )
                out[name][str(key)] = parameter_value(axis, field, value, f"parameters['{name}']['{key}']")
        return out

    def laws(self, case: Mapping[str, Mapping[str, float]]) -> dict[str, dict[str, float]]:
        """The SI m, c, k, offset each joint FMU runs with: start values, the scenario's overrides,
        then the case's (`case` as `parameters` returns it); k and c are 0 where `enabled` is False."""
        out = {}
        for name, src in self.scenario.sources().items():
            law = self.descriptions[name].parameters(src.axis)
            given = dict(src.parameters) | case[name]
            for key, value in given.items():
                axis, _, field = key.partition(".")
                if axis == src.axis and field in ("m", "c", "k", "offset"):
                    law[field] = float(value)
            law.setdefault("offset", 0.0)
            if given.get(f"{src.axis}.enabled") is False:  # the spring-damper off: the joint is free
                law["k"] = law["c"] = 0.0
            out[name] = law
        return out

    def trace(
        self,
        case: Mapping[str, Mapping[str, float]] | None = None,
        *,
        step: float | None = None,
        duration: float | None = None,
        progress: Progress = None,
        engine: str = "auto",
    ) -> Trace:
        """The time series of one run: every system reset, `case` applied (as `parameters` returns
        it; None: the scenario as it is), the loop run at `step` for `duration` (s; defaults the
        scenario's). A step other than the scenario's gets its own robot (or hub), built once.

        Raises:
            DesignerError: as `run`.
        """
        self._open()
        sc = self.scenario
        case = self.parameters(None) if case is None else case
        step = sc.step if step is None else step
        if duration is not None:
            duration = positive(duration, "duration")
            check_memory(sc, duration)
        if step not in self._masters:
            self._masters[step] = self._master(step)
        master = self._masters[step]
        for name, system in self.systems.items():
            system.reset(case[name])
        sc.reset(master, lambda: self.laws(case), step)
        bound = self._kernel(step, master, engine)
        if bound is None and engine == "auto":
            engine = "python"
        span = sc.duration if duration is None else duration
        return run_master(master, span, step, progress=progress, engine=engine, bound=bound)

    def _kernel(self, step: float, master: Master, engine: str) -> Bound | None:
        """The master at `step` bound to the compiled kernel once (None: python, or it cannot)."""
        if engine not in ENGINES:
            raise DesignerError(f"unknown engine '{engine}'", f"use one of: {', '.join(ENGINES)}")
        if engine == "python":
            return None
        if step not in self._bound:
            try:
                self._bound[step] = bind(master)
            except DesignerError:
                if engine == "kernel":
                    raise
                self._bound[step] = None
        return self._bound[step]

    def run(
        self,
        parameters: Mapping[str, Mapping[str, float]] | None = None,
        *,
        duration: float | None = None,
        engine: str = "auto",
        validate: bool = False,
        progress: Progress = None,
    ) -> Result:
        """Run one case and return its `Result` (in memory; nothing is written).

        Args:
            parameters: the case's FMU parameters, SI, by joint (by "rig" for the virtual rig):
                {"j1": {"theta.k": 0.3, "theta.c": 8e-4}}; None runs the scenario as it is.
            duration: s, default the scenario's.
            engine: "kernel", "python" or "auto" (see `designer.cosim.run`).
            validate: also compare with the reference solutions (see `designer.cosim.run`).
            progress: called with the fraction done, 0 to 1.

        Raises:
            DesignerError: bad parameters, an FMU that refuses them or fails during the run (with its
                log line), a co-simulation that diverges, a closed session.
        """
        share = 0.5 if validate else 1.0

        def part(offset: float, scale: float) -> Progress:
            return None if progress is None else (lambda f: progress(offset + scale * f))

        sc = self.scenario
        case = self.parameters(parameters)
        laws = self.laws(case)
        trace = self.trace(case, duration=duration, progress=part(0.0, share), engine=engine)
        metrics = sc.metrics(trace, laws)
        validation = sc.validate(self.trace, case, laws, part(share, 1.0 - share)) if validate else None
        notes = (*trace.delays, *sc.notes(self.master))
        return Result(
            sc, trace.time, trace.columns, trace.values, metrics, laws, validation, notes, trace.engine
        )

    # ------------------------------------------------------------------ life cycle

    def close(self) -> None:
        """Free every FMU instance and remove the temporary folder (idempotent)."""
        if not self.closed:
            self.closed = True
            self._masters.clear()
            self._bound.clear()
            self._stack.close()

    def __enter__(self) -> Session:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def prepare(scenario: Scenario) -> Session:
    """Check `scenario` and build everything its runs share, once (see the module's docstring).

    Returns:
        A `Session`: use it in a `with` block (or call `close()`).

    Raises:
        DesignerError: a bad scenario, an FMU that cannot be read or refuses its parameters (with its
            log line), a robot model MuJoCo cannot compile. Whatever was built is freed first.
    """
    fix = "read one with designer.cosim.load(path)"
    check_type(scenario, Scenario, "scenario", expected="a Scenario", fix=fix)
    sc = scenario if scenario.checked else scenario.check()
    stack = contextlib.ExitStack()
    try:
        folder = stack.enter_context(temporary_folder("designer-cosim-"))
        session = Session(sc, stack, folder)
    except BaseException:
        stack.close()
        raise
    return session
