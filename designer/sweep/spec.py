"""Sweep specifications (TOML): the scenario, where the cases come from, how they run, the task limits.

Parsed and checked completely before anything runs; every problem is a DesignerError naming the key.
The README documents every key; `examples/sweep_arm.toml` is a commented example.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..cosim.rig_scenario import RigScenario
from ..cosim.robot_scenario import RobotScenario
from ..cosim.scenario import Scenario
from ..errors import DesignerError, check_type
from ..keys import check_keys, read_toml
from .limits import Limit, parse_limit

CASE_TYPES = ("grid", "suggestion", "montecarlo")
#: the [cases] keys each type reads (`type` itself aside): another type's key is refused, not ignored
CASE_KEYS = {
    "grid": ("joints", "designs"),
    "suggestion": ("joints", "file", "candidates"),
    "montecarlo": ("joints", "designs", "n", "seed"),
}
PATHS = ("fmu", "engine")


@dataclass(frozen=True)
class Cases:
    """Where the cases come from: `type` (grid | suggestion | montecarlo) and its options.

    grid: `joints` maps a joint to {key: values}, keys k and c (rig units on the joint's axis) or
    print settings (the others from the joint's design), values a list of numbers.
    suggestion: `file` (a `designer suggest --json` output), `joints`, `candidates` (1-based).
    montecarlo: `n` draws seeded by `seed` for `joints`, around each joint's design (`designs`
    overrides the scenario's).
    """

    type: str
    joints: dict[str, Any] = field(default_factory=dict)
    n: int = 0
    seed: int = 0
    file: Path | None = None
    candidates: tuple[int, ...] = ()
    designs: dict[str, dict[str, float]] = field(default_factory=dict)


@dataclass(frozen=True)
class Spec:
    """A checked sweep: the scenario, the cases, the evaluation path and the task limits.

    `path` "fmu" co-simulates every case with the joint FMUs; "engine" computes the linear
    spring-dampers inside MuJoCo in batches through `mujoco.rollout`, and re-runs `check` of the
    cases through the FMUs to compare. `workers` sets local processes; `cluster` the Dask cluster.
    """

    scenario: Scenario
    cases: Cases
    path: str = "fmu"
    check: int = 3
    limits: tuple[Limit, ...] = ()
    surrogate: Path | None = None
    workers: int | None = None
    batch: int | None = None
    cluster: dict[str, Any] = field(default_factory=dict)
    source: Path | None = None


def _where(path: Path, key: str) -> str:
    return f"{path.name}: {key}"


def _count(table: dict, key: str, path: Path, default: int | None, minimum: int = 1) -> int | None:
    value = table.get(key, default)
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int) or value < minimum:
        raise DesignerError(f"{_where(path, key)} = {value!r} is not a whole number >= {minimum}", "fix it")
    return value


def _values(spec: Any, key: str, path: Path) -> list[float]:
    """A grid axis: a list of numbers, or {from, to, n, scale = "linear" | "log"}."""
    if isinstance(spec, dict):
        try:
            lo, hi, n = float(spec["from"]), float(spec["to"]), int(spec["n"])
        except (KeyError, TypeError, ValueError):
            raise DesignerError(
                f"{_where(path, key)} must be a list or {{from, to, n}}", "e.g. {from = 100, to = 400, n = 5}"
            ) from None
        scale = spec.get("scale", "linear")
        if scale not in ("linear", "log") or n < 1 or (scale == "log" and min(lo, hi) <= 0):
            raise DesignerError(f"{_where(path, key)} is not a usable range", "n >= 1, log scales positive")
        points = np.geomspace(lo, hi, n) if scale == "log" else np.linspace(lo, hi, n)
        return [float(v) for v in points]
    if not isinstance(spec, list) or not spec:
        raise DesignerError(f"{_where(path, key)} must list values", "e.g. [100, 200, 300]")
    for v in spec:
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise DesignerError(f"{_where(path, key)} has {v!r}, not a finite number", "fix it")
    return [float(v) for v in spec]


def _cases(doc: dict, path: Path, scenario: Scenario) -> Cases:
    table = doc.get("cases")
    if not isinstance(table, dict) or table.get("type") not in CASE_TYPES:
        raise DesignerError(
            f"{path.name} needs a [cases] table with a type", f"type = one of {', '.join(CASE_TYPES)}"
        )
    kind = table["type"]  # CASE_TYPES are READERS' keys
    for key in table:
        if key != "type" and key not in CASE_KEYS[kind]:
            owners = " or ".join(f'"{t}"' for t in CASE_TYPES if key in CASE_KEYS[t])
            raise DesignerError(
                f'{_where(path, "cases." + key)} is read by type = {owners}, not by type = "{kind}"',
                f"remove {key} or change the type",
            )
    designs = table.get("designs", {})
    if not isinstance(designs, dict) or not all(isinstance(d, dict) for d in designs.values()):
        raise DesignerError(
            f"{_where(path, 'cases.designs')} must map joints to print settings", "see the README"
        )
    return READERS[kind](table, path, scenario, {j: dict(d) for j, d in designs.items()})


def _grid(table: dict, path: Path, scenario: Scenario, designs: dict) -> Cases:
    joints = table.get("joints")
    if not isinstance(joints, dict) or not joints:
        raise DesignerError(f"{_where(path, 'cases.joints')} must map joints to grid axes", "see the README")
    grid = {}
    for j, axes in joints.items():
        if not isinstance(axes, dict) or not axes:
            raise DesignerError(
                f"{_where(path, 'cases.joints.' + j)} must be a table of axes", "e.g. {k = [..]}"
            )
        grid[j] = {q: _values(v, f"cases.joints.{j}.{q}", path) for q, v in axes.items()}
    return Cases(type="grid", joints=grid, designs=designs)


def _joint_names(table: dict, path: Path, scenario: Scenario) -> dict[str, None]:
    """The joints a suggestion or Monte Carlo sweep varies (default: every joint of the scenario)."""
    joints = table.get("joints", list(scenario.sources()))
    if not isinstance(joints, list) or not all(isinstance(j, str) for j in joints):
        raise DesignerError(f"{_where(path, 'cases.joints')} must list joint names", 'e.g. ["j1", "j2"]')
    return dict.fromkeys(joints)


def _suggestion(table: dict, path: Path, scenario: Scenario, designs: dict) -> Cases:
    joints = _joint_names(table, path, scenario)
    if not isinstance(table.get("file"), str):
        raise DesignerError(f"{_where(path, 'cases.file')} is missing", 'give file = "suggestion.json"')
    file = (path.parent / table["file"]).resolve()
    cands = table.get("candidates", [])
    if not isinstance(cands, list) or not all(isinstance(c, int) and c >= 1 for c in cands):
        raise DesignerError(f"{_where(path, 'cases.candidates')} must list numbers >= 1", "e.g. [1, 2, 3]")
    return Cases(type="suggestion", joints=joints, file=file, candidates=tuple(cands))


def _montecarlo(table: dict, path: Path, scenario: Scenario, designs: dict) -> Cases:
    return Cases(
        type="montecarlo",
        joints=_joint_names(table, path, scenario),
        n=_count(table, "n", path, None),
        seed=_count(table, "seed", path, 0, minimum=0),
        designs=designs,
    )


#: the reader of each type of [cases] table (what it holds besides `type` and `designs`: CASE_KEYS)
READERS: dict[str, Callable[[dict, Path, Scenario, dict], Cases]] = {
    "grid": _grid,
    "suggestion": _suggestion,
    "montecarlo": _montecarlo,
}


def _cluster(doc: dict, path: Path) -> dict[str, Any]:
    cluster = doc.get("cluster", {})
    if not isinstance(cluster, dict):
        raise DesignerError(f"{_where(path, 'cluster')} must be a table", "see the README")
    chosen = [k for k in ("scheduler", "workers", "slurm") if k in cluster]
    if len(chosen) > 1:
        raise DesignerError(f"{_where(path, 'cluster')} sets {', '.join(chosen)}", "give one of them")
    if "workers" in cluster:
        _count(cluster, "workers", path, None)
    if "slurm" in cluster and not isinstance(cluster["slurm"], dict):
        raise DesignerError(
            f"{_where(path, 'cluster.slurm')} must be a table", "e.g. {cores = 4, memory = '8GB'}"
        )
    return dict(cluster)


def load(path: str | Path) -> Spec:
    """Read and check a sweep file and its scenario; every problem raises a DesignerError."""
    from .. import cosim

    path, doc = read_toml(path, what="sweep")
    _check_sweep_keys(doc, path)
    if not isinstance(doc.get("scenario"), str):
        raise DesignerError(f"{path.name} names no scenario", 'add scenario = "arm.toml" at the top')
    scenario = cosim.load((path.parent / doc["scenario"]).resolve())
    sweep = doc.get("sweep", {})
    if not isinstance(sweep, dict):
        raise DesignerError(f"{_where(path, 'sweep')} must be a table", "see the README")
    if "duration" in sweep:
        scenario = with_duration(scenario, sweep["duration"])
    mode = sweep.get("path", "fmu")
    if mode not in PATHS:
        raise DesignerError(f"{_where(path, 'sweep.path')} = {mode!r} is not allowed", "use fmu or engine")
    limits = sweep.get("limits", [])
    if not isinstance(limits, list):
        raise DesignerError(f"{_where(path, 'sweep.limits')} must list limits", 'e.g. ["overshoot<=5%"]')
    surrogate = sweep.get("surrogate")
    spec = Spec(
        scenario=scenario,
        cases=_cases(doc, path, scenario),
        path=mode,
        check=_count(sweep, "check", path, 3, minimum=0),
        limits=tuple(parse_limit(x) for x in limits),
        surrogate=None if surrogate is None else (path.parent / str(surrogate)).resolve(),
        workers=_count(sweep, "workers", path, None),
        batch=_count(sweep, "batch", path, None),
        cluster=_cluster(doc, path),
        source=path,
    )
    return check(spec)


#: the keys a sweep file may have, per table (a misspelt one, e.g. `limts`, was ignored silently)
SWEEP_KEYS = {
    "": ("scenario", "sweep", "cases", "cluster"),
    "sweep": ("path", "check", "duration", "limits", "surrogate", "workers", "batch"),
    "cases": ("type", "joints", "designs", "n", "seed", "file", "candidates"),
    "cluster": ("scheduler", "workers", "slurm"),
}


def _check_sweep_keys(doc: dict, path: Path) -> None:
    """Raise for an unknown key (with the nearest valid one) in the file or one of its tables."""
    check_keys(doc, SWEEP_KEYS[""], where=path.name)
    for table in ("sweep", "cases", "cluster"):
        if isinstance(doc.get(table), dict):
            check_keys(doc[table], SWEEP_KEYS[table], where=f"[{table}] of {path.name}")


def with_duration(scenario: Scenario, duration: Any) -> Scenario:
    """The scenario run for another duration (s)."""
    if isinstance(duration, bool) or not isinstance(duration, (int, float)) or not duration >= scenario.step:
        raise DesignerError(f"duration {duration!r} is not at least one step", f"give >= {scenario.step:g} s")
    return dataclasses.replace(scenario, duration=float(duration))


def _rig_sweep(spec: Spec) -> None:
    """A rig sweep identifies each case's virtual rig log through the FMU: no engine path, no limits.

    Raises:
        DesignerError: the engine path or limits.
    """
    if spec.path != "fmu" or spec.limits:
        raise DesignerError(
            "a rig sweep identifies each case's virtual rig log through the FMU",
            "use path='fmu' and no limits with a rig scenario",
        )


#: the checks a sweep of each scenario type adds (a robot sweep takes either path and any limits)
TYPE_RULES: dict[type[Scenario], tuple[Callable[[Spec], None], ...]] = {
    RobotScenario: (),
    RigScenario: (_rig_sweep,),
}


def check(spec: Spec) -> Spec:
    """Check a spec built in code as `load` checks a file; returns it (a Monte Carlo or suggestion sweep
    without joints varies them all).

    Raises:
        DesignerError: a rig scenario with the engine path or limits, a case naming an unknown
            joint, or a Monte Carlo sweep without its count; a bad scenario (Scenario.check); `spec`
            not a Spec.
    """
    check_type(spec, Spec, "spec", expected="a sweep Spec", fix="read one with designer.sweep.load(path)")
    sc = spec.scenario if spec.scenario.checked else spec.scenario.check()
    spec = dataclasses.replace(spec, scenario=sc)
    for rule in TYPE_RULES[type(sc)]:
        rule(spec)
    if spec.path not in PATHS:
        raise DesignerError(f"path={spec.path!r} is not allowed", "use path='fmu' or path='engine'")
    if spec.cases.type not in CASE_TYPES:
        raise DesignerError(
            f"cases type {spec.cases.type!r} is unknown", f"use one of {', '.join(CASE_TYPES)}"
        )
    names = sc.sources()
    for rule in CASE_RULES[spec.cases.type]:
        rule(spec.cases)
    if not spec.cases.joints:
        spec = dataclasses.replace(spec, cases=dataclasses.replace(spec.cases, joints=dict.fromkeys(names)))
    for j in spec.cases.joints:
        if j not in names:
            raise DesignerError(
                f"the sweep varies joint '{j}' the scenario lacks", f"it has {', '.join(names)}"
            )
    return spec


def _grid_axes(cases: Cases) -> None:
    if not cases.joints:
        raise DesignerError("a grid sweep needs its axes", "give joints={'j1': {'k': [100, 200]}}")


def _draw_count(cases: Cases) -> None:
    if not cases.n:
        raise DesignerError("a Monte Carlo sweep needs a number of draws", "give n (e.g. n = 200)")


#: what `Cases` built in code must hold, by type, beyond the common checks (a suggestion sweep
#: without joints varies them all)
CASE_RULES: dict[str, tuple[Callable[[Cases], None], ...]] = {
    "grid": (_grid_axes,),
    "suggestion": (),
    "montecarlo": (_draw_count,),
}
