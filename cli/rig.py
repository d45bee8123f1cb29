"""Commands of the study's pipeline: identify, rig simulate, clean, doe, analyze."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Annotated

import typer

from designer.errors import DesignerError

from .common import (
    AcceptImplausibleOpt,
    JsonOpt,
    Typer,
    console,
    err_console,
    finishing,
    print_json,
    progress,
)

rig_app = Typer(help="The virtual rig: simulate the study's experiment.", no_args_is_help=True)

_FACTOR_HELP = "specimen factor written to the log's sidecar (give all six, or none)"
#: identify's runs table of the prints (designer print's)
RunsOpt = Annotated[
    Path | None,
    typer.Option(
        "--runs", help="the prints' runs table (designer print's): fill the row of the print a log names"
    ),
]

#: identify's print id of one log whose sidecar names none
PrintOpt = Annotated[
    str | None,
    typer.Option(
        "--print",
        help="with --runs and one log: the print it measured (its id in the runs table, e.g. P1), "
        "for a log whose sidecar names none",
    ),
]


def identify(
    logs: Annotated[
        list[Path], typer.Argument(help="rig logs (CSV or Parquet), each with its factor sidecar")
    ],
    output: Annotated[
        Path | None,
        typer.Option("-o", "--output", help="write the coefficient table (CSV) of the logs that pass"),
    ] = None,
    load_delay: Annotated[
        float | None,
        typer.Option(
            help="s by which the load channel lags the position (default: sidecar load_delay_s, else 0)"
        ),
    ] = None,
    load_filter: Annotated[
        str | None,
        typer.Option(
            help="the load sensor's low-pass, e.g. butter2:200Hz, undone exactly (default: sidecar "
            "load_filter, else none)"
        ),
    ] = None,
    runs: RunsOpt = None,
    print_id: PrintOpt = None,
    accept_implausible: AcceptImplausibleOpt = False,
    json_out: JsonOpt = False,
) -> None:
    """Identify m, c, k per axis from rig logs (F = m r'' + c r' + k r); exit 1 if any log fails.

    A force sensor's own low-pass lags the load like a delay and biases c (a 2nd-order Butterworth
    at 200 Hz: about -45 % of c at 0.8 N/mm); give it with --load-filter.

    With --runs, each log's k and c go into the row of the print its sidecar names ({"print": "P1"}),
    or, for one log, the print --print names.

    Example: designer identify run1.csv run2.parquet --load-delay 0.002 -o table.csv

    Example: designer identify p1_run.csv --runs batch1/runs.csv --print P1
    """
    from designer.rig.axis_fit import ESTIMATOR
    from designer.rig.identify import identify as run
    from designer.rig.identify import results_table

    _check_identify(logs, output, runs, print_id, load_delay)
    with progress("identifying") as bar:
        results = run(logs, load_delay_s=load_delay, load_filter=load_filter, progress=bar)
    finishing()
    passed = [r for r in results if r.ok]
    wrote = output is not None and bool(passed)
    if wrote:
        from designer.study.data import write_frame

        write_frame(results_table(passed), output)
    filled = _fill_runs(runs, passed, print_id, accept_implausible)
    if json_out:
        print_json(
            {
                "estimator": ESTIMATOR,
                "logs": [r.to_dict() for r in results],
                "failed": [str(r.path) for r in results if not r.ok],
                "warnings": [f"{r.path}: {w}" for r in results for w in r.warnings],
                "table": str(output) if wrote else None,
                "runs": filled,
            }
        )
    else:
        for res in results:
            _print_identification(res)
        console.print(f"estimator: {ESTIMATOR}")
        if wrote:
            console.print(f"wrote {output} ({len(passed)} of {len(results)} logs)")
        elif output is not None:
            console.print(f"no log passed: {output} not written")
        _print_filled(filled, runs)
    if len(passed) < len(results):
        raise typer.Exit(1)


def _check_identify(
    logs: list[Path], output: Path | None, runs: Path | None, print_id: str | None, load_delay: float | None
) -> None:
    """identify's arguments, before any log is read: the outputs writable, --print with --runs."""
    from designer.files import check_output

    for path in (output, runs):
        if path is not None:
            check_output(path, suffixes=TABLE_SUFFIXES, inputs=logs)
    if print_id is not None and runs is None:
        raise DesignerError("--print names the row of a runs table to fill", "give the table with --runs")
    if load_delay is not None and load_delay != load_delay:
        raise DesignerError("--load-delay is NaN", "give the delay in seconds, e.g. --load-delay 0.002")


def _fill_runs(
    runs: Path | None, passed: list, print_id: str | None, accept_implausible: bool
) -> dict | None:
    """Fill the runs table from the logs that passed; None without --runs or a passed log."""
    if runs is None or not passed:
        return None
    from designer.printing.runs import fill_file

    return fill_file(runs, passed, print_id=print_id, accept_implausible=accept_implausible)


def _print_filled(filled: dict | None, runs: Path | None) -> None:
    if filled is not None:
        waiting = f"; not measured yet: {', '.join(filled['waiting'])}" if filled["waiting"] else ""
        console.print(f"filled {', '.join(filled['filled'])} in {runs}{waiting}")


def _print_identification(res) -> None:
    """One log: its coefficients, band tables, warnings and failures, in rig units."""
    from rich.table import Table

    from designer import units

    table = Table(title=f"{res.path}  ({res.rate:g} Hz)")
    for col in ("axis", "k", "c", "m", "R2", "band"):
        table.add_column(col)
    for a, f in res.axes.items():
        table.add_row(
            a,
            f"{f.k:.4g} +/- {f.k_se:.2g} {units.rig_unit('k', a)}",
            f"{f.c:.4g} +/- {f.c_se:.2g} {units.rig_unit('c', a)}",
            f"{f.m:.3g} +/- {f.m_se:.2g} {units.rig_unit('m', a)}",
            f"{f.r2:.5f}",
            f"{f.band['low_hz']:.3g}-{f.band['high_hz']:.3g} Hz "
            f"(filter flat to {f.band['filter_pass_hz']:.3g} Hz)",
        )
    console.print(table)
    for f in res.axes.values():
        ru, ku, cu = units.rig_unit("r", f.axis), units.rig_unit("k", f.axis), units.rig_unit("c", f.axis)
        console.print(f"  {f.axis}: {f.statement()}")
        console.print(
            f"  {f.axis}: load delay corrected {1e3 * f.load_delay_s:.3g} ms"
            + (f", load filter {f.load_filter} undone" if f.load_filter else "")
            + "; one more sample of skew "
            f"changes c by {f.c_per_sample_skew:+.3g} {cu}"
        )
        amp = ", ".join(
            f"{r['from']:.3g}-{r['to']:.3g} {ru}: {r['k']:.4g} +/- {r['k_se']:.2g}"
            for r in f.k_amplitude["rows"]
        )
        console.print(f"  {f.axis}: k(amplitude) [{ku}] {amp} (p equal {f.k_amplitude['p_equal']:.2g})")
        freq = ", ".join(
            f"{r['from_hz']:.3g}-{r['to_hz']:.3g} Hz: {r['c']:.4g} +/- {r['c_se']:.2g}"
            for r in f.c_frequency["rows"]
        )
        console.print(f"  {f.axis}: c(frequency) [{cu}] {freq} (p equal {f.c_frequency['p_equal']:.2g})")
    for note in res.notes:
        console.print(f"  note: {note}")
    for w in res.warnings:
        console.print(f"  warning: {_as_flags(w)}")
    for a, why in res.failures.items():
        console.print(f"  FAILED {a}: {_as_flags(why)}")
    for a, why in res.still.items():
        console.print(f"  still {a}: {why}; not identified (the moving axes are)")


def _as_flags(text: str) -> str:
    """The library's argument names in a warning or reason, as this command's flags."""
    text = re.sub(r"load_filter='([^']+)'", r"--load-filter \1", text)
    return text.replace("load_filter", "--load-filter").replace("load_delay_s", "--load-delay")


TABLE_SUFFIXES = (".csv", ".parquet", ".pq")


@rig_app.command("simulate")
def simulate(
    output: Annotated[Path, typer.Option("-o", "--output", help="log to write (.csv, or .parquet)")],
    k: Annotated[float, typer.Option(help="stiffness, N/mm (N.mm/rad for rotational axes)")],
    c: Annotated[float, typer.Option(help="damping, N.s/mm (N.mm.s/rad for rotational axes)")],
    m: Annotated[float, typer.Option(help="mass, kg (inertia kg.m^2 for rotational axes)")] = 0.001,
    axis: Annotated[list[str], typer.Option(help="axis to simulate; repeat for several")] = ("x",),
    duration: Annotated[float, typer.Option(help="run length T, s (the study: 2200)")] = 2200.0,
    rate: Annotated[float, typer.Option(help="sampling rate, Hz")] = 1000.0,
    amplitude: Annotated[float, typer.Option(help="motion of each axis per rad of hub, mm or rad")] = 1.0,
    noise: Annotated[float, typer.Option(help="force noise, fraction of the RMS load")] = 0.01,
    dropouts: Annotated[
        float, typer.Option(help="fraction of samples in dropout segments (NaN or zero)")
    ] = 0.0,
    seed: Annotated[int | None, typer.Option(help="random seed")] = None,
    f0: Annotated[float, typer.Option(help="chirp start frequency, Hz")] = 0.2,
    f1: Annotated[float, typer.Option(help="chirp end frequency, Hz")] = 1.85,
    density: Annotated[float | None, typer.Option(help=_FACTOR_HELP)] = None,
    length: Annotated[float | None, typer.Option(help=_FACTOR_HELP)] = None,
    width: Annotated[float | None, typer.Option(help=_FACTOR_HELP)] = None,
    height: Annotated[float | None, typer.Option(help=_FACTOR_HELP)] = None,
    layer: Annotated[float | None, typer.Option(help=_FACTOR_HELP)] = None,
    raster: Annotated[float | None, typer.Option(help=_FACTOR_HELP)] = None,
    json_out: JsonOpt = False,
) -> None:
    """Drive a joint with the study's chirp (0.2 to 1.85 Hz) and write the rig log.

    Example: designer rig simulate --k 0.8 --c 2e-3 --m 0.001 --duration 200 --dropouts 0.001 -o log.csv
    """
    from designer.files import check_output
    from designer.rig.logs import write_log
    from designer.rig.simulate import footprint
    from designer.rig.simulate import simulate as run

    size = footprint(len(axis), duration=duration, rate=rate, parquet=output.suffix.lower() != ".csv")
    check_output(output, suffixes=TABLE_SUFFIXES, estimate_bytes=size["file"])
    given = {"density": density, "length": length, "width": width, "height": height}
    given |= {"layer": layer, "raster": raster}
    factors = {n: v for n, v in given.items() if v is not None}
    if factors and len(factors) < 6:
        missing = ", ".join(f"--{n}" for n, v in given.items() if v is None)
        raise DesignerError(f"missing factor(s) {missing}", "give all six factors, or none")
    if factors:
        from designer.rig.logs import sidecar_path

        check_output(sidecar_path(output))  # its name is longer than the log's with a shorter suffix
    with progress("simulating") as bar:
        df = run(
            {a: {"m": m, "c": c, "k": k} for a in axis},
            duration=duration,
            rate=rate,
            amplitude=amplitude,
            noise=noise,
            dropouts=dropouts,
            seed=seed,
            f0=f0,
            f1=f1,
        )
        bar(0.5)
        finishing()
        write_log(df, output, factors or None)
        bar(1.0)
    if json_out:
        from designer.rig.logs import sidecar_path

        sidecar = str(sidecar_path(output)) if factors else None
        print_json(
            {
                "path": str(output),
                "rows": len(df),
                "duration_s": duration,
                "rate_hz": rate,
                "axes": list(axis),
            }
            | {"coefficients": {"m": m, "c": c, "k": k}, "factors": factors or None, "sidecar": sidecar}
        )
        return
    console.print(f"wrote {output}: {len(df)} rows, {duration:g} s at {rate:g} Hz, axes {', '.join(axis)}")


def clean(
    table: Annotated[
        Path, typer.Argument(help="coefficient table (CSV or Parquet), e.g. from designer identify")
    ],
    output: Annotated[
        Path | None, typer.Option("-o", "--output", help="write the kept runs (CSV or Parquet)")
    ] = None,
    eps: Annotated[float, typer.Option(help="DBSCAN radius in standard deviations (the study: 0.5)")] = 0.5,
    min_samples: Annotated[int, typer.Option(help="DBSCAN core size (the study: 5)")] = 5,
    max_drop: Annotated[
        float,
        typer.Option(help="refuse (exit 1, nothing written) when more than this share of runs would go"),
    ] = 0.2,
    json_out: JsonOpt = False,
) -> None:
    """Drop runs with NaN or zero coefficients, then DBSCAN outliers; say why for each and what DBSCAN did.

    Refuses (exit 1, nothing written) to drop more than --max-drop of the runs, or all of them.

    Example: designer clean table.csv -o clean.csv
    """
    from designer.files import check_output
    from designer.rig.clean import clean as run
    from designer.study.data import read_frame, write_frame

    if output is not None:
        check_output(output, suffixes=TABLE_SUFFIXES, inputs=[table])
    if not 0 <= max_drop <= 1:
        raise DesignerError(f"--max-drop {max_drop:g}", "give a share between 0 and 1, e.g. 0.2")
    res = run(read_frame(table), eps=eps, min_samples=min_samples, source=table.name)
    refused = res.drop_share > max_drop or len(res.table) == 0
    finishing()
    if output is not None and not refused:
        write_frame(res.table, output)
    if json_out:
        print_json(res.summary() | {"refused": refused, "max_drop": max_drop})
    else:
        _print_clean(res, output if not refused else None)
    if refused:
        why = (
            "no run"
            if len(res.table) == 0
            else f"{100 * res.drop_share:.0f} % dropped, over --max-drop {max_drop:g}"
        )
        err_console.print(
            f"refused: cleaning would keep {len(res.table)} of {res.runs} runs ({why}); nothing written "
            "(check the reasons above; loosen --eps/--min-samples, or accept it with --max-drop 1)",
            soft_wrap=True,
        )
        raise typer.Exit(1)


def _print_clean(res, output: Path | None) -> None:
    console.print(f"kept {len(res.table)} of {res.runs} runs")
    for row in res.dropped.itertuples():
        console.print(f"  dropped row {row.row}: {row.reason}")
    for line in res.explanation:
        console.print(f"  {line}")
    if output is not None:
        console.print(f"wrote {output}")


def doe(
    output: Annotated[Path | None, typer.Option("-o", "--output", help="write the run sheet (CSV)")] = None,
    center: Annotated[
        int | None, typer.Option(help="centre runs (default 3 per layer x raster; 6 all-continuous)")
    ] = None,
    seed: Annotated[int | None, typer.Option(help="random seed of the run order")] = None,
    all_continuous: Annotated[
        bool, typer.Option(help="the six-factor design of Box and Behnken (1960) instead")
    ] = False,
    augment: Annotated[
        int | None, typer.Option(help="pick N specimens that most narrow the surrogate's PIs")
    ] = None,
    k: Annotated[float | None, typer.Option(help="with --augment: target stiffness, N/mm")] = None,
    c: Annotated[float | None, typer.Option(help="with --augment: target damping, N.s/mm")] = None,
    axis: Annotated[str, typer.Option(help="with --augment and a target: its axis")] = "x",
    data: Annotated[
        Path | None, typer.Option(help="with --augment: table to fit (default: bundled surrogate)")
    ] = None,
    json_out: JsonOpt = False,
) -> None:
    """Plan specimens: the study's Box-Behnken run sheet, or the next N that most narrow the 95 % PIs.

    Example: designer doe --seed 1 -o plan.csv
    Example: designer doe --augment 8 --k 0.8 --c 2e-3 -o next.csv
    """
    from designer.files import check_output
    from designer.study import doe as plans

    if output is not None:
        check_output(output, suffixes=TABLE_SUFFIXES, inputs=[data] if data else [])
    if augment is None:
        if k is not None or c is not None or data is not None:
            raise DesignerError("--k, --c and --data go with --augment", "add --augment N")
        if all_continuous:
            plan = plans.all_continuous_plan(plans.CENTER_BB6 if center is None else center, seed)
        else:
            plan = plans.study_plan(plans.CENTER if center is None else center, seed)
        _finish_plan(plan, output, json_out, {})
        return
    if all_continuous or center is not None:
        given = "--all-continuous" if all_continuous else "--center"
        raise DesignerError(
            f"{given} plans a new design; --augment adds to the data", f"drop {given} or --augment"
        )
    _check_augment(plans, augment)
    plan, narrowing = _augment(plans, augment, k, c, axis, data)
    _finish_plan(plan, output, json_out, narrowing)


#: seconds per greedy pick, measured: `designer doe --augment 100000` took 94 s
_SECONDS_PER_PICK = 94 / 100_000


def _check_augment(plans, n: int) -> None:
    """Refuse more specimens than printable level combinations before the greedy search starts."""
    grid = len(plans.printable_grid())
    if n < 1 or n > grid:
        cost = f" (about {n * _SECONDS_PER_PICK:.0f} s of search, repeating combinations)" if n > grid else ""
        raise DesignerError(
            f"--augment {n}: give 1 to {grid} specimens, the number of printable level combinations{cost}",
            "a campaign adds a few to a few dozen specimens: plan them, print, measure, refit",
        )


def _augment(plans, n: int, k: float | None, c: float | None, axis: str, data: Path | None):
    from designer.model.surrogate import Surrogate

    if n < 1:
        raise DesignerError(f"--augment {n}", "give the number of specimens to add, 1 or more")
    sur = Surrogate().fit(data) if data is not None else Surrogate.load()
    with progress("choosing specimens") as bar:
        return plans.plan_next(sur, n=n, targets={"k": k, "c": c}, axis=axis, progress=bar)


def _finish_plan(plan, output: Path | None, json_out: bool, narrowing: dict) -> None:
    import math

    from designer import units

    finishing()
    if output is not None:
        from designer.study.data import write_frame

        write_frame(plan, output)
    if json_out:
        print_json({"runs": plan.to_dict(orient="records"), "pi_narrowing": narrowing})
        return
    from rich.table import Table

    table = Table()
    for col in plan.columns:
        table.add_column(col)
    for row in plan.itertuples(index=False):
        table.add_row(*(f"{v:g}" if isinstance(v, float) else str(v) for v in row))
    console.print(table)
    console.print(f"{len(plan)} runs")
    for resp, nar in narrowing.items():
        before, after = nar["half_width_before"], nar["half_width_after"]
        if nar["transform"] == "log":
            text = f"x/ {math.exp(before):.3g} -> x/ {math.exp(after):.3g}"
        else:
            q, a = resp.split("_", 1)
            text = f"+/- {before:.3g} -> +/- {after:.3g} {units.rig_unit(q, a)}"
        console.print(f"{resp}: mean 95 % PI half-width {text} ({100 * (1 - after / before):.1f} % narrower)")
    if output is not None:
        console.print(f"wrote {output}")


def analyze(
    data: Annotated[
        Path | None, typer.Option(help="coefficient table (default: the bundled study table)")
    ] = None,
    json_out: JsonOpt = False,
) -> None:
    """MANOVA over the responses, ANOVA per response with contribution %, correlations, Table 4.

    Example: designer analyze --json
    """
    from designer.study.data import load_table
    from designer.study.stats import analyze as run

    res = run(load_table(data))
    if json_out:
        print_json(res)
        return
    from rich.table import Table

    for resp, rows in res["anova"].items():
        table = Table(title=f"ANOVA of {resp} (type III, first-order, {res['runs']} runs)")
        for col in ("source", "DF", "SS", "F", "p", "contribution"):
            table.add_column(col)
        for r in rows:
            table.add_row(
                r["source"],
                f"{r['df']:g}",
                f"{r['sum_sq']:.3g}",
                "" if r["F"] != r["F"] else f"{r['F']:.3f}",
                "" if r["p"] != r["p"] else f"{r['p']:.3g}",
                "" if r["contribution_pct"] != r["contribution_pct"] else f"{r['contribution_pct']:.1f} %",
            )
        console.print(table)
    if res["manova"]:
        table = Table(title="MANOVA")
        for col in ("source", "statistic", "value", "F", "DF", "p"):
            table.add_column(col)
        for r in res["manova"]:
            table.add_row(
                r["source"],
                r["statistic"],
                f"{r['value']:.4g}",
                f"{r['F']:.3f}",
                f"{r['df1']:g}, {r['df2']:g}",
                f"{r['p']:.3g}",
            )
        console.print(table)
    corr = Table(title="Correlation")
    names = list(res["correlation"])
    corr.add_column("")
    for n in names:
        corr.add_column(n)
    for n in names:
        corr.add_row(n, *(f"{res['correlation'][m][n]:+.2f}" for m in names))
    console.print(corr)
    if "table4" in res:
        table = Table(title="k_x against the paper's Table 4")
        for col in ("source", "F paper", "F", "diff", "p paper", "p", "agrees"):
            table.add_column(col)
        for r in res["table4"]["rows"]:
            table.add_row(
                r["source"],
                f"{r['F_paper']:.3f}",
                f"{r['F']:.3f}",
                f"{r['F_diff_pct']:+.1f} %",
                f"{r['p_paper']:.3g}",
                f"{r['p']:.3g}",
                "yes" if r["agrees"] else "NO",
            )
        console.print(table)
        console.print(res["table4"]["note"])


def register(app: typer.Typer) -> None:
    """Add identify, rig simulate, clean, doe and analyze to the `designer` command."""
    app.command()(identify)
    app.add_typer(rig_app, name="rig")
    app.command()(clean)
    app.command()(doe)
    app.command()(analyze)
