"""Scenarios: what to co-simulate. `Scenario` is the protocol; `RobotScenario` (robot_scenario.py) and
`RigScenario` (rig_scenario.py) are its two types.

A robot scenario drives flexible joints of a MuJoCo model, each by a motor reference; a rig scenario
drives `rig_joint` by the hub chirp. `Scenario(...)` builds the type its keywords name (`joints=`: a
robot, `rig_joint=`: the rig) and only stores the values (so `dataclasses.replace` is free);
`Scenario.check()` checks every value and fills the defaults, and `designer.cosim.load(path)` (the
TOML loader, scenario_file.py) and `designer.cosim.prepare` call it, so a run never starts on a bad
scenario. Everything a session, a run or a sweep does that depends on the type is a method of the
type (the protocol below); only the two loaders (the file's tables, the constructor's keywords)
decide which type a scenario is. The README documents every key.
"""

from __future__ import annotations

import math
import numbers
from abc import ABC, abstractmethod
from collections import Counter
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from .. import units
from ..errors import DesignerError
from ..joint import MAX_COEFFICIENT, Joint
from .master import ALGORITHMS, Master, Series, System, Trace
from .robot import INTEGRATORS

FMI_VERSIONS = (2, 3)
OUTPUTS = ("csv", "parquet", "plot")
#: the FMU parameters a scenario may override, per axis ("theta.k")
PARAMETER_FIELDS = ("m", "c", "k", "offset", "enabled")


@dataclass(frozen=True)
class JointSource:
    """Where a joint FMU comes from: an FMU file, or a `Joint` exported on the fly.

    `parameters` overrides FMU parameters in SI, keyed "axis.field" (e.g. {"theta.k": 0.3}).
    `keep_host` (robots): keep the host joint's own stiffness, damping and armature in parallel with
    the flexure; by default they are zeroed, since the flexible joint replaces them (and said so).
    Building one stores the values; `check()` (called by `load` and `prepare`) checks them.

    Check raises:
        DesignerError: not exactly one of `fmu` and `joint`, an unknown axis, an FMU file that is
            missing or lacks the axis, a joint without the axis, a bad `fmi_version` or parameter.
    """

    axis: str = "theta"
    fmu: Path | None = None
    joint: Joint | None = None
    fmi_version: int = 2
    parameters: Mapping[str, float] = field(default_factory=dict)
    keep_host: bool = False

    def check(self) -> JointSource:
        """This source checked, its path a Path (construction only stores; load/prepare check).

        Raises:
            DesignerError: as the class says.
        """
        units.check_axis(self.axis)
        if (self.fmu is None) == (self.joint is None):
            raise DesignerError("a JointSource needs exactly one of fmu= or joint=", "give one of them")
        if self.fmi_version not in FMI_VERSIONS:
            raise DesignerError(f"fmi_version = {self.fmi_version!r} is not supported", "use 2 or 3")
        for key, value in self.parameters.items():
            axis, _, name = str(key).partition(".")
            if axis != self.axis or name not in PARAMETER_FIELDS:
                raise DesignerError(
                    f"parameter '{key}' is not a parameter of axis {self.axis}",
                    f"use {', '.join(f'{self.axis}.{f}' for f in PARAMETER_FIELDS)}",
                )
            parameter_value(axis, name, value, f"parameter '{key}'")
        if self.fmu is None:
            self.joint.axis(self.axis)
            return self
        from .fmu import check_fmu

        check_fmu(self.fmu, [self.axis])
        return replace(self, fmu=Path(self.fmu))


#: the most validation steps a scenario lists: each is a whole run, the order of convergence needs 2
MAX_VALIDATION_STEPS = 10

#: the one-line refusal of a scenario that is neither (or both) a robot and the rig
NEITHER = (
    "a scenario needs joints (a robot) or rig_joint (the virtual rig), not both or neither",
    "give joints={'j1': JointSource(...)} or rig_joint=JointSource(...)",
)

#: a run's trace at another step or duration: `Session.trace(case, step=, duration=)`
Tracer = Callable[..., Trace]
Progress = Callable[[float], None] | None
#: the SI m, c, k, offset each joint FMU runs with, by system name (`Session.laws`)
Laws = Mapping[str, Mapping[str, float]]


@dataclass(frozen=True)
class Scenario(ABC):
    """A scenario; times in s, paths absolute. The fields every scenario has are here; the two types
    add theirs (`RobotScenario`: joints, motors, model, lengths, masses; `RigScenario`: rig_joint,
    hub, factors).

    `validation_steps` default to the step halved three times; `validation_duration` to `duration`.
    `path` is the file the scenario was read from, if any. `Scenario(...)` builds the type its
    keywords name; building one stores the values (scikit-learn's convention); `check()` checks and
    completes them, and `load` and `designer.cosim.prepare` call it.

    The protocol (what each type implements): `kind` ("robot" or "rig", for summaries),
    `interface` (the joint FMUs' interface: "force" or "body"), `sources()`, `signals()`,
    `own_fields()` (its fields checked), `wire(fmus, step)`, `reset(master, laws, step)`,
    `metrics(trace, laws)`, `validate(trace, case, laws, progress)`, `notes(master)`,
    `write_extra(series, folder)` and `factors_of(joint)`.
    """

    duration: float
    step: float
    algorithm: str = "gauss-seidel"
    integrator: str | None = None
    outputs: Mapping[str, bool] = field(default_factory=dict)
    validation_steps: tuple[float, ...] = ()
    validation_duration: float | None = None
    path: Path | None = None
    #: True on what `check()` returns; `dataclasses.replace` gives an unchecked copy again
    checked: bool = field(default=False, init=False, repr=False, compare=False)

    #: "robot" or "rig"
    kind: ClassVar[str]
    #: the keyword of `Scenario(...)` that builds this type
    keyword: ClassVar[str]
    #: the interface of its joint FMUs: "force" (a force element) or "body" (the rig's specimen)
    interface: ClassVar[str]

    def __new__(cls, *args: Any, **kwargs: Any) -> Scenario:
        """`Scenario(...)` builds the type whose keyword is given (`joints=` or `rig_joint=`)."""
        if cls is not Scenario:
            return super().__new__(cls)
        named = [t for t in Scenario.__subclasses__() if t.keyword in kwargs]
        if len(named) != 1:
            raise DesignerError(*NEITHER)
        return super().__new__(named[0])

    def check(self) -> Scenario:
        """This scenario checked and completed (defaults filled in, paths as Path, sources checked).

        Building a Scenario only stores its values; `load` and `cosim.prepare` call this, so a run
        never starts on a bad scenario, and `dataclasses.replace` costs no file reads.

        Raises:
            DesignerError: the first value that is out of range or inconsistent, naming its field.
        """
        step, duration = positive(self.step, "step"), positive(self.duration, "duration")
        if duration < step:
            raise DesignerError(f"duration = {duration:g} s is shorter than step = {step:g} s", "lengthen it")
        one_of(self.algorithm, ALGORITHMS, "algorithm")
        if self.integrator is not None:  # None: the robot model's own
            one_of(self.integrator, INTEGRATORS, "integrator")
        if not self.sources():
            raise DesignerError(*NEITHER)
        unknown = set(self.outputs) - set(OUTPUTS)
        if unknown or not all(isinstance(v, bool) for v in self.outputs.values()):
            raise DesignerError(
                f"outputs = {dict(self.outputs)} is not a set of switches", "use csv, parquet, plot"
            )
        own = self.own_fields()
        own["outputs"] = {k: bool(self.outputs.get(k, True)) for k in OUTPUTS}
        sc = replace(self, **own, **self._validation_fields())
        check_memory(sc)
        object.__setattr__(sc, "checked", True)  # a frozen dataclass's own flag, set once here
        return sc

    def _validation_fields(self) -> dict[str, Any]:
        steps = self.validation_steps or tuple(self.step / 2**i for i in range(4))
        steps = tuple(positive(s, "validation_steps") for s in steps)
        if len(steps) < 2:
            raise DesignerError(
                f"validation_steps = {list(steps)} lists fewer than two steps", "e.g. [1e-3, 5e-4]"
            )
        twice = sorted(s for s, n in Counter(steps).items() if n > 1)
        if twice:
            raise DesignerError(
                f"validation_steps lists {', '.join(f'{s:g}' for s in twice)} more than once",
                "list each step once, e.g. [1e-3, 5e-4]",
            )
        if len(steps) > MAX_VALIDATION_STEPS:
            raise DesignerError(
                f"validation_steps lists {len(steps)} steps; a convergence check takes 2 to "
                f"{MAX_VALIDATION_STEPS}, each run in turn",
                "list a few steps halving down, e.g. [1e-3, 5e-4, 2.5e-4]",
            )
        span = (
            self.duration
            if self.validation_duration is None
            else positive(self.validation_duration, "validation_duration")
        )
        return {"validation_steps": steps, "validation_duration": min(span, self.duration)}

    # ------------------------------------------------------------------ the protocol

    @abstractmethod
    def own_fields(self) -> dict[str, Any]:
        """This type's own fields checked and completed (what `check` replaces them with)."""

    @abstractmethod
    def sources(self) -> dict[str, JointSource]:
        """The joint sources by system name ("rig" for the virtual rig's joint); empty: none given."""

    @abstractmethod
    def signals(self) -> int:
        """How many signals a run records per step (the width of its result)."""

    @abstractmethod
    def wire(self, fmus: Mapping[str, System], step: float) -> Master:
        """The joint FMU systems `fmus` (by system name) wired to the robot or the rig's hub at `step` (s)."""

    @abstractmethod
    def reset(self, master: Master, laws: Callable[[], Laws], step: float) -> None:
        """Bring `master`'s systems other than the joint FMUs back to t = 0 for a case whose joints run
        with `laws()` (SI m, c, k, offset by system) at `step` (s)."""

    @abstractmethod
    def metrics(self, trace: Trace, laws: Laws) -> dict[str, Any]:
        """A run's metrics (see README) from its `trace` and the joints' SI `laws`."""

    @abstractmethod
    def validate(self, trace: Tracer, case: Mapping, laws: Laws, progress: Progress) -> dict[str, Any]:
        """The comparison with this type's reference solution at the validation steps; `trace` runs the
        case at another step (`Session.trace`)."""

    @abstractmethod
    def notes(self, master: Master) -> tuple[str, ...]:
        """What a reader of a run wired by `master` should know (host elements changed, ...)."""

    @abstractmethod
    def write_extra(self, series: Series, folder: Path) -> list[Path]:
        """The files this type writes beside a run's time series and metrics (the rig's log) into
        `folder`; their paths."""

    @abstractmethod
    def factors_of(self, joint: str) -> Mapping[str, float] | None:
        """The print settings the scenario itself states for `joint` (the rig's `factors`), or None."""


def check_memory(sc: Scenario, duration: float | None = None) -> None:
    """Refuse a run whose results would not fit in memory, before anything is allocated; `duration`
    (s) replaces the scenario's (`Session.run(duration=)`).

    Raises:
        DesignerError: with the estimate and what is available.
    """
    from ..limits import check_memory as check

    duration = sc.duration if duration is None else duration
    rows = duration / sc.step + 1
    check(
        8.0 * rows * (sc.signals() + 1),
        what=f"duration = {duration:g} s at step = {sc.step:g} s ({rows:.3g} steps)",
        fix="shorten the duration or lengthen the step",
    )


def finite(value: Any, what: str) -> float:
    """`value` as a float.

    Raises:
        DesignerError: not a finite number (a bool is not one), naming `what`.
    """
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise DesignerError(f"{what} = {value!r} is not a finite number", "give a finite number")
    return float(value)


def parameter_value(axis: str, field: str, value: Any, what: str) -> float | bool:
    """A joint parameter's value checked: `enabled` a bool (Python's or numpy's), the others a finite
    number (numpy's float32 and int64 included, a bool not), m, c and k no larger than any physical
    joint's (`designer.joint.MAX_COEFFICIENT` in rig units).

    Raises:
        DesignerError: the value is not of its field's kind or beyond a joint's, naming `what`.
    """
    if field == "enabled":
        if not isinstance(value, (bool, np.bool_)):
            raise DesignerError(f"{what} = {value!r} is not true or false", "give True or False")
        return bool(value)
    real = isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_))
    if not real or not math.isfinite(value):
        raise DesignerError(f"{what} = {value!r} is not a finite number", "give its value in SI")
    if field in ("m", "c", "k") and units.from_si(field, axis, float(value)) > MAX_COEFFICIENT:
        top = units.to_si(field, axis, MAX_COEFFICIENT)
        raise DesignerError(
            f"{what} = {float(value):g} {units.si_unit(field, axis)} is beyond any physical joint",
            f"give it in SI, at most {top:g} {units.si_unit(field, axis)}",
        )
    return float(value)


def positive(value: Any, what: str) -> float:
    """`value` as a positive float.

    Raises:
        DesignerError: not a finite positive number, naming `what`.
    """
    v = finite(value, what)
    if v <= 0:
        raise DesignerError(f"{what} = {v:g} must be positive", "give a positive number")
    return v


def one_of(value: Any, options: tuple, what: str) -> None:
    """Refuse a `value` not among `options`.

    Raises:
        DesignerError: naming `what` and the options.
    """
    if value not in options:
        raise DesignerError(
            f"{what} = {value!r} is not allowed", f"use one of: {', '.join(map(str, options))}"
        )
