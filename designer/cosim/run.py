"""Run a checked scenario: build the systems, co-simulate, compute metrics, validate, write results."""

from __future__ import annotations

import contextlib
import json
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
import pandas as pd

from .. import units
from ..errors import DesignerError
from ..files import atomic_path, atomic_write
from .fmu import FmuSystem, read_parameters
from .kernel import run_master
from .master import Master, Result
from .metrics import joint_metrics
from .robot import Robot, SpringDamper, load_spec
from .scenario import JointSource, Scenario

Progress = Callable[[float], None] | None


@contextlib.contextmanager
def joint_fmus(sc: Scenario) -> Iterator[dict[str, Path]]:
    """The FMU file of every joint (key "rig" for the rig), exporting the others into a temporary folder."""
    sources = {"rig": sc.rig_joint} if sc.kind == "rig" else sc.joints
    with tempfile.TemporaryDirectory(prefix="designer-cosim-") as tmp:
        paths = {}
        for name, src in sources.items():
            if src.fmu is not None:
                paths[name] = src.fmu
                continue
            from ..export.fmu import export_fmu

            interface = "body" if sc.kind == "rig" else "force"
            paths[name] = export_fmu(
                src.joint, Path(tmp) / f"{name}.fmu", fmi_version=src.fmi_version, interface=interface
            )
        yield paths


def law(src: JointSource, path: Path) -> dict[str, float]:
    """The SI parameters m, c, k, offset the joint's FMU runs with (start values, then overrides)."""
    params = read_parameters(path, src.axis)
    for key, value in src.parameters.items():
        axis, _, q = key.partition(".")
        if axis == src.axis:
            params[q] = float(value)
    params.setdefault("offset", 0.0)
    return params


def robot_run(
    sc: Scenario,
    fmus: dict[str, Path],
    step: float,
    duration: float,
    algorithm: str,
    progress: Progress = None,
    engine: str = "auto",
) -> Result:
    """The robot co-simulated with its joint FMUs, by `engine` (see kernel.run_master)."""
    robot = Robot(load_spec(sc.model, sc.lengths, sc.masses), sc.motors, step, sc.integrator)
    systems: dict = {"robot": robot}
    connections = []
    try:
        for name, src in sc.joints.items():
            systems[name] = FmuSystem(fmus[name], [src.axis], name=name, parameters=src.parameters)
            if systems[name].interface != "force":
                raise DesignerError(
                    f"the FMU of joint {name} has the body interface", "export it with --interface force"
                )
            a = src.axis
            connections += [
                (f"robot.{name}.s", f"{name}.{a}.s"),
                (f"robot.{name}.v", f"{name}.{a}.v"),
                (f"{name}.{a}.f", f"robot.{name}.tau"),
            ]
        master = Master(systems, connections, algorithm)
        return run_master(master, duration, step, progress=progress, engine=engine)
    finally:
        for s in systems.values():
            if isinstance(s, FmuSystem):
                s.close()


def robot_reference(sc: Scenario, laws: dict, step: float, duration: float, integrator: str) -> Result:
    """The same robot with every joint's spring-damper computed inside MuJoCo."""
    springs = {j: SpringDamper(p["k"], p["c"], p["offset"]) for j, p in laws.items()}
    robot = Robot(load_spec(sc.model, sc.lengths, sc.masses), sc.motors, step, integrator, in_engine=springs)
    return Master({"robot": robot}, []).run(duration, step)


def rig_run(
    sc: Scenario, fmu: Path, params: dict, step: float, duration: float, progress: Progress = None
) -> Result:
    """The hub servo driving the joint FMU's body interface."""
    from .rig import HubServo, check_stable, servo_gains

    check_stable(params["m"], params["c"], params["k"], step)
    a = sc.rig_joint.axis
    joint = FmuSystem(fmu, [a], name="joint", parameters=sc.rig_joint.parameters)
    try:
        if joint.interface != "body":
            raise DesignerError("the rig's FMU has the force interface", "export it with --interface body")
        hub = HubServo(sc.hub, *servo_gains(params["m"], params["c"], params["k"]))
        connections = [(f"joint.{a}.s", "hub.s"), (f"joint.{a}.v", "hub.v"), ("hub.f", f"joint.{a}.f")]
        return Master({"joint": joint, "hub": hub}, connections, sc.algorithm).run(duration, step, progress)
    finally:
        joint.close()


def _angles(res: Result, joints) -> np.ndarray:
    return np.column_stack([res.column(f"robot.{j}.q") for j in joints])


def validate(sc: Scenario, fmus: dict[str, Path], laws: dict, progress: Progress = None) -> dict:
    """Error against the reference at the scenario's step and at each validation step (joint angle, SI)."""
    duration = sc.validation_duration
    steps = sorted(sc.validation_steps, reverse=True)
    rows = []
    if sc.kind == "rig":
        from .rig import reference

        p = laws["rig"]
        for i, h in enumerate([sc.step, *steps]):
            res = rig_run(sc, fmus["rig"], p, h, duration)
            s = res.column(f"joint.{sc.rig_joint.axis}.s")
            rows.append(
                {
                    "step": h,
                    "max_error": float(
                        np.max(np.abs(s - reference(p["m"], p["c"], p["k"], sc.hub, res.time)))
                    ),
                }
            )
            if progress is not None:
                progress((i + 1) / (len(steps) + 1))
        return {
            "reference": "monolithic scipy DOP853, rtol 1e-11",
            "max_error": rows[0]["max_error"],
            "steps": rows[1:],
        }
    joints = list(sc.joints)
    fine = min(steps) / 4
    ref_fine = robot_reference(sc, laws, fine, duration, "rk4")
    same = _angles(robot_run(sc, fmus, sc.step, duration, sc.algorithm), joints)
    same_ref = _angles(robot_reference(sc, laws, sc.step, duration, sc.integrator), joints)
    for i, h in enumerate(steps):
        ratio = int(round(h / fine))
        if abs(ratio * fine - h) > 1e-9 * h:
            raise DesignerError(
                f"validation step {h:g} s is not a multiple of {fine:g} s",
                "use steps halving from the largest",
            )
        q = _angles(robot_run(sc, fmus, h, duration, sc.algorithm), joints)
        q_same = _angles(robot_reference(sc, laws, h, duration, sc.integrator), joints)
        rows.append(
            {
                "step": h,
                "max_error": float(np.max(np.abs(q - _angles(ref_fine, joints)[::ratio]))),
                "max_error_same_step": float(np.max(np.abs(q - q_same))),
            }
        )
        if progress is not None:
            progress((i + 1) / len(steps))
    return {
        "reference": f"in-engine MuJoCo general actuator; steps against RK4 at {fine:g} s",
        "max_error": float(np.max(np.abs(same - same_ref))),
        "steps": rows,
    }


def robot_metrics(sc: Scenario, res: Result, laws: dict) -> dict:
    return {
        j: joint_metrics(
            res.time,
            res.column(f"robot.{j}.q"),
            res.column(f"robot.{j}.motor"),
            res.column(f"robot.{j}.v"),
            laws[j]["c"],
            sc.motors[j],
        )
        for j in sc.joints
    }


def rig_log(sc: Scenario, res: Result) -> pd.DataFrame:
    """The run as a rig log: t, the axis' coordinate and load in rig units, the hub angle.

    The load is held over each step, so the sensor's sample at t_n is the mean of the loads held
    either side of it: read at one edge, the log would look half a step late (extra damping k h / 2).
    """
    from ..rig.logs import LOAD

    a = sc.rig_joint.axis
    held = res.column("hub.f")
    sensed = np.concatenate([held[:1], 0.5 * (held[1:] + held[:-1])])
    return pd.DataFrame(
        {
            "t": res.time,
            a: units.from_si("r", a, res.column(f"joint.{a}.s")),
            LOAD[a]: units.from_si("F", a, sensed),
            "hub": res.column("hub.q"),
        }
    )


def rig_metrics(sc: Scenario, res: Result, params: dict) -> dict:
    a = sc.rig_joint.axis
    s, q = res.column(f"joint.{a}.s"), res.column("hub.q")
    return {
        "rig": {
            "axis": a,
            "tracking_rms": float(np.sqrt(np.mean((q - s) ** 2))),
            "peak_load": float(units.from_si("F", a, np.max(np.abs(res.column("hub.f"))))),
            "peak_load_unit": units.rig_unit("F", a),
            "coefficients_si": params,
        }
    }


def write_outputs(sc: Scenario, out: Path, frame: pd.DataFrame, summary: dict) -> list[Path]:
    """Write the time series, metrics and plot into `out`, each file atomically."""
    out.mkdir(parents=True, exist_ok=True)
    written = []
    if sc.outputs["csv"]:
        with atomic_write(out / "timeseries.csv") as fh:
            frame.to_csv(fh, index=False)
        written.append(out / "timeseries.csv")
    if sc.outputs["parquet"]:
        with atomic_path(out / "timeseries.parquet") as tmp:
            frame.to_parquet(tmp, index=False)
        written.append(out / "timeseries.parquet")
    with atomic_write(out / "metrics.json") as fh:
        json.dump(summary, fh, indent=2, default=float)
    written.append(out / "metrics.json")
    if sc.outputs["plot"]:
        written.append(plot(frame, out / "plot.png"))
    return written


def plot(frame: pd.DataFrame, path: Path) -> Path:
    """Angles (or coordinate and hub) and loads against time, one panel each."""
    from ..plots.timeseries import plot_timeseries

    angles = [c for c in frame.columns if c.endswith((".q", ".motor", ".s"))]
    loads = [c for c in frame.columns if c.endswith((".f", ".tau"))]
    panels = {"angle [rad] / coordinate [SI]": angles, "torque [N.m] / force [N]": loads}
    return plot_timeseries(frame, path, panels={label: cols for label, cols in panels.items() if cols})


def simulate(sc: Scenario, out: Path, with_validation: bool = False, progress: Progress = None) -> dict:
    """Run a scenario into the folder `out`; returns {"metrics", "files"[, "validation"]}."""
    share = 0.5 if with_validation else 1.0

    def part(offset: float, scale: float) -> Progress:
        return None if progress is None else (lambda f: progress(offset + scale * f))

    with joint_fmus(sc) as fmus:
        if sc.kind == "rig":
            laws = {"rig": law(sc.rig_joint, fmus["rig"])}
            res = rig_run(sc, fmus["rig"], laws["rig"], sc.step, sc.duration, part(0.0, share))
            metrics = rig_metrics(sc, res, laws["rig"])
        else:
            laws = {j: law(src, fmus[j]) for j, src in sc.joints.items()}
            res = robot_run(sc, fmus, sc.step, sc.duration, sc.algorithm, part(0.0, share))
            metrics = robot_metrics(sc, res, laws)
        summary = {"scenario": str(sc.path), "kind": sc.kind, "step": sc.step, "metrics": metrics}
        if res.delays:
            summary["delays"] = list(res.delays)
        if with_validation:
            summary["validation"] = validate(sc, fmus, laws, part(share, 1.0 - share))
    frame = pd.DataFrame(res.values, columns=res.columns)
    frame.insert(0, "t", res.time)
    files = write_outputs(sc, out, frame, summary)
    if sc.kind == "rig":
        from ..rig.logs import write_log

        files.append(write_log(rig_log(sc, res), out / "rig_log.csv", sc.factors))
    summary["files"] = [str(f) for f in files]
    return summary
