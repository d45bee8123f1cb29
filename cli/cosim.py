"""`designer cosim`: run a co-simulation scenario (robot with joint FMUs, or the virtual rig)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .common import console, print_json, progress


def cosim(
    scenario: Annotated[Path, typer.Argument(help="scenario file (TOML); see the README for its format")],
    out: Annotated[Path, typer.Option("-o", "--output", help="folder for the results")] = Path("results"),
    validate: Annotated[
        bool, typer.Option("--validate", help="compare with the reference at four steps")
    ] = False,
    json_out: Annotated[bool, typer.Option("--json", help="print metrics (and validation) as JSON")] = False,
    engine: Annotated[
        str,
        typer.Option(
            "--engine",
            help="auto: the compiled kernel when a C compiler is there, else python; kernel; python",
        ),
    ] = "auto",
) -> None:
    """Co-simulate joint FMUs with a MuJoCo robot or the virtual rig; write time series, metrics, plot.

    Example: designer cosim examples/two_link_arm.toml -o results/ --validate
    """
    from designer.cosim import load, run, write_outputs
    from designer.files import check_output_folder

    sc = load(scenario)
    check_output_folder(out)
    with progress(f"co-simulating {scenario.name}", enabled=not json_out) as bar:
        result = run(sc, validate=validate, progress=bar, engine=engine)
    files = write_outputs(result, out)
    summary = result.summary() | {"files": [str(f) for f in files]}
    if json_out:
        print_json(summary)
        return
    _print(summary)


def _print(summary: dict) -> None:
    from rich.table import Table

    if summary["kind"] == "rig":
        rig = summary["metrics"]["rig"]
        console.print(
            f"rig, axis {rig['axis']}: hub tracking RMS {rig['tracking_rms']:.4g} (SI), "
            f"peak load {rig['peak_load']:.4g} {rig['peak_load_unit']}"
        )
    else:
        table = Table(title=f"joints (step {summary['step']:g} s)")
        for col in ("joint", "tracking RMS", "peak deflection", "overshoot", "settling", "energy dissipated"):
            table.add_column(col, justify="right")
        for name, m in summary["metrics"].items():
            table.add_row(
                name,
                f"{m['tracking_rms_rad']:.4g} rad",
                f"{m['peak_deflection_rad']:.4g} rad",
                "-" if m["overshoot_pct"] is None else f"{m['overshoot_pct']:.3g} %",
                "-" if m["settling_time_s"] is None else f"{m['settling_time_s']:.4g} s",
                f"{m['energy_dissipated_J']:.4g} J",
            )
        console.print(table)
    val = summary.get("validation")
    if val:
        console.print(f"validation against {val['reference']}")
        console.print(f"  max error at the scenario's step: {val['max_error']:.3g} (rad or m)")
        for row in val["steps"]:
            console.print(f"  step {row['step']:.4g} s: max error {row['max_error']:.3g} (rad or m)")
    for note in summary.get("notes", []):
        console.print(f"note: {note}")
    ran = {"kernel": "the compiled kernel", "python": "the Python master"}[summary["engine"]]
    console.print(f"loop run by {ran}")
    for f in summary["files"]:
        console.print(f"wrote {f}")


def register(app: typer.Typer) -> None:
    app.command("cosim")(cosim)
