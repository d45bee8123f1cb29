"""The scenario file loader: read a TOML scenario, decide its type from its tables ([robot] or [rig]),
build that type and check it.

`load(path)` checks the file's keys and types and names the file and key of the first problem; the
README documents every key. This is the one place that decides a file's scenario type.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ..errors import DesignerError
from ..joint import from_one_source
from ..keys import check_keys, read_toml
from .references import Chirp, Reference, Sine, Step, Trajectory
from .rig_scenario import RigScenario
from .robot import ARM_LENGTHS, ARM_MASSES
from .robot_scenario import RobotScenario
from .scenario import OUTPUTS, JointSource, Scenario

#: keys of each table of a scenario file
KEYS = {
    "": ("simulation", "robot", "joints", "rig", "outputs", "validation"),
    "simulation": ("duration", "step", "algorithm", "integrator"),
    "robot": ("model", "lengths", "masses", "package_paths"),
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
        integrator=sim.get("integrator"),
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


def _rig(doc: Mapping, d: _Doc, common: dict) -> RigScenario:
    rig = d.table(doc, "rig", "rig")
    base = Chirp()
    hub = Chirp(*(d.number(rig, k, "rig.", getattr(base, k)) for k in ("amplitude", "f0", "f1", "sweep")))
    return RigScenario(
        rig_joint=_joint_source(rig.get("joint"), "rig.joint", d, "joint_rig"),
        hub=hub,
        factors=rig.get("factors"),
        **common,
    )


def _robot(doc: Mapping, d: _Doc, common: dict) -> RobotScenario:
    robot = d.table(doc, "robot", "robot")
    model = robot.get("model", "arm")
    joints_doc = d.table(doc, "joints", required=True)
    if not joints_doc:
        raise DesignerError(f"{d.path.name} maps no joint", "add a [joints.NAME] table per flexible joint")
    joints, motors = {}, {}
    for name, spec in joints_doc.items():
        key = f"joints.{name}"
        # the FMU's model name: robot joint names may hold what an identifier cannot ('robot:joint4')
        joints[name] = _joint_source(spec, key, d, "joint_" + re.sub(r"\W", "_", name))
        motors[name] = _reference(
            spec.get("reference", {"type": "step", "amplitude": 0.0}), f"{key}.reference", d
        )
    lengths = robot.get("lengths", list(ARM_LENGTHS))
    masses = robot.get("masses", list(ARM_MASSES))
    for key, value in (("lengths", lengths), ("masses", masses)):
        if not isinstance(value, list):
            raise DesignerError(f"{d.where('robot.' + key)} must be a list of numbers", "e.g. [0.08, 0.06]")
    packages = robot.get("package_paths", {})
    if not isinstance(packages, dict):
        raise DesignerError(
            f"{d.where('robot.package_paths')} must be a table",
            'e.g. package_paths = { my_robot = "../my_robot" }',
        )
    return RobotScenario(
        model=None if model == "arm" else d.file(model, "robot.model"),
        package_paths={
            name: d.file(folder, f"robot.package_paths.{name}") for name, folder in packages.items()
        },
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
