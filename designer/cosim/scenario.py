"""Scenario files (TOML): parsed and checked completely before anything runs.

A scenario is either a robot (`[robot]` and `[joints.NAME]`) or the virtual rig (`[rig]`); both
take `[simulation]`, `[outputs]` and `[validation]`. The README documents every key.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

if sys.version_info >= (3, 11):
    import tomllib
else:
    import tomli as tomllib

from .. import units
from ..errors import DesignerError
from ..joint import Joint
from .master import ALGORITHMS
from .references import Chirp, Reference, Sine, Step, Trajectory
from .robot import ARM_LENGTHS, ARM_MASSES, INTEGRATORS

FMI_VERSIONS = (2, 3)


@dataclass(frozen=True)
class JointSource:
    """Where a joint FMU comes from: a file, or a joint (coefficients, design, suggestion) to export."""

    axis: str
    fmu: Path | None = None
    joint: Joint | None = None
    fmi_version: int = 2
    parameters: dict[str, float] = field(default_factory=dict)


@dataclass(frozen=True)
class Scenario:
    """A checked scenario: kind "robot" or "rig", times in s, paths absolute."""

    path: Path
    kind: str
    duration: float
    step: float
    algorithm: str = "gauss-seidel"
    integrator: str = "euler"
    #: robot: the model file (None: the built-in planar arm) and the arm's links
    model: Path | None = None
    lengths: tuple[float, ...] = ARM_LENGTHS
    masses: tuple[float, ...] = ARM_MASSES
    #: robot: per robot joint, its FMU source and its motor reference
    joints: dict[str, JointSource] = field(default_factory=dict)
    motors: dict[str, Reference] = field(default_factory=dict)
    #: rig: the joint, its hub motion and the specimen's factors for the log's sidecar
    rig_joint: JointSource | None = None
    hub: Chirp | None = None
    factors: dict[str, float] | None = None
    outputs: dict[str, bool] = field(default_factory=lambda: {"csv": True, "parquet": True, "plot": True})
    #: macro steps of the validation, s, and the span it covers
    validation_steps: tuple[float, ...] = ()
    validation_duration: float = 0.0


def _where(path: Path, key: str) -> str:
    return f"{path.name}: {key}"


def _table(doc: dict, key: str, path: Path, required: bool = False) -> dict:
    value = doc.get(key, {} if not required else None)
    if value is None:
        raise DesignerError(f"{path.name} has no [{key}] table", "see the scenario format in the README")
    if not isinstance(value, dict):
        raise DesignerError(f"{_where(path, key)} must be a table", "see the scenario format in the README")
    return value


def _number(table: dict, key: str, path: Path, default: float | None = None, positive: bool = True) -> float:
    value = table.get(key, default)
    if value is None:
        raise DesignerError(f"{_where(path, key)} is missing", "give it a number")
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise DesignerError(f"{_where(path, key)} = {value!r} is not a number", "give a finite number")
    if positive and value <= 0:
        raise DesignerError(f"{_where(path, key)} = {value:g} must be positive", "give a positive number")
    return float(value)


def _choice(table: dict, key: str, options: tuple, path: Path, default):
    value = table.get(key, default)
    if value not in options:
        raise DesignerError(
            f"{_where(path, key)} = {value!r} is not allowed", f"use one of: {', '.join(map(str, options))}"
        )
    return value


def _file(value: Any, key: str, path: Path) -> Path:
    if not isinstance(value, str):
        raise DesignerError(f"{_where(path, key)} must be a path", "give a file path as a string")
    p = Path(value)
    return p if p.is_absolute() else (path.parent / p).resolve()


def _reference(spec: Any, key: str, path: Path) -> Reference:
    if not isinstance(spec, dict) or "type" not in spec:
        raise DesignerError(
            f"{_where(path, key)} must be a table with a type",
            'e.g. {type = "sine", amplitude = 0.5, frequency = 1}',
        )
    kind = spec["type"]
    if kind == "step":
        return Step(
            _number(spec, "amplitude", path, positive=False),
            _number(spec, "at", path, 0.0, positive=False),
            _number(spec, "initial", path, 0.0, positive=False),
        )
    if kind == "sine":
        return Sine(
            _number(spec, "amplitude", path, positive=False),
            _number(spec, "frequency", path),
            _number(spec, "offset", path, 0.0, positive=False),
            _number(spec, "phase", path, 0.0, positive=False),
        )
    if kind == "chirp":
        return _chirp(spec, path)
    if kind == "csv":
        return Trajectory.from_csv(_file(spec.get("file"), f"{key}.file", path), spec.get("column", "q"))
    raise DesignerError(
        f"{_where(path, key)}: unknown reference type {kind!r}", "use step, sine, chirp or csv"
    )


def _chirp(spec: dict, path: Path) -> Chirp:
    base = Chirp()
    return Chirp(
        _number(spec, "amplitude", path, base.amplitude),
        _number(spec, "f0", path, base.f0),
        _number(spec, "f1", path, base.f1),
        _number(spec, "sweep", path, base.sweep),
    )


SOURCES = ("fmu", "coefficients", "design", "suggestion")


def _joint_source(spec: Any, key: str, path: Path, default_axis: str, name: str) -> JointSource:
    if not isinstance(spec, dict):
        raise DesignerError(f"{_where(path, key)} must be a table", "see the scenario format in the README")
    axis = units.check_axis(spec.get("axis", default_axis))
    version = _choice(spec, "fmi_version", FMI_VERSIONS, path, 2)
    params = spec.get("parameters", {})
    if not isinstance(params, dict):
        raise DesignerError(f"{_where(path, key)}.parameters must be a table", 'e.g. {"theta.k" = 0.3}')
    has = [k for k in SOURCES if k in spec]
    if len(has) != 1:
        raise DesignerError(
            f"{_where(path, key)} needs exactly one of {', '.join(SOURCES)}",
            f"it has: {', '.join(has) or 'none'}",
        )
    if "candidate" in spec and "suggestion" not in spec:
        raise DesignerError(f"{_where(path, key)}.candidate needs a suggestion", 'add suggestion = "s.json"')
    if "fmu" in spec:
        fmu = _file(spec["fmu"], f"{key}.fmu", path)
        from .fmu import check_fmu

        check_fmu(fmu, [axis])
        return JointSource(axis=axis, fmu=fmu, fmi_version=version, parameters=params)
    joint = _joint(spec, key, path, axis, name)
    return JointSource(axis=axis, joint=joint, fmi_version=version, parameters=params)


def _joint(spec: dict, key: str, path: Path, axis: str, name: str) -> Joint:
    """The joint of a coefficients, design (through the default surrogate) or suggestion source."""
    if "suggestion" in spec:
        candidate = spec.get("candidate", 1)
        if isinstance(candidate, bool) or not isinstance(candidate, int):
            raise DesignerError(
                f"{_where(path, key)}.candidate = {candidate!r} is not a whole number", "1 = best"
            )
        return Joint.from_suggestion(
            _file(spec["suggestion"], f"{key}.suggestion", path), candidate=candidate, axes=[axis], name=name
        )
    if "design" in spec:
        design = spec["design"]
        if not isinstance(design, dict):
            raise DesignerError(
                f"{_where(path, key)}.design must be a table of the six print settings",
                "e.g. {density = 60, length = 24, width = 4.5, height = 9, layer = 0.16, raster = 45}",
            )
        return Joint.from_design(design, axes=[axis], name=name)
    coef = spec["coefficients"]
    if not isinstance(coef, dict) or not {"k", "c"} <= set(coef):
        raise DesignerError(
            f"{_where(path, key)}.coefficients needs k and c (rig units)", "e.g. {k = 300, c = 0.8, m = 2e-6}"
        )
    coef = {q: _number(coef, q, path, positive=q != "c") for q in coef}
    return Joint.from_coefficients({axis: coef}, name=name)


def load(path: str | Path) -> Scenario:
    """Read and check a scenario file; every problem raises a DesignerError before anything runs."""
    path = Path(path).resolve()
    if not path.is_file():
        raise DesignerError(f"scenario {path} does not exist", "give the path of a .toml scenario file")
    try:
        doc = tomllib.loads(path.read_text())
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise DesignerError(f"{path.name} is not valid TOML: {exc}", "fix the syntax") from None
    sim = _table(doc, "simulation", path, required=True)
    step = _number(sim, "step", path)
    duration = _number(sim, "duration", path)
    if duration < step:
        raise DesignerError(f"duration {duration:g} s is shorter than the step {step:g} s", "lengthen it")
    out = {k: True for k in ("csv", "parquet", "plot")}
    for k, v in _table(doc, "outputs", path).items():
        if k not in out or not isinstance(v, bool):
            raise DesignerError(
                f"{_where(path, 'outputs.' + k)} is not an output switch",
                "use csv, parquet, plot = true|false",
            )
        out[k] = v
    val = _table(doc, "validation", path)
    steps = val.get("steps", [step / 2**i for i in range(4)])
    if not isinstance(steps, list) or len(steps) < 2:
        raise DesignerError(
            f"{_where(path, 'validation.steps')} must list at least two steps", "e.g. [1e-3, 5e-4]"
        )
    steps = tuple(_number({"step": s}, "step", path) for s in steps)
    common = dict(
        path=path,
        duration=duration,
        step=step,
        algorithm=_choice(sim, "algorithm", ALGORITHMS, path, "gauss-seidel"),
        integrator=_choice(sim, "integrator", INTEGRATORS, path, "euler"),
        outputs=out,
        validation_steps=steps,
        validation_duration=min(_number(val, "duration", path, duration), duration),
    )
    if ("rig" in doc) == ("robot" in doc):
        raise DesignerError(f"{path.name} needs exactly one of [robot] or [rig]", "see the README")
    if "rig" in doc:
        rig = _table(doc, "rig", path)
        factors = rig.get("factors")
        if factors is not None:
            from .. import space

            factors = space.validate(factors)
        return Scenario(
            kind="rig",
            rig_joint=_joint_source(rig.get("joint"), "rig.joint", path, "theta", "joint_rig"),
            hub=_chirp(rig, path),
            factors=factors,
            **common,
        )
    return _robot(doc, path, common)


def _robot(doc: dict, path: Path, common: dict) -> Scenario:
    from .robot import check_joints, load_spec

    robot = _table(doc, "robot", path)
    model = robot.get("model", "arm")
    model_path = None if model == "arm" else _file(model, "robot.model", path)
    lengths = tuple(robot.get("lengths", ARM_LENGTHS))
    masses = tuple(robot.get("masses", ARM_MASSES))
    spec = load_spec(model_path, lengths, masses)
    joints_doc = _table(doc, "joints", path, required=True)
    if not joints_doc:
        raise DesignerError(f"{path.name} maps no joint", "add a [joints.NAME] table per flexible joint")
    check_joints(spec, list(joints_doc))
    joints, motors = {}, {}
    for name, spec_j in joints_doc.items():
        joints[name] = _joint_source(spec_j, f"joints.{name}", path, "theta", f"joint_{name}")
        motors[name] = _reference(
            spec_j.get("reference", {"type": "step", "amplitude": 0.0}), f"joints.{name}.reference", path
        )
    return Scenario(
        kind="robot", model=model_path, lengths=lengths, masses=masses, joints=joints, motors=motors, **common
    )
