"""Run a scenario in memory (`run` -> `Result`); writing its files is a separate call (`write_outputs`).

A run exports the joints that are not FMU files into a temporary folder, co-simulates them with the
robot or the rig, computes the metrics and, when asked, compares with the reference solution.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .. import units
from ..errors import DesignerError, check_type, path_argument
from ..files import atomic_folder, atomic_path, atomic_write
from .kernel import run_master
from .master import Master, Trace
from .metrics import joint_metrics
from .robot import SpringDamper
from .scenario import Scenario
from .session import Session, prepare, robot_system

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.figure import Figure

Progress = Callable[[float], None] | None


@dataclass(frozen=True)
class Result:
    """One co-simulation, in memory.

    `time` has shape (n,) in s; `values` shape (n, len(columns)), columns `system.variable` in SI
    (`robot.j1.q` rad, `j1.theta.f` N.m, ...). `metrics` per joint (see README), `validation` when
    asked, `laws` the SI m, c, k, offset each joint FMU ran with, `notes` what the reader should know.
    """

    scenario: Scenario
    time: np.ndarray
    columns: list[str]
    values: np.ndarray
    metrics: dict[str, Any]
    laws: dict[str, dict[str, float]]
    validation: dict[str, Any] | None = None
    notes: tuple[str, ...] = field(default_factory=tuple)
    #: what ran the loop: "kernel" (compiled) or "python" (the reference master)
    engine: str = "python"

    def column(self, name: str) -> np.ndarray:
        """The signal `name`, shape (n,).

        Raises:
            DesignerError: no such column.
        """
        if name not in self.columns:
            raise DesignerError(f"the result has no column '{name}'", f"it has: {', '.join(self.columns)}")
        return self.values[:, self.columns.index(name)]

    def to_frame(self) -> pd.DataFrame:
        """The time series as a DataFrame: column `t` [s], then the signals in SI."""
        import pandas as pd

        frame = pd.DataFrame(self.values, columns=self.columns)
        frame.insert(0, "t", self.time)
        return frame

    def summary(self) -> dict[str, Any]:
        """Plain data for JSON: the scenario file, kind, step, metrics, validation and notes."""
        sc = self.scenario
        out = {
            "scenario": None if sc.path is None else str(sc.path),
            "kind": sc.kind,
            "step": sc.step,
            "engine": self.engine,
            "metrics": self.metrics,
            "notes": list(self.notes),
        }
        if self.validation is not None:
            out["validation"] = self.validation
        return out


def _angles(res: Trace, joints) -> np.ndarray:
    return np.column_stack([res.column(f"robot.{j}.q") for j in joints])


def _validate_rig(session: Session, case: Mapping, laws: Mapping, progress: Progress) -> dict:
    from .rig import reference

    sc = session.scenario
    p, rows = laws["rig"], []
    steps = sorted(sc.validation_steps, reverse=True)
    for i, h in enumerate([sc.step, *steps]):
        res = session.trace(case, step=h, duration=sc.validation_duration)
        s = res.column(f"joint.{sc.rig_joint.axis}.s")
        error = np.max(np.abs(s - reference(p["m"], p["c"], p["k"], sc.hub, res.time)))
        rows.append({"step": h, "max_error": float(error)})
        if progress is not None:
            progress((i + 1) / (len(steps) + 1))
    return {
        "reference": "monolithic scipy DOP853, rtol 1e-11",
        "max_error": rows[0]["max_error"],
        "steps": rows[1:],
    }


def robot_reference(sc: Scenario, laws: Mapping, step: float, duration: float, integrator: str) -> Trace:
    """The same robot with every joint's spring-damper computed inside MuJoCo."""
    springs = {j: SpringDamper(p["k"], p["c"], p["offset"]) for j, p in laws.items()}
    robot = robot_system(sc, step, integrator=integrator, in_engine=springs)
    return run_master(Master({"robot": robot}, []), duration, step)


def _validate_robot(session: Session, case: Mapping, laws: Mapping, progress: Progress) -> dict:
    sc = session.scenario
    duration, joints = sc.validation_duration, list(sc.joints)
    steps = sorted(sc.validation_steps, reverse=True)
    fine = min(steps) / 4
    ref_fine = _angles(robot_reference(sc, laws, fine, duration, "rk4"), joints)
    same = _angles(session.trace(case, duration=duration), joints)
    same_ref = _angles(robot_reference(sc, laws, sc.step, duration, sc.integrator), joints)
    rows = []
    for i, h in enumerate(steps):
        ratio = int(round(h / fine))
        if abs(ratio * fine - h) > 1e-9 * h:
            raise DesignerError(
                f"validation step {h:g} s is not a multiple of {fine:g} s",
                "use steps halving from the largest",
            )
        q = _angles(session.trace(case, step=h, duration=duration), joints)
        q_same = _angles(robot_reference(sc, laws, h, duration, sc.integrator), joints)
        rows.append(
            {
                "step": h,
                "max_error": float(np.max(np.abs(q - ref_fine[::ratio]))),
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


def robot_metrics(sc: Scenario, res: Trace, laws: Mapping) -> dict:
    """Per joint: tracking, deflection, overshoot, settling and energy (see metrics.joint_metrics)."""
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


def rig_metrics(sc: Scenario, res: Trace, params: Mapping) -> dict:
    """The hub's tracking of the joint and the peak load on the specimen."""
    a = sc.rig_joint.axis
    s, q = res.column(f"joint.{a}.s"), res.column("hub.q")
    return {
        "rig": {
            "axis": a,
            "tracking_rms": float(np.sqrt(np.mean((q - s) ** 2))),
            "peak_load": float(units.from_si("F", a, np.max(np.abs(res.column("hub.f"))))),
            "peak_load_unit": units.rig_unit("F", a),
            "coefficients_si": dict(params),
        }
    }


def result(
    session: Session,
    case: Mapping[str, Mapping[str, float]],
    duration: float | None,
    engine: str,
    validate: bool,
    progress: Progress,
) -> Result:
    """One run of a prepared session (what `Session.run` returns; `case` as Session.parameters gives it)."""
    share = 0.5 if validate else 1.0

    def part(offset: float, scale: float) -> Progress:
        return None if progress is None else (lambda f: progress(offset + scale * f))

    sc = session.scenario
    laws = session.laws(case)
    trace = session.trace(case, duration=duration, progress=part(0.0, share), engine=engine)
    if sc.kind == "rig":
        metrics, check = rig_metrics(sc, trace, laws["rig"]), _validate_rig
    else:
        metrics, check = robot_metrics(sc, trace, laws), _validate_robot
    validation = check(session, case, laws, part(share, 1.0 - share)) if validate else None
    notes = (*trace.delays, *(session.master.systems["robot"].notes if sc.kind == "robot" else ()))
    return Result(sc, trace.time, trace.columns, trace.values, metrics, laws, validation, notes, trace.engine)


def run(
    scenario: Scenario, *, validate: bool = False, progress: Progress = None, engine: str = "auto"
) -> Result:
    """Co-simulate `scenario` once and return the result in memory; no file is written.

    `with prepare(scenario) as s: return s.run(...)`: for many runs of one scenario, prepare a
    `Session` yourself and call its `run` per case.

    Args:
        scenario: a `Scenario` (built in code, or read by `designer.cosim.load`).
        validate: also compare with the reference (in-engine MuJoCo spring-damper and RK4 for a
            robot, a monolithic scipy solution for the rig) at the scenario's validation steps.
        progress: called with the fraction done, 0 to 1.
        engine: "kernel" runs the loop compiled (fmus/kernel/, built on first use with the system C
            compiler), "python" in the reference master, "auto" the kernel when there is a compiler
            and it can run every system; `Result.engine` says which ran.

    Raises:
        DesignerError: a bad scenario, an FMU that cannot be loaded or refuses its parameters, a
            co-simulation that diverges.
    """
    with prepare(scenario) as session:
        return session.run(validate=validate, progress=progress, engine=engine)


def rig_log(result: Result) -> pd.DataFrame:
    """A rig run as a rig log: t, the axis' coordinate and load in rig units, the hub angle.

    The load is held over each step, so the sensor's sample at t_n is the mean of the loads held
    either side of it: read at one edge, the log would look half a step late (extra damping k h / 2).
    """
    import pandas as pd

    from ..rig.logs import LOAD

    a = result.scenario.rig_joint.axis
    held = result.column("hub.f")
    sensed = np.concatenate([held[:1], 0.5 * (held[1:] + held[:-1])])
    return pd.DataFrame(
        {
            "t": result.time,
            a: units.from_si("r", a, result.column(f"joint.{a}.s")),
            LOAD[a]: units.from_si("F", a, sensed),
            "hub": result.column("hub.q"),
        }
    )


#: every file `write_outputs` may write into its folder (which ones: the scenario's switches and kind)
OUTPUT_FILES = (
    "timeseries.csv",
    "timeseries.parquet",
    "metrics.json",
    "plot.png",
    "rig_log.csv",
    "rig_log.json",
)


def write_outputs(
    result: Result,
    folder: str | Path,
    *,
    csv: bool | None = None,
    parquet: bool | None = None,
    plot: bool | None = None,
) -> list[Path]:
    """Write a result into `folder`, all files or none; returns the paths written.

    `timeseries.csv` and `timeseries.parquet` (column `t` [s], then the signals in SI), `metrics.json`
    (`Result.summary()`), `plot.png`; for the rig also `rig_log.csv` and its sidecar. `csv`,
    `parquet`, `plot` default to the scenario's `outputs` switches. The files are written into a
    staging folder beside `folder` and moved in together, so an interrupt leaves the folder as it was.

    Raises:
        DesignerError: `folder` is a file or cannot be created or written; `result` is not a Result.
    """
    check_type(result, Result, "result", expected="a Result", fix="give what designer.cosim.run returns")
    out = path_argument(folder, "folder", what="a folder")
    if out.exists() and not out.is_dir():
        raise DesignerError(f"folder={str(out)!r} is a file", "give a folder for the results")
    switches = result.scenario.outputs
    want = {
        "csv": switches["csv"] if csv is None else csv,
        "parquet": switches["parquet"] if parquet is None else parquet,
        "plot": switches["plot"] if plot is None else plot,
    }
    written = []
    with atomic_folder(out, OUTPUT_FILES) as stage:
        if want["csv"] or want["parquet"]:
            written += _write_series(result, stage, want["csv"], want["parquet"])
        with atomic_write(stage / "metrics.json") as fh:
            json.dump(result.summary(), fh, indent=2, default=float)
        written.append(stage / "metrics.json")
        if want["plot"]:
            from ..plots.common import save_figure

            written.append(save_figure(plot_result(result), stage / "plot.png"))
        if result.scenario.kind == "rig":
            from ..rig.logs import write_log

            written.append(write_log(rig_log(result), stage / "rig_log.csv", result.scenario.factors))
    return [out / Path(f).name for f in written]


def _write_series(result: Result, out: Path, csv: bool, parquet: bool) -> list[Path]:
    """The time series through pyarrow (its CSV writer is several times faster than pandas')."""
    import pyarrow as pa

    # columns as buffers: pa.array / pa.table on numpy would import pandas (0.5 s) to check the type
    columns = np.ascontiguousarray(np.column_stack([result.time, result.values]).T, dtype=float)
    arrays = [pa.Array.from_buffers(pa.float64(), len(c), [None, pa.py_buffer(c)]) for c in columns]
    table = pa.Table.from_arrays(arrays, names=["t", *result.columns])
    written = []
    if csv:
        import pyarrow.csv as pacsv

        with atomic_path(out / "timeseries.csv") as tmp:
            pacsv.write_csv(table, tmp)
        written.append(out / "timeseries.csv")
    if parquet:
        import pyarrow.parquet as pq

        with atomic_path(out / "timeseries.parquet") as tmp:
            pq.write_table(table, tmp)
        written.append(out / "timeseries.parquet")
    return written


def plot_result(result: Result) -> Figure:
    """Angles (or coordinate and hub) and loads against time, one panel each: a matplotlib Figure
    (save it with `designer.plots.common.save_figure` or `Figure.savefig`)."""
    from ..plots.timeseries import plot_timeseries

    frame = result.to_frame()
    angles = [c for c in frame.columns if c.endswith((".q", ".motor", ".s"))]
    loads = [c for c in frame.columns if c.endswith((".f", ".tau"))]
    panels = {"angle [rad] / coordinate [SI]": angles, "torque [N.m] / force [N]": loads}
    return plot_timeseries(frame, panels={label: cols for label, cols in panels.items() if cols})
