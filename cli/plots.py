"""`designer plot ...` and `designer validate`: figures of the data, the surrogate and the design space."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .common import console, print_json

plot_app = typer.Typer(
    help="Draw the data, the surrogate and the design space (PNG, SVG or PDF; headless).",
    no_args_is_help=True,
)

Output = Annotated[Path, typer.Option("-o", "--output", help="image file (.png .svg .pdf)")]
Table = Annotated[
    Path | None,
    typer.Option("--table", help="coefficient table (CSV/Parquet); default: the bundled 44 runs"),
]
Axis = Annotated[str, typer.Option("--axis", help="axis: x y z theta phi psi")]
Json = Annotated[bool, typer.Option("--json", help="print the plotted numbers as JSON")]


def _quantities(response: str | None) -> list[str] | None:
    """'c,k' -> ['c', 'k']; None -> every quantity the table has."""
    return None if response is None else [q.strip() for q in response.split(",") if q.strip()]


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
    table: Table = None,
    as_json: Json = False,
) -> None:
    """Main-effect boxplots of each response against each factor's levels, medians in red.

    Example: designer plot effects --response k --axis x -o effects.png
    """
    from designer.data import load_table
    from designer.plots import common, effects

    common.check_image_path(output)
    t = load_table(table)
    responses = common.responses_for(t, _quantities(response), axis)
    path = effects.plot_effects(t, responses, output)
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
    table: Table = None,
    as_json: Json = False,
) -> None:
    """Heat map of the Pearson correlations between the six factors and the responses.

    Example: designer plot heatmap -o heatmap.png
    """
    from designer.data import load_table
    from designer.plots import common, heatmap

    common.check_image_path(output)
    t = load_table(table)
    responses = common.responses_for(t, None, axis)
    path = heatmap.plot_heatmap(t, responses, output)
    if as_json:
        print_json({"figure": str(path), "correlations": heatmap.correlations(t, responses).to_dict()})
    else:
        _saved(path)


def validate_cmd(
    output: Annotated[
        Path, typer.Option("-o", "--output", help="folder for report.html, report.md, figures/")
    ] = Path("report"),
    table: Table = None,
    as_json: Json = False,
) -> None:
    """Check the tool against the study and itself; write HTML and Markdown reports; exit 1 if a check fails.

    Example: designer validate -o report/
    """
    from designer.report import validate

    from .common import progress

    with progress("validating") as bar:
        results, page, md, seconds = validate(output, table, progress=bar)
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
            console.print(f"{mark} {r.name} ({r.seconds:.1f} s): {r.summary}")
        console.print(
            f"{len(results) - len(failed)} of {len(results)} checks pass in {seconds:.1f} s; "
            f"wrote {page} and {md}"
        )
    if failed:
        raise typer.Exit(1)


def register(app: typer.Typer) -> None:
    """Add `designer plot` to the main app."""
    app.add_typer(plot_app, name="plot")
    app.command("validate")(validate_cmd)
