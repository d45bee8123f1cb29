"""`designer cosim`: run a co-simulation scenario (robot with joint FMUs, or the virtual rig)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .common import console, finishing, print_json, progress, quiet_mujoco


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

    With --validate, exit 1 when the verdict is FAIL (the results are still written).

    Example: designer cosim examples/two_link_arm.toml -o results/ --validate
    """
    from designer.cosim import load, run, write_outputs
    from designer.cosim.run import OUTPUT_FILES
    from designer.files import check_output_folder

    quiet_mujoco()
    sc = load(scenario)
    check_output_folder(out, OUTPUT_FILES)
    with progress(f"co-simulating {scenario.name}", enabled=not json_out) as bar:
        result = run(sc, validate=validate, progress=bar, engine=engine)
    finishing()
    files = write_outputs(result, out)
    summary = result.summary() | {"files": [str(f) for f in files]}
    passed = _verdict(summary["validation"])[1] if summary.get("validation") else True
    if json_out:
        print_json(summary | ({"validation_passed": passed} if summary.get("validation") else {}))
    else:
        _print(summary)
    if not passed:  # a check failed: the negative answer's exit code (the outputs are written)
        raise typer.Exit(1)


def _verdict(val: dict) -> tuple[list[str], bool]:
    """What --validate found against what is expected, as lines, and whether it passed: at each
    macro step the co-simulation agrees with the same spring-damper inside MuJoCo to round-off, and
    its error against the fine reference falls at least first-order (Gauss-Seidel) as the step halves."""
    import math

    from designer.validate.cosim import COSIM_ORDER, COSIM_SAME_STEP

    steps = sorted(val["steps"], key=lambda r: -r["step"])
    ok = True
    lines = [
        f"validation against {val['reference']} (errors in rad, m on a translational axis):",
        f"  max error against the reference at the scenario's step: {val['max_error']:.3g}",
    ]
    for prev, row in zip([None, *steps], steps, strict=False):
        line = f"  step {row['step']:g} s: error {row['max_error']:.3g}"
        if prev is not None and prev["max_error"] > 0 and row["max_error"] > 0:
            order = math.log2(prev["max_error"] / row["max_error"]) / math.log2(prev["step"] / row["step"])
            good = order >= COSIM_ORDER
            ok &= good
            line += f", order {order:.2f} (expected >= {COSIM_ORDER:g}: {'pass' if good else 'FAIL'})"
        same = row.get("max_error_same_step")
        if same is not None:
            good = same <= COSIM_SAME_STEP
            ok &= good
            verdict = "pass" if good else "FAIL"
            line += f"; same-step MuJoCo {same:.1g} (expected <= {COSIM_SAME_STEP:g}: {verdict})"
        lines.append(line)
    lines.append(f"validation: {'pass' if ok else 'FAIL'}")
    return lines, ok


def _print_verdict(val: dict) -> bool:
    """Print `_verdict`'s lines; return whether the validation passed."""
    lines, ok = _verdict(val)
    for line in lines:
        console.print(line)
    return ok


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
        _print_verdict(val)
    for note in summary.get("notes", []):
        console.print(f"note: {note}")  # a note names TOML tables: [joints.j1] (the console takes no markup)
    ran = {"kernel": "the compiled kernel", "python": "the Python master"}[summary["engine"]]
    console.print(f"loop run by {ran}")
    for f in summary["files"]:
        console.print(f"wrote {f}")


def register(app: typer.Typer) -> None:
    app.command("cosim")(cosim)
