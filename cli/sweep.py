"""`designer sweep` (many co-simulations, one table) and `designer tune` (task -> k, c -> designs)."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Annotated

import typer

from designer.errors import DesignerError

from .common import console, err_console, finishing, print_json, progress

JsonOpt = Annotated[bool, typer.Option("--json", help="print the summary as JSON only")]
WorkersOpt = Annotated[
    int | None,
    typer.Option("--workers", min=1, help="local worker processes (default: one per core; 1: serial)"),
]
SchedulerOpt = Annotated[
    str | None, typer.Option("--scheduler", help="run on a Dask scheduler, e.g. tcp://10.0.0.5:8786")
]


def sweep(
    spec: Annotated[Path, typer.Argument(help="sweep file (TOML); see the README for its format")],
    out: Annotated[
        Path, typer.Option("-o", "--output", help="folder for results.parquet, summary.json, metrics.png")
    ] = Path("sweep"),
    workers: WorkersOpt = None,
    scheduler: SchedulerOpt = None,
    path: Annotated[
        str | None,
        typer.Option("--path", help="fmu (co-simulate every case) or engine (mujoco.rollout fast path)"),
    ] = None,
    plot: Annotated[bool, typer.Option("--plot/--no-plot", help="draw metrics.png")] = True,
    max_cases: Annotated[
        int | None,
        typer.Option(
            "--max-cases", min=1, help="most cases to run (default 1000000); checked before any work"
        ),
    ] = None,
    json_out: JsonOpt = False,
) -> None:
    """Run a design sweep: a grid, suggestion candidates or Monte Carlo draws over the prediction intervals.

    A rerun into the same folder skips the cases already finished (out/cases.jsonl). Exit 1 when no
    case succeeds.

    Example: designer sweep examples/sweep_arm.toml -o results/sweep --workers 2
    """
    from dataclasses import replace

    from designer import sweep as sw
    from designer.files import check_output_folder
    from designer.sweep.executors import executor
    from designer.sweep.summary import OUTPUT_FILES

    s = sw.load(spec)
    if path is not None:
        if path not in ("fmu", "engine"):
            raise DesignerError(f"--path {path} is not allowed", "use --path fmu or --path engine")
        s = replace(s, path=path)
    max_cases = sw.MAX_CASES if max_cases is None else max_cases
    sw.check_size(s, max_cases)
    check_output_folder(out, OUTPUT_FILES)
    made = _missing_folders(out)
    out.mkdir(parents=True, exist_ok=True)
    workers = workers if workers else s.workers
    try:
        with executor(workers=workers, scheduler=scheduler, cluster=s.cluster) as ex:
            with progress(f"sweeping {spec.name}", enabled=not json_out) as bar:
                result = sw.run(
                    s, executor=ex, journal=out / "cases.jsonl", progress=bar, max_cases=max_cases
                )
        finishing()
        files = sw.write_results(result, out, plot=plot)
    except BaseException:  # stopped or failed: keep the finished cases for a rerun, nothing else
        _keep_journal(out / "cases.jsonl", made)
        raise
    summary = result.summary | {"resumed": result.resumed, "files": [str(f) for f in files]}
    if json_out:
        print_json(summary)
    else:
        _print_sweep(summary)
    if summary["ok"] == 0:
        raise typer.Exit(1)


def _missing_folders(folder: Path) -> list[Path]:
    """`folder` and those of its parents that do not exist yet, innermost first."""
    return [p for p in [folder, *folder.parents] if not p.exists()]


def _keep_journal(journal: Path, made: list[Path]) -> None:
    """After an interrupted or failed sweep: the journal of finished cases stays for a rerun to resume
    (and stderr says so); one with no finished case is removed, with the folders this run created."""
    lines = journal.read_bytes().count(b"\n") if journal.is_file() else 0
    if lines:
        err_console.print(f"{lines} finished cases kept in {journal}: rerun the same command to resume")
        return
    journal.unlink(missing_ok=True)
    for folder in made:
        try:
            folder.rmdir()
        except OSError:  # not empty: something else was put there meanwhile
            return


def _number(v: float | None, unit: str) -> str:
    return "-" if v is None or not math.isfinite(v) else f"{v:.4g} {unit}".strip()


def _print_sweep(summary: dict) -> None:
    from rich.table import Table

    console.print(
        f"{summary['cases']} cases ({summary['case_type']}, {summary['path']} path): {summary['ok']} ok, "
        f"{summary['failed']} failed, {summary['resumed']} resumed from an earlier run"
    )
    table = Table(title="metrics over the finished cases")
    for col in ("metric", "5 %", "50 %", "95 %", "cases with a value"):
        table.add_column(col, justify="right")
    for col, p in summary["percentiles"].items():
        unit = summary["units"].get(col, "")
        table.add_row(col, *(_number(p[f"p{q}"], unit) for q in (5, 50, 95)), f"{p['n']}")
    console.print(table)
    for row in summary.get("limits", []):
        console.print(f"{100 * row['share']:.0f} % of the cases meet {row['limit']}")
    if "share_meeting_all" in summary:
        console.print(f"{100 * summary['share_meeting_all']:.0f} % meet every limit")
    check = summary.get("engine_check")
    if check:
        console.print(
            f"engine path vs FMU co-simulation on cases {check['cases']}: largest joint-angle difference "
            f"{check['max_angle_difference_rad']:.2g} rad"
        )
    for f in summary["failures"]:
        console.print(f"case {f['case']} failed: {f['message']}")
    for f in summary["files"]:
        console.print(f"wrote {f}")


def _parse_bounds(items: list[str]) -> dict[str, tuple[float, float]]:
    out = {}
    for item in items:
        key, sep, rng = item.partition("=")
        low, colon, high = rng.partition(":")
        joint, dot, q = key.strip().partition(".")
        if not (sep and colon and dot and q in ("k", "c")):
            raise DesignerError(
                f"--bounds '{item}' is not JOINT.k=LOW:HIGH", "write e.g. --bounds j1.k=200:600"
            )
        try:
            out[key.strip()] = (float(low), float(high))
        except ValueError:
            raise DesignerError(f"--bounds '{item}': not numbers", "write e.g. --bounds j1.c=5:150") from None
    return out


def tune(
    scenario: Annotated[Path, typer.Argument(help="robot scenario file (TOML)")],
    objective: Annotated[
        str,
        typer.Option(
            "--objective",
            help="metric to minimise, summed over the joints: settling_time, "
            "overshoot, tracking_rms, peak_deflection, energy_dissipated",
        ),
    ] = "settling_time",
    limit: Annotated[
        list[str] | None, typer.Option("--limit", help='task limit met at every joint, e.g. "overshoot<=5%"')
    ] = None,
    bounds: Annotated[
        list[str] | None,
        typer.Option(
            "--bounds",
            help="JOINT.k=LOW:HIGH or JOINT.c=LOW:HIGH in rig units (default: the surrogate's reach)",
        ),
    ] = None,
    out: Annotated[Path | None, typer.Option("-o", "--output", help="write the result as JSON here")] = None,
    path: Annotated[str, typer.Option("--path", help="engine (fast, FMU-checked optimum) or fmu")] = "engine",
    robustness: Annotated[
        int, typer.Option("--robustness", min=0, help="Monte Carlo draws of the designs to print")
    ] = 100,
    seed: Annotated[int, typer.Option("--seed", min=0, help="seed of the optimiser and the draws")] = 0,
    workers: WorkersOpt = None,
    scheduler: SchedulerOpt = None,
    json_out: JsonOpt = False,
) -> None:
    """Tune k and c of every joint for a task, name designs to print, and test them under the PIs.

    Exit 1 when no tried k, c meets the limits.

    Example: designer tune examples/tune_one_link.toml --objective settling_time --limit "overshoot<=0%"
    --bounds j1.k=200:600 --bounds j1.c=5:150 -o tuned.json
    """
    from designer import cosim
    from designer.files import atomic_write
    from designer.sweep.executors import executor
    from designer.sweep.limits import parse_limit
    from designer.sweep.tune import tune as run_tune

    if path not in ("fmu", "engine"):
        raise DesignerError(f"--path {path} is not allowed", "use --path engine or --path fmu")
    limits = [parse_limit(x) for x in limit or []]
    box = _parse_bounds(bounds or [])
    sc = cosim.load(scenario)
    with executor(workers=workers, scheduler=scheduler) as ex:
        with progress(f"tuning {scenario.name}", enabled=not json_out) as bar:
            result = run_tune(
                sc,
                objective=objective,
                limits=limits,
                bounds=box,
                path=path,
                executor=ex,
                robustness=robustness,
                seed=seed,
                progress=bar,
            )
    finishing()
    data = result.to_dict()
    if out is not None:
        out.parent.mkdir(parents=True, exist_ok=True)
        with atomic_write(out) as fh:
            json.dump(data, fh, indent=2, default=float)
    if json_out:
        print_json(data)
    else:
        _print_tune(data, sc, out)
    if not result.feasible:
        raise typer.Exit(1)


def _print_tune(data: dict, sc, out: Path | None) -> None:
    from designer import units
    from designer.sweep.limits import unit

    state = "meets every limit" if data["feasible"] else "does NOT meet the limits"
    objective_unit = unit(data["objective"])
    console.print(f"tuned after {data['evaluations']} co-simulations; the best {state}")
    for j, coef in data["joints"].items():
        a = sc.joints[j].axis
        value = data["metrics"].get(f"{j}.{data['objective']}")
        console.print(
            f"  {j}: k = {units.fmt(coef['k'], 'k', a)}, c = {units.fmt(coef['c'], 'c', a)}, "
            f"{data['objective']} = {_number(value, objective_unit)}"
        )
    for j, d in data["designs"].items():
        best = d["candidates"][0]["params"] if d["candidates"] else {}
        console.print(f"  {j}: design to print {best}")
        for s in d["statements"]:
            console.print(f"    {s}")
    rob = data.get("robustness")
    if rob:
        console.print(f"robustness over {rob['cases']} draws within the PIs of these designs:")
        for col, p in rob["percentiles"].items():
            u = unit(col.split(".", 1)[1])
            console.print(f"  {col}: 5/50/95 % = " + " / ".join(_number(p[f"p{q}"], u) for q in (5, 50, 95)))
        if "share_meeting_all" in rob:
            console.print(f"  {100 * rob['share_meeting_all']:.0f} % of the draws meet every limit")
    if out is not None:
        console.print(f"wrote {out}")


def register(app: typer.Typer) -> None:
    app.command("sweep")(sweep)
    app.command("tune")(tune)
