"""`designer plot ...` and `designer validate`: figures of the data, the surrogate and the design space."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.markup import escape

from .common import DataOpt, FixOpt, Typer, console, finishing, parse_fix, print_json, quiet_mujoco
from .common import progress as progress_bar

plot_app = Typer(
    help="Draw the data, the surrogate and the design space (PNG, SVG or PDF; headless).",
    no_args_is_help=True,
)

Output = Annotated[Path, typer.Option("-o", "--output", help="image file (.png .svg .pdf)")]
Axis = Annotated[str, typer.Option("--axis", help="axis: x y z theta phi psi")]
Json = Annotated[bool, typer.Option("--json", help="print the plotted numbers as JSON")]


def _quantities(response: str | None) -> list[str] | None:
    """'c,k' -> ['c', 'k']; None -> every quantity the table has."""
    return None if response is None else [q.strip() for q in response.split(",") if q.strip()]


def _image_out(path: Path) -> Path:
    """Check before drawing that an image can be written at `path` (format by suffix, folder, space)."""
    from designer.files import check_output
    from designer.plots.common import FORMATS

    return check_output(path, suffixes=FORMATS)


def _saved(path: Path) -> None:
    console.print(f"wrote {path} ({path.stat().st_size / 1024:.0f} KiB)")


@plot_app.command("effects")
def effects_cmd(
    output: Output = Path("effects.png"),
    response: Annotated[
        str | None,
        typer.Option("--response", help="quantities, comma-separated: c,k (default: all)"),
    ] = None,
    axis: Axis = "x",
    table: DataOpt = None,
    as_json: Json = False,
) -> None:
    """Main-effect boxplots of each response against each factor's levels, medians in red.

    Example: designer plot effects --response k --axis x -o effects.png
    """
    from designer.plots import common, effects
    from designer.study.data import load_table

    _image_out(output)
    t = load_table(table)
    responses = common.responses_for(t, _quantities(response), axis)
    path = common.save_figure(effects.plot_effects(t, responses=responses), output)
    if as_json:
        print_json({"figure": str(path), "medians": effects.main_effects(t, responses).to_dict("records")})
    else:
        _saved(path)


@plot_app.command("heatmap")
def heatmap_cmd(
    output: Output = Path("heatmap.png"),
    axis: Annotated[
        str | None,
        typer.Option("--axis", help="only this axis' responses (default: all in the table)"),
    ] = None,
    table: DataOpt = None,
    as_json: Json = False,
) -> None:
    """Heat map of the Pearson correlations between the six factors and the responses.

    Example: designer plot heatmap -o heatmap.png
    """
    from designer.plots import common, heatmap
    from designer.study.data import load_table
    from designer.study.stats import correlation

    _image_out(output)
    t = load_table(table)
    responses = common.responses_for(t, None, axis)
    path = common.save_figure(heatmap.plot_heatmap(t, responses=responses), output)
    if as_json:
        print_json({"figure": str(path), "correlations": correlation(t, responses).to_dict()})
    else:
        _saved(path)


Surrogate = Annotated[
    Path | None,
    typer.Option("--surrogate", help="fitted surrogate JSON (designer fit); default: the bundled one"),
]


def _surrogate(path: Path | None):
    from designer.model.surrogate import Surrogate as _S

    return _S.load() if path is None else _S.load(path)


@plot_app.command("space")
def space_cmd(
    x: Annotated[str, typer.Option("--x", help="continuous factor on the first axis")] = "width",
    y: Annotated[str, typer.Option("--y", help="continuous factor on the second axis")] = "height",
    z: Annotated[str | None, typer.Option("--z", help="third factor (with --volume)")] = None,
    response: Annotated[str, typer.Option("--response", help="quantity: k or c")] = "k",
    axis: Axis = "x",
    fix: FixOpt = None,
    target: Annotated[
        float | None, typer.Option("--target", help="target value in rig units (N/mm, N.s/mm)")
    ] = None,
    volume: Annotated[bool, typer.Option("--volume", help="isosurfaces over --x, --y, --z")] = False,
    output: Output = Path("space.png"),
    html: Annotated[Path | None, typer.Option("--html", help="also write an interactive HTML scene")] = None,
    surrogate: Surrogate = None,
    as_json: Json = False,
) -> None:
    """The surrogate's response over two factors (others held) with its 95 % PI, the runs and the target.

    Example: designer plot space --x width --y height --response k --target 0.8 -o space.png --html space.html
    """
    from designer.errors import DesignerError
    from designer.plots import html3d, space

    _image_out(output)
    if target is not None and not target > 0:
        raise DesignerError(f"--target {target:g}", "give a positive target in rig units (N/mm, N.s/mm)")
    if html is not None:
        from designer.files import check_output

        check_output(html, suffixes=[".html", ".htm"])
    sur = _surrogate(surrogate)
    resp = f"{response}_{axis}"
    fixed = parse_fix(fix)
    with progress_bar("rendering") as bar:
        if volume:
            if z is None:
                raise DesignerError("--volume needs a third factor", "add --z, e.g. --z density")
            view = space.volume_view(sur, resp, factors=[x, y, z], fixed=fixed, target=target)
        else:
            if z is not None:
                raise DesignerError("--z draws only with --volume", "add --volume or drop --z")
            view = space.surface_view(sur, resp, x=x, y=y, fixed=fixed, target=target)
        plotter = space.render(view)
        files = [space.save_screenshot(plotter, output)]
        plotter.close()
        if html is not None:
            files.append(html3d.write_scene(view.scene, html))
        bar(1.0)
    if as_json:
        print_json(view.to_dict() | {"files": [str(f) for f in files]})
        return
    held = ", ".join(f"{k} {v:g}" for k, v in view.held.items())
    console.print(
        f"{resp} from {view.value_range[0]:.4g} to {view.value_range[1]:.4g} {view.unit} (held: {held})"
    )
    if not sur.model(resp).predictable:
        from designer.design.suggestions import predictability

        console.print(predictability(sur, axis)[response]["statement"])
    if target is not None:
        console.print(
            f"target {target:g} {view.unit} lies inside the 95 % PI over {view.target_in_pi:.0%} of the plot"
        )
    for f in files:
        _saved(f)


@plot_app.command("loo")
def loo_cmd(
    output: Output = Path("loo.png"),
    axis: Annotated[str | None, typer.Option("--axis", help="only this axis (default: all)")] = None,
    surrogate: Surrogate = None,
    as_json: Json = False,
) -> None:
    """Leave-one-out predictions against the measurements, with 95 % PIs, per response of the surrogate.

    Example: designer plot loo -o loo.png
    """
    from designer.errors import DesignerError
    from designer.plots import common, loo

    _image_out(output)
    sur = _surrogate(surrogate)
    responses = [r for r in sur.responses if axis is None or r.split("_", 1)[1] == axis]
    if not responses:
        raise DesignerError(
            f"the surrogate has no response on axis {axis}", f"it has {', '.join(sur.responses)}"
        )
    path = common.save_figure(loo.plot_loo(sur, responses=responses), output)
    # the figures the plot shows: nested leave-one-out (the form chosen again without each run) where
    # the surrogate has it; the selected form's own leave-one-out, optimistic, only as a second figure
    metrics = {
        r: {
            "form": sur.model(r).form,
            "nested": bool(sur.model(r).loo_nested),
            **sur.model(r).accuracy,
            "selected_form": dict(sur.model(r).loo),
        }
        for r in responses
    }
    # of a calibrated surrogate: the user's own prints, each predicted from every other run
    own = {r: d for r in responses if (d := loo.own_loo_table(sur, r)) is not None}
    if as_json:
        mine = {r: {**loo.own_accuracy(d), "runs": d.to_dict("records")} for r, d in own.items()}
        print_json({"figure": str(path), "loo": metrics} | ({"loo_user": mine} if own else {}))
        return
    for r, d in own.items():
        a = loo.own_accuracy(d)
        console.print(
            f"{r}: {loo.your_prints(a['n'])}, each predicted by the calibrated surrogate from the others: "
            f"median error {a['mape']:.0f} %, RMSE {a['rmse']:.3g} {sur.model(r).unit}, "
            f"95 % PI covers {int(d.covered.sum())} of {a['n']}"
        )
    whose = f"the study's {len(sur.table)} runs, " if own else ""
    for r, m in metrics.items():
        unit = sur.model(r).unit
        kind = "nested leave-one-out" if m["nested"] else "leave-one-out of the selected form (optimistic)"
        tail = f" (selected form alone: Q2 {m['selected_form']['q2']:.2f}, optimistic)" if m["nested"] else ""
        console.print(
            f"{r}: {whose}{m['form']}, {kind} Q2 {m['q2']:.2f}, RMSE {m['rmse']:.3g} {unit}, "
            f"95 % PI coverage {m['coverage95']:.0%}{tail}"
        )
    _saved(path)


@plot_app.command("timeseries")
def timeseries_cmd(
    series: Annotated[
        Path, typer.Argument(help="time series CSV or Parquet with a 't' column (designer cosim)")
    ],
    output: Output = Path("timeseries.png"),
    columns: Annotated[
        str | None, typer.Option("--columns", help="signals, comma-separated (default: all)")
    ] = None,
    reference: Annotated[Path | None, typer.Option("--reference", help="reference series to overlay")] = None,
    as_json: Json = False,
) -> None:
    """Co-simulation signals against time, one panel each, a reference dashed.

    Example: designer plot timeseries results/arm/timeseries.csv --columns robot.j1.q,robot.j2.q -o ts.png
    """
    from designer.plots import common, timeseries

    _image_out(output)
    frame = _read_series(series)
    ref = None if reference is None else _read_series(reference)
    cols = None if columns is None else [c.strip() for c in columns.split(",") if c.strip()]
    path = common.save_figure(timeseries.plot_timeseries(frame, columns=cols, reference=ref), output)
    if as_json:
        shown = cols or [c for c in frame.columns if c != "t"]
        print_json(
            {
                "figure": str(path),
                "rows": len(frame),
                "t": [frame["t"].iloc[0], frame["t"].iloc[-1]],
                "signals": {
                    c: {"min": frame[c].min(), "max": frame[c].max(), "final": frame[c].iloc[-1]}
                    for c in shown
                },
            }
        )
        return
    _saved(path)


def _read_series(path: Path):
    import pandas as pd

    from designer.errors import DesignerError

    if not path.is_file():
        raise DesignerError(f"no such file: {path}", "give a CSV or Parquet time series")
    try:
        from designer.study.data import read_frame

        return read_frame(path)
    except (ValueError, OSError, pd.errors.ParserError, UnicodeDecodeError) as exc:
        raise DesignerError(
            f"cannot read {path}: {str(exc).splitlines()[0]}", "give a CSV or Parquet file"
        ) from None


def validate_cmd(
    output: Annotated[
        Path, typer.Option("-o", "--output", help="folder for report.html, report.md, figures/")
    ] = Path("report"),
    table: DataOpt = None,
    as_json: Json = False,
) -> None:
    """Check the tool against the study and itself; write HTML and Markdown reports; exit 1 if a check fails.

    Example: designer validate -o report/
    """
    from designer.files import check_output_folder
    from designer.validate.report import validate

    check_output_folder(output, estimate_bytes=20e6)
    quiet_mujoco()
    with progress_bar("validating") as bar:
        results, page, md, seconds = validate(output, table=table, progress=bar)
    finishing()
    failed = [r for r in results if not r.passed]
    if as_json:
        print_json(
            {
                "passed": not failed,
                "seconds": seconds,
                "report": str(page),
                "checks": [r.to_dict() for r in results],
            }
        )
    else:
        for r in results:
            mark = "[green]PASS[/green]" if r.passed else "[red]FAIL[/red]"
            console.print(f"{mark} {escape(r.name)} ({r.seconds:.1f} s): {escape(r.summary)}", markup=True)
        console.print(
            f"{len(results) - len(failed)} of {len(results)} checks pass in {seconds:.1f} s; "
            f"wrote {page} and {md}"
        )
    if failed:
        raise typer.Exit(1)


def profile_cmd(
    output: Annotated[Path, typer.Option("-o", "--output", help="page to write (.html)")] = Path(
        "profiler.html"
    ),
    surrogate: Surrogate = None,
    axis: Axis = "x",
    target: Annotated[
        list[str] | None,
        typer.Option("--target", help="target in rig units, QUANTITY=VALUE (repeat): k=0.8, c=2e-3"),
    ] = None,
    tolerance: Annotated[
        float | None,
        typer.Option(
            "--tolerance",
            help="a joint meets its target within this many %; default the suggestion's, else 10",
        ),
    ] = None,
    suggestion: Annotated[
        Path | None,
        typer.Option("--suggestion", help="output of designer suggest --json: candidates to click"),
    ] = None,
    design: Annotated[
        list[str] | None,
        typer.Option(
            "--design", help="open at NAME=VALUE (repeat); default 60 %, 24, 4.5, 9, 0.16 mm, 0 deg"
        ),
    ] = None,
    as_json: Json = False,
) -> None:
    """An interactive prediction profiler: one self-contained HTML page (no server, no network).

    Sliders and typed values per factor, per response the prediction and its 95 % PI against each
    factor; goals (target, low and high limits, min, max) with the probability of meeting each and all
    of them; locks and "maximize" (the search of designer suggest, in the page); a contour view and a
    P trace; a print-noise simulator; remembered settings copied as export commands; suggestions to
    click. Opened with --suggestion, the page starts at its first candidate with its goals.

    Example: designer profile --target k=0.8 -o profiler.html
    """
    from designer.errors import DesignerError
    from designer.plots import profile
    from designer.study import space

    if tolerance is not None and not 0 < tolerance < 100:
        raise DesignerError(
            f"--tolerance {tolerance:g} is not a percentage in (0, 100)", "give e.g. --tolerance 10"
        )
    if suggestion is not None:
        _refuse_next_output(suggestion, surrogate)
    sur = _surrogate(surrogate)
    targets = parse_fix(target, flag="--target", example="k=0.8", names=None)
    start = parse_fix(design, flag="--design", example="width=3.5")
    page = profile.build_profiler(
        sur,
        axis=axis,
        targets=targets,
        tolerance=None if tolerance is None else tolerance / 100,
        suggestion=suggestion,
        design=start or None,
        surrogate_file=surrogate,
    )
    finishing()
    path = profile.write_profiler(page, output)
    opened = page.data["design"]
    if as_json:
        preds = sur.predict(opened, responses=[r["name"] for r in page.data["responses"]])
        print_json(
            {
                "page": str(path),
                "design": opened,
                "predicted": {r: p.at(0).to_dict() for r, p in preds.items()},
                "accuracy": {r["name"]: r["accuracy"] for r in page.data["responses"]},
                "suggestions": len(page.data["suggestions"]),
            }
        )
        return
    _saved(path)
    at = ", ".join(f"{k} {v:g} {space.factor(k).unit}" for k, v in opened.items())
    console.print(f"open it in a browser; it starts at {at}")


def _refuse_next_output(path: Path, surrogate: Path | None) -> None:
    """Refuse a `designer next --json` output given as --suggestion, naming the suggest command line
    with next's own goals that makes one (the library says why such a file is no suggestion)."""
    from designer.errors import DesignerError
    from designer.plots.profile import is_next_prints, suggestion_data

    data = suggestion_data(path)
    if not is_next_prints(data):
        return
    goals = [
        f"--{q} {v:g}" if isinstance(v, int | float) else f"--{q} {v}" for q, v in data["targets"].items()
    ]
    if data.get("axis", "x") != "x":
        goals.append(f"--axis {data['axis']}")
    if isinstance(data.get("tolerance"), int | float) and data["tolerance"] != 0.1:
        goals.append(f"--tolerance {100 * data['tolerance']:g}")
    if surrogate is not None:
        goals.append(f"--surrogate {surrogate}")
    raise DesignerError(
        f"--suggestion {path} is an output of designer next (a recommendation and prints to measure), "
        "not of designer suggest",
        f"make one with designer suggest {' '.join(goals)} --json > s.json and give --suggestion s.json",
    )


def register(app: typer.Typer) -> None:
    """Add `designer plot` and `designer profile` to the main app."""
    app.add_typer(plot_app, name="plot")
    app.command("validate")(validate_cmd)
    app.command("profile")(profile_cmd)
