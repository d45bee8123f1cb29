"""Scenarios: what to co-simulate, built in code or read from a TOML file.

A scenario is either a robot (`joints`: flexible joints of a MuJoCo model, each driven by a motor
reference) or the virtual rig (`rig_joint` driven by the hub chirp). `Scenario(...)` stores its values
(so `dataclasses.replace` is free); `Scenario.check()` checks every value and fills the defaults, and
`load(path)` and `designer.cosim.prepare` call it, so a run never starts on a bad scenario. `load`
also checks the file's keys and types and names the file and key of the first problem. The README
documents every key.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from .. import units
from ..errors import DesignerError
from ..joint import Joint, from_one_source
from ..keys import check_keys, read_toml
from .master import ALGORITHMS
from .references import Chirp, Reference, Sine, Step, Trajectory
from .robot import ARM_LENGTHS, ARM_MASSES, INTEGRATORS

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
            _finite(value, f"parameter '{key}'")
        if self.fmu is None:
            self.joint.axis(self.axis)
            return self
        from .fmu import check_fmu

        check_fmu(self.fmu, [self.axis])
        return replace(self, fmu=Path(self.fmu))


@dataclass(frozen=True)
class Scenario:
    """A scenario; times in s, lengths in m, masses in kg, paths absolute.

    Robot: `joints` maps hinge or slide joints of the model (None: the built-in planar arm with
    `lengths` and `masses`, hinges j1..jN) to their `JointSource`; `motors` gives each joint's motor
    reference (default: held at 0). Rig: `rig_joint` (needs a mass) is driven by `hub` (default:
    the study's chirp, 1 rad, 0.2 to 1.85 Hz over 2200 s); `factors` go into the rig log's sidecar.
    `validation_steps` default to the step halved three times; `validation_duration` to `duration`.
    `path` is the file the scenario was read from, if any.

    Building one stores the values (scikit-learn's convention); `check()` checks and completes them,
    and `load` and `designer.cosim.prepare` call it.
    """

    duration: float
    step: float
    joints: Mapping[str, JointSource] = field(default_factory=dict)
    motors: Mapping[str, Reference] = field(default_factory=dict)
    model: Path | None = None
    lengths: tuple[float, ...] = ARM_LENGTHS
    masses: tuple[float, ...] = ARM_MASSES
    rig_joint: JointSource | None = None
    hub: Chirp | None = None
    factors: Mapping[str, float] | None = None
    algorithm: str = "gauss-seidel"
    integrator: str = "euler"
    outputs: Mapping[str, bool] = field(default_factory=dict)
    validation_steps: tuple[float, ...] = ()
    validation_duration: float | None = None
    path: Path | None = None
    #: True on what `check()` returns; `dataclasses.replace` gives an unchecked copy again
    checked: bool = field(default=False, init=False, repr=False, compare=False)

    @property
    def kind(self) -> str:
        """ "robot" or "rig"."""
        return "rig" if self.rig_joint is not None else "robot"

    def check(self) -> Scenario:
        """This scenario checked and completed (defaults filled in, paths as Path, sources checked).

        Building a Scenario only stores its values; `load` and `cosim.prepare` call this, so a run
        never starts on a bad scenario, and `dataclasses.replace` costs no file reads.

        Raises:
            DesignerError: the first value that is out of range or inconsistent, naming its field.
        """
        step, duration = _positive(self.step, "step"), _positive(self.duration, "duration")
        if duration < step:
            raise DesignerError(f"duration = {duration:g} s is shorter than step = {step:g} s", "lengthen it")
        _one_of(self.algorithm, ALGORITHMS, "algorithm")
        _one_of(self.integrator, INTEGRATORS, "integrator")
        if bool(self.joints) == (self.rig_joint is not None):
            raise DesignerError(
                "a scenario needs joints (a robot) or rig_joint (the virtual rig), not both or neither",
                "give joints={'j1': JointSource(...)} or rig_joint=JointSource(...)",
            )
        unknown = set(self.outputs) - set(OUTPUTS)
        if unknown or not all(isinstance(v, bool) for v in self.outputs.values()):
            raise DesignerError(
                f"outputs = {dict(self.outputs)} is not a set of switches", "use csv, parquet, plot"
            )
        fields = self._robot_fields() if self.kind == "robot" else self._rig_fields()
        fields["outputs"] = {k: bool(self.outputs.get(k, True)) for k in OUTPUTS}
        sc = replace(self, **fields, **self._validation_fields())
        check_memory(sc)
        object.__setattr__(sc, "checked", True)  # a frozen dataclass's own flag, set once here
        return sc

    def _robot_fields(self) -> dict[str, Any]:
        from .robot import check_joints, load_spec

        out: dict[str, Any] = {}
        if self.model is not None:
            out["model"] = Path(self.model)
        else:
            lengths = tuple(_positive(v, "lengths") for v in self.lengths)
            masses = tuple(_positive(v, "masses") for v in self.masses)
            if not lengths or len(lengths) != len(masses):
                raise DesignerError(
                    f"lengths ({len(lengths)}) and masses ({len(masses)}) differ in number",
                    "give one length and one mass per link",
                )
            out |= {"lengths": lengths, "masses": masses}
        spec = load_spec(out.get("model"), out.get("lengths", self.lengths), out.get("masses", self.masses))
        check_joints(spec, list(self.joints))
        for name, src in self.joints.items():
            if not isinstance(src, JointSource):
                raise DesignerError(f"joints['{name}'] is a {type(src).__name__}", "give a JointSource")
        out["joints"] = {name: src.check() for name, src in self.joints.items()}
        extra = set(self.motors) - set(self.joints)
        if extra:
            raise DesignerError(
                f"motors name joint(s) without a flexible joint: {', '.join(sorted(extra))}",
                f"flexible joints: {', '.join(self.joints)}",
            )
        for name, ref in self.motors.items():
            if not isinstance(ref, (Step, Sine, Chirp, Trajectory)):
                raise DesignerError(
                    f"motors['{name}'] is a {type(ref).__name__}", "give a Step, Sine, Chirp or Trajectory"
                )
        out["motors"] = {j: self.motors.get(j, Step(0.0)) for j in self.joints}
        return out

    def _rig_fields(self) -> dict[str, Any]:
        src = self.rig_joint
        if not isinstance(src, JointSource):
            raise DesignerError(f"rig_joint is a {type(src).__name__}", "give a JointSource")
        src = src.check()
        if src.joint is not None and src.joint.axis(src.axis).m is None:
            raise DesignerError(
                f"the rig joint has no mass on axis {src.axis}",
                "give its m, or build it from a design so the mass follows from geometry",
            )
        hub = Chirp() if self.hub is None else self.hub
        hub.check_sampling(1.0 / self.step, what="1 / step")
        out: dict[str, Any] = {"rig_joint": src, "hub": hub}
        if self.factors is not None:
            from ..study import space

            out["factors"] = space.check_design(self.factors)
        return out

    def _validation_fields(self) -> dict[str, Any]:
        steps = self.validation_steps or tuple(self.step / 2**i for i in range(4))
        steps = tuple(_positive(s, "validation_steps") for s in steps)
        if len(steps) < 2:
            raise DesignerError(
                f"validation_steps = {list(steps)} lists fewer than two steps", "e.g. [1e-3, 5e-4]"
            )
        span = (
            self.duration
            if self.validation_duration is None
            else _positive(self.validation_duration, "validation_duration")
        )
        return {"validation_steps": steps, "validation_duration": min(span, self.duration)}

    def signals(self) -> int:
        """How many signals a run records per step (the width of its result)."""
        return 6 if self.kind == "rig" else 5 * len(self.joints)


def check_memory(sc: Scenario) -> None:
    """Refuse a run whose results would not fit in memory, before anything is allocated.

    Raises:
        DesignerError: with the estimate and what is available.
    """
    from ..limits import check_memory as check

    rows = sc.duration / sc.step + 1
    check(
        8.0 * rows * (sc.signals() + 1),
        what=f"duration = {sc.duration:g} s at step = {sc.step:g} s ({rows:.3g} steps)",
        fix="shorten the duration or lengthen the step",
    )


def _finite(value: Any, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise DesignerError(f"{what} = {value!r} is not a finite number", "give a finite number")
    return float(value)


def _positive(value: Any, what: str) -> float:
    v = _finite(value, what)
    if v <= 0:
        raise DesignerError(f"{what} = {v:g} must be positive", "give a positive number")
    return v


def _one_of(value: Any, options: tuple, what: str) -> None:
    if value not in options:
        raise DesignerError(
            f"{what} = {value!r} is not allowed", f"use one of: {', '.join(map(str, options))}"
        )


# ---------------------------------------------------------------- reading a TOML file

#: keys of each table of a scenario file
KEYS = {
    "": ("simulation", "robot", "joints", "rig", "outputs", "validation"),
    "simulation": ("duration", "step", "algorithm", "integrator"),
    "robot": ("model", "lengths", "masses"),
    "joint": (
        "fmu",
        "coefficients",
        "design",
        "suggestion",
        "candidate",
        "axis",
        "fmi_version",
        "parameters",
        "reference",
        "keep_host",
    ),
    "rig": ("joint", "amplitude", "f0", "f1", "sweep", "factors"),
    "validation": ("steps", "duration"),
    "step": ("type", "amplitude", "at", "initial"),
    "sine": ("type", "amplitude", "frequency", "offset", "phase"),
    "chirp": ("type", "amplitude", "f0", "f1", "sweep"),
    "csv": ("type", "file", "column"),
}
SOURCES = ("fmu", "coefficients", "design", "suggestion")


class _Doc:
    """A scenario file's tables with the file's name for messages."""

    def __init__(self, path: Path) -> None:
        self.path = path

    def where(self, key: str) -> str:
        return f"{self.path.name}: {key}"

    def table(self, doc: Mapping, key: str, keys: str | None = None, required: bool = False) -> dict:
        value = doc.get(key.rpartition(".")[2])
        if value is None:
            if required:
                raise DesignerError(
                    f"{self.path.name} has no [{key}] table", "see the scenario format in the README"
                )
            return {}
        if not isinstance(value, dict):
            raise DesignerError(f"{self.where(key)} must be a table", "see the scenario format in the README")
        if keys is not None:
            check_keys(value, KEYS[keys], where=f"[{key}] of {self.path.name}")
        return value

    def number(self, table: Mapping, key: str, where: str, default: float | None = None) -> float | None:
        value = table.get(key, default)
        if value is None:
            return None
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise DesignerError(
                f"{self.where(where + key)} = {value!r} is not a number", "give a finite number"
            )
        return float(value)

    def required(self, table: Mapping, key: str, where: str) -> float:
        if key not in table:
            raise DesignerError(f"{self.where(where + key)} is missing", "give it a number")
        return self.number(table, key, where)

    def file(self, value: Any, key: str) -> Path:
        if not isinstance(value, str):
            raise DesignerError(f"{self.where(key)} must be a path", "give a file path as a string")
        p = Path(value)
        return p if p.is_absolute() else (self.path.parent / p).resolve()


def load(path: str | Path) -> Scenario:
    """Read and check a scenario file; every problem raises a DesignerError before anything runs.

    Raises:
        DesignerError: a missing or malformed file, an unknown key (with the closest valid one), a
            value of the wrong type or out of range, naming the file and the key.
    """
    path, doc = read_toml(path, what="scenario")
    d = _Doc(path)
    check_keys(doc, KEYS[""], where=path.name)
    sim = d.table(doc, "simulation", "simulation", required=True)
    outputs = d.table(doc, "outputs")
    check_keys(outputs, OUTPUTS, where=f"[outputs] of {path.name}")
    val = d.table(doc, "validation", "validation")
    steps = val.get("steps", [])
    if not isinstance(steps, list):
        raise DesignerError(f"{d.where('validation.steps')} must be a list of steps", "e.g. [1e-3, 5e-4]")
    common = dict(
        path=path,
        duration=d.required(sim, "duration", "simulation."),
        step=d.required(sim, "step", "simulation."),
        algorithm=sim.get("algorithm", "gauss-seidel"),
        integrator=sim.get("integrator", "euler"),
        outputs=outputs,
        validation_steps=tuple(d.number({"steps": s}, "steps", "validation.") for s in steps),
        validation_duration=d.number(val, "duration", "validation."),
    )
    if ("rig" in doc) == ("robot" in doc):
        raise DesignerError(f"{path.name} needs exactly one of [robot] or [rig]", "see the README")
    try:
        return (_rig(doc, d, common) if "rig" in doc else _robot(doc, d, common)).check()
    except DesignerError as exc:
        if exc.problem.startswith(path.name):
            raise
        raise DesignerError(f"{path.name}: {exc.problem}", exc.fix) from None


def _rig(doc: Mapping, d: _Doc, common: dict) -> Scenario:
    rig = d.table(doc, "rig", "rig")
    base = Chirp()
    hub = Chirp(*(d.number(rig, k, "rig.", getattr(base, k)) for k in ("amplitude", "f0", "f1", "sweep")))
    return Scenario(
        rig_joint=_joint_source(rig.get("joint"), "rig.joint", d, "joint_rig"),
        hub=hub,
        factors=rig.get("factors"),
        **common,
    )


def _robot(doc: Mapping, d: _Doc, common: dict) -> Scenario:
    robot = d.table(doc, "robot", "robot")
    model = robot.get("model", "arm")
    joints_doc = d.table(doc, "joints", required=True)
    if not joints_doc:
        raise DesignerError(f"{d.path.name} maps no joint", "add a [joints.NAME] table per flexible joint")
    joints, motors = {}, {}
    for name, spec in joints_doc.items():
        key = f"joints.{name}"
        joints[name] = _joint_source(spec, key, d, f"joint_{name}")
        motors[name] = _reference(
            spec.get("reference", {"type": "step", "amplitude": 0.0}), f"{key}.reference", d
        )
    lengths = robot.get("lengths", list(ARM_LENGTHS))
    masses = robot.get("masses", list(ARM_MASSES))
    for key, value in (("lengths", lengths), ("masses", masses)):
        if not isinstance(value, list):
            raise DesignerError(f"{d.where('robot.' + key)} must be a list of numbers", "e.g. [0.08, 0.06]")
    return Scenario(
        model=None if model == "arm" else d.file(model, "robot.model"),
        lengths=tuple(d.number({"lengths": x}, "lengths", "robot.") for x in lengths),
        masses=tuple(d.number({"masses": x}, "masses", "robot.") for x in masses),
        joints=joints,
        motors=motors,
        **common,
    )


def _reference(spec: Any, key: str, d: _Doc) -> Reference:
    if not isinstance(spec, dict) or spec.get("type") not in ("step", "sine", "chirp", "csv"):
        raise DesignerError(
            f"{d.where(key)} must be a table with a type of step, sine, chirp or csv",
            'e.g. {type = "sine", amplitude = 0.5, frequency = 1}',
        )
    kind = spec["type"]
    check_keys(spec, KEYS[kind], where=f"{key} ({kind}) of {d.path.name}")
    if kind == "csv":
        return Trajectory.from_csv(d.file(spec.get("file"), f"{key}.file"), spec.get("column", "q"))
    cls = {"step": Step, "sine": Sine, "chirp": Chirp}[kind]
    values = {k: d.number(spec, k, key + ".") for k in KEYS[kind][1:] if k in spec}
    if kind in ("step", "sine") and "amplitude" not in values:
        raise DesignerError(
            f"{d.where(key + '.amplitude')} is missing", "give the amplitude in rad (m for a slide)"
        )
    if kind == "sine" and not values.get("frequency", 0) > 0:
        raise DesignerError(f"{d.where(key + '.frequency')} must be positive", "give the frequency in Hz")
    return cls(**values)


def _joint_source(spec: Any, key: str, d: _Doc, name: str) -> JointSource:
    if not isinstance(spec, dict):
        raise DesignerError(f"{d.where(key)} must be a table", "see the scenario format in the README")
    check_keys(spec, KEYS["joint"], where=f"[{key}] of {d.path.name}")
    axis = spec.get("axis", "theta")
    if not isinstance(axis, str):
        raise DesignerError(f"{d.where(key)}.axis = {axis!r} is not an axis name", 'give e.g. axis = "theta"')
    has = [k for k in SOURCES if k in spec]
    if len(has) != 1:
        raise DesignerError(
            f"{d.where(key)} needs exactly one of {', '.join(SOURCES)}", f"it has: {', '.join(has) or 'none'}"
        )
    candidate = spec.get("candidate", 1)
    if "candidate" in spec and "suggestion" not in spec:
        raise DesignerError(f"{d.where(key)}.candidate needs a suggestion", 'add suggestion = "s.json"')
    if isinstance(candidate, bool) or not isinstance(candidate, int):
        raise DesignerError(f"{d.where(key)}.candidate = {candidate!r} is not a whole number", "1 = best")
    params = spec.get("parameters", {})
    if isinstance(params, str):  # an SSV parameter set (SSP), units converted to SI
        from ..export.ssp import read_ssv

        params = read_ssv(d.file(params, f"{key}.parameters"))
    if not isinstance(params, dict):
        raise DesignerError(
            f"{d.where(key)}.parameters must be a table or an SSV file", 'e.g. {"theta.k" = 0.3} or "j1.ssv"'
        )
    keep_host = spec.get("keep_host", False)
    if not isinstance(keep_host, bool):
        raise DesignerError(
            f"{d.where(key)}.keep_host = {keep_host!r} is not true or false", "give keep_host = true"
        )
    common = dict(axis=axis, fmi_version=spec.get("fmi_version", 2), parameters=params, keep_host=keep_host)
    if "fmu" in spec:
        return JointSource(fmu=d.file(spec["fmu"], f"{key}.fmu"), **common)
    for table in ("coefficients", "design"):
        if table in spec and not isinstance(spec[table], dict):
            raise DesignerError(
                f"{d.where(key)}.{table} must be a table", "see the scenario format in the README"
            )
    joint = from_one_source(
        coefficients={axis: spec["coefficients"]} if "coefficients" in spec else None,
        design=spec.get("design"),
        suggestion=d.file(spec["suggestion"], f"{key}.suggestion") if "suggestion" in spec else None,
        candidate=candidate,
        axes=None if "coefficients" in spec else [axis],
        name=name,
    )
    return JointSource(joint=joint, **common)
