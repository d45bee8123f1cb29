"""Run a scenario in memory (`run` -> `Result`); writing its files is a separate call (`write_outputs`).

A run exports the joints that are not FMU files into a temporary folder, co-simulates them with the
robot or the rig, computes the metrics and, when asked, compares with the reference solution.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..errors import DesignerError, check_type, path_argument
from ..files import atomic_folder, atomic_path, atomic_write
from .result import Result
from .scenario import Scenario
from .session import Progress, prepare

if TYPE_CHECKING:
    from matplotlib.figure import Figure


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
    with atomic_folder(out) as stage:
        if want["csv"] or want["parquet"]:
            written += _write_series(result, stage, want["csv"], want["parquet"])
        with atomic_write(stage / "metrics.json") as fh:
            json.dump(result.summary(), fh, indent=2, default=float)
        written.append(stage / "metrics.json")
        if want["plot"]:
            from ..plots.common import save_figure

            written.append(save_figure(plot_result(result), stage / "plot.png"))
        written += result.scenario.write_extra(result, stage)
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
