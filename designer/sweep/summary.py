"""A sweep's summary (percentiles, share meeting the limits, the engine path's check), its files, its plot."""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from .. import units
from ..cosim.host import integrator_name
from ..cosim.rig_scenario import RigScenario
from ..cosim.robot_scenario import RobotScenario
from ..files import atomic_folder, atomic_path, atomic_write
from ..study import space
from .cases import Case
from .engine import rollout_traces
from .evaluate import RIG_METRICS, fmu_result, metrics
from .limits import METRICS, applies
from .spec import Spec

PERCENTILES = (5, 50, 95)


def column_units(spec: Spec, frame: pd.DataFrame) -> dict[str, str]:
    """The unit of every numeric column of a sweep table (rig units for coefficients)."""
    out = {}
    metric_units = dict(METRICS.values()) | {"k_error_pct": "%", "c_error_pct": "%", "r2": "1"}
    joints = spec.scenario.sources()
    for col in frame.columns:
        joint, _, name = col.partition(".")
        if not name:
            continue
        if name in metric_units:
            out[col] = metric_units[name]
        elif name in ("k", "c", "k_identified", "c_identified") and joint in joints:
            out[col] = units.rig_unit(name[0], joints[joint].axis)
        elif name[:2] in ("k_", "c_") and name[2:] in units.AXES:
            out[col] = units.rig_unit(name[0], name[2:])
        elif name in space.BY_NAME:
            out[col] = space.BY_NAME[name].unit
    out["wall_s"] = "s"
    return out


def robot_columns(sc: RobotScenario, frame: pd.DataFrame) -> list[str]:
    """A robot sweep's metric columns, joint by joint (step metrics for stepped joints only)."""
    names = [c for c, _ in METRICS.values()]
    return [
        f"{j}.{m}"
        for j in sc.joints
        for m in names
        if f"{j}.{m}" in frame.columns and applies(m, sc.motors[j])
    ]


def rig_columns(sc: RigScenario, frame: pd.DataFrame) -> list[str]:
    """A rig sweep's metric columns: the identification of the rig joint."""
    return [f"rig.{m}" for m in RIG_METRICS if f"rig.{m}" in frame.columns]


#: the metric columns of a sweep table, by scenario type
COLUMNS = {RobotScenario: robot_columns, RigScenario: rig_columns}


def metric_columns(spec: Spec, frame: pd.DataFrame) -> list[str]:
    """The metric columns of a sweep table."""
    return COLUMNS[type(spec.scenario)](spec.scenario, frame)


def percentiles(frame: pd.DataFrame, columns: Sequence[str]) -> dict[str, dict]:
    """Per metric column: 5/50/95 % percentiles over the finished cases that have a value, and counts."""
    ok = frame[frame["status"] == "ok"]
    out = {}
    for col in columns:
        values = ok[col].to_numpy(dtype=float)
        have = values[np.isfinite(values)]
        entry = {"n": int(len(have)), "missing": int(len(values) - len(have))}
        entry |= {f"p{p}": (float(np.percentile(have, p)) if len(have) else None) for p in PERCENTILES}
        out[col] = entry
    return out


def limit_shares(spec: Spec, frame: pd.DataFrame) -> dict:
    """Share of all cases meeting each limit at every joint it applies to (step metrics: joints with a
    step reference), and all limits at once; failed cases meet none."""
    if not spec.limits or frame.empty:
        return {}
    ok = (frame["status"] == "ok").to_numpy()
    every = ok.copy()
    per = []
    for limit in spec.limits:
        met = ok.copy()
        for j in spec.scenario.joints:
            if not applies(limit.metric, spec.scenario.motors[j]):
                continue
            col = f"{j}.{limit.metric}"
            values = frame[col].to_numpy(dtype=float) if col in frame else np.full(len(frame), np.nan)
            met &= np.array([limit.met(v) for v in values])
        every &= met
        per.append({"limit": str(limit), "share": float(met.mean())})
    return {"limits": per, "share_meeting_all": float(every.mean())}


def engine_check(spec: Spec, *, cases: Sequence[Case], frame: pd.DataFrame) -> dict | None:
    """The engine path against the FMU co-simulation on `spec.check` cases spread over the finished ones."""
    if spec.path != "engine" or spec.check == 0:
        return None
    from ..cosim import prepare

    ok = set(frame.loc[frame["status"] == "ok", "key"])
    finished = [c for c in cases if c.key in ok]
    if not finished:
        return None
    picks = [
        finished[i] for i in np.unique(np.linspace(0, len(finished) - 1, spec.check).round().astype(int))
    ]
    sc = spec.scenario
    engine = rollout_traces(sc, picks)
    angle, metric_diff = 0.0, {}
    with prepare(sc) as session:
        for case, fast in zip(picks, engine, strict=True):
            result = fmu_result(session, case=case)
            q = [f"robot.{j}.q" for j in sc.joints]
            angle = max(angle, max(float(np.max(np.abs(result.column(c) - fast.column(c)))) for c in q))
            slow, quick = result.metrics, metrics(sc, trace=fast, case=case)
            for j in sc.joints:
                for name, v in slow[j].items():
                    w = quick[j][name]
                    d = 0.0 if v is None and w is None else (np.inf if v is None or w is None else abs(v - w))
                    metric_diff[f"{j}.{name}"] = max(metric_diff.get(f"{j}.{name}", 0.0), float(d))
    return {
        "cases": [c.index for c in picks],
        "max_angle_difference_rad": angle,
        "max_metric_difference": metric_diff,
        "integrator": sc.integrator or integrator_name(sc.model_spec()),
    }


def summarize(spec: Spec, *, frame: pd.DataFrame, cases: Sequence[Case]) -> dict:
    """The summary of a sweep table: counts, percentiles, limit shares, units, the engine check."""
    failed = frame[frame["status"] != "ok"]
    summary = {
        "cases": int(len(frame)),
        "ok": int(len(frame) - len(failed)),
        "failed": int(len(failed)),
        "failures": [{"case": int(r.case), "message": r.message} for r in failed.itertuples()][:20],
        "path": spec.path,
        "case_type": spec.cases.type,
        "percentiles": percentiles(frame, metric_columns(spec, frame)),
        "units": column_units(spec, frame),
    }
    summary |= limit_shares(spec, frame)
    check = engine_check(spec, cases=cases, frame=frame)
    if check is not None:
        summary["engine_check"] = check
    return summary


def write_results(result, folder: str | Path, *, plot: bool = True) -> list[Path]:
    """Write results.parquet (units in its metadata), summary.json and, optionally, metrics.png."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    folder = Path(folder)
    arrow = pa.Table.from_pandas(result.table, preserve_index=False)
    meta = dict(arrow.schema.metadata or {})
    meta[b"designer.units"] = json.dumps(result.summary["units"]).encode()
    with atomic_folder(folder) as stage:  # moved in together: an interrupt leaves none of them
        with atomic_path(stage / "results.parquet") as tmp:
            pq.write_table(arrow.replace_schema_metadata(meta), tmp)
        with atomic_write(stage / "summary.json") as fh:
            json.dump(result.summary, fh, indent=2, default=float)
        names = ["results.parquet", "summary.json"]
        if plot and result.summary["ok"]:
            names.append(plot_metrics(result, stage / "metrics.png").name)
    return [folder / name for name in names]


def plot_metrics(result, path: str | Path) -> Path:
    """One histogram per metric column with its 5/50/95 % percentiles (dashed) and the task limits (red)."""
    import matplotlib.pyplot as plt

    from ..plots.common import save_figure

    pct = result.summary["percentiles"]
    cols = [c for c, p in pct.items() if p["n"]]
    ncol = min(len(cols), 3)
    nrow = -(-len(cols) // ncol)
    fig, axes = plt.subplots(nrow, ncol, figsize=(4.2 * ncol, 3.0 * nrow), squeeze=False)
    ok = result.table[result.table["status"] == "ok"]
    limits = {lim.metric: lim for lim in result.spec.limits}
    for ax, col in zip(axes.ravel(), cols, strict=False):
        values = ok[col].to_numpy(dtype=float)
        ax.hist(values[np.isfinite(values)], bins=30, color="0.6")
        for p in PERCENTILES:
            ax.axvline(pct[col][f"p{p}"], color="k", ls="--", lw=0.8)
        name = col.split(".", 1)[1]
        if name in limits:
            ax.axvline(limits[name].value, color="red", lw=1.2)
        ax.set_xlabel(f"{col} ({result.summary['units'].get(col, '')})")
        ax.set_title(f"{pct[col]['n']} cases with a value", fontsize=9)
        ax.set_ylabel("cases")
    for ax in axes.ravel()[len(cols) :]:
        ax.set_visible(False)
    fig.suptitle(f"{result.summary['ok']} cases: percentiles 5/50/95 % dashed, task limits red")
    fig.tight_layout()
    return save_figure(fig, path)
