"""`designer print`: the designs to print as a 3MF plate, STL + PrusaSlicer settings per print, and
the runs table their measurements go into."""

from __future__ import annotations

import json
import shlex
from pathlib import Path
from typing import Annotated

import typer

from designer.errors import DesignerError

from .common import JsonOpt, console, design_text, finishing, print_json

_FACTOR_HELP = "one design's setting (give all six, or --from)"


def print_(
    output: Annotated[
        Path, typer.Option("-o", "--output", help="folder for the plate, STLs, .ini files (and runs.csv)")
    ],
    from_: Annotated[
        Path | None, typer.Option("--from", help="designer next --json (its prints) or suggest --json output")
    ] = None,
    candidate: Annotated[
        int | None, typer.Option(help="candidate of a suggest output (default 1, the best)")
    ] = None,
    density: Annotated[float | None, typer.Option(help=_FACTOR_HELP)] = None,
    length: Annotated[float | None, typer.Option(help=_FACTOR_HELP)] = None,
    width: Annotated[float | None, typer.Option(help=_FACTOR_HELP)] = None,
    height: Annotated[float | None, typer.Option(help=_FACTOR_HELP)] = None,
    layer: Annotated[float | None, typer.Option(help=_FACTOR_HELP)] = None,
    raster: Annotated[float | None, typer.Option(help=_FACTOR_HELP)] = None,
    ids: Annotated[
        list[str] | None,
        typer.Option("--id", help="print id to engrave, one per design (default P1, P2, ...)"),
    ] = None,
    runs: Annotated[
        Path | None,
        typer.Option(
            "--runs",
            help="runs table to append this batch to (ids continue its own); default OUTPUT/runs.csv",
        ),
    ] = None,
    axis: Annotated[
        str,
        typer.Option(
            "--axis",
            help="axis the rig measures, named in the runs table's k and c columns: x y z theta phi psi "
            "(the study's surrogate calibrates from x; a theta goal of next or suggest is derived from x: "
            "keep x)",
        ),
    ] = "x",
    block_length: Annotated[float, typer.Option(help="clamping block along the beam, mm")] = 12.0,
    block_width: Annotated[float, typer.Option(help="clamping block across the beam, mm")] = 20.0,
    block_height: Annotated[float, typer.Option(help="clamping block height, mm")] = 20.0,
    as_json: JsonOpt = False,
) -> None:
    """Print-ready parts: a 3MF plate with every print of the batch, each object with its own slicer
    settings (PrusaSlicer and OrcaSlicer / Bambu Studio), an STL and a PrusaSlicer .ini per print,
    and the runs table with the measured columns empty.

    Each specimen is the study's beam (length, width, height) between two clamping blocks, the print
    id engraved on the first block; layer height, infill density and angle (the raster) are the
    design's; cubic infill (rectilinear at 100 %), two 0.4 mm perimeters (0.8 mm shell), TPU at
    210 C on a 60 C bed.

    Example: designer next --k 0.8 --n 3 --json > next.json && designer print --from next.json -o prints
    """
    from designer.files import check_output, check_output_folder
    from designer.printing import batch
    from designer.printing import runs as runs_table
    from designer.printing.specimen import Clamp

    check_output_folder(output)
    if runs is not None:
        check_output(runs, suffixes=(".csv", ".parquet", ".pq"))
    given = dict(density=density, length=length, width=width, height=height, layer=layer, raster=raster)
    designs = _designs(from_, candidate, given)
    existing = runs_table.read_runs(runs) if runs is not None and runs.exists() else None
    names = list(ids) if ids else runs_table.next_ids(existing, len(designs))
    clamp = Clamp(length=block_length, width=block_width, height=block_height)
    made = batch.prepare(designs, names, clamp)
    finishing()
    files = batch.write_batch(made, output, runs_path=runs, axis=axis)
    data = {
        "prints": [{"print": p.print_id, "params": p.params} for p in made.prints],
        "notes": made.notes,
        "files": files,
    }
    if as_json:
        print_json(data)
    else:
        _print_batch(data)


def _designs(from_: Path | None, candidate: int | None, given: dict) -> list[dict]:
    """The designs to print: those of --from, or the one design of the six settings."""
    from designer.printing import batch

    one = {n: v for n, v in given.items() if v is not None}
    if from_ is not None and one:
        raise DesignerError(
            "both --from and design settings are given", "give --from FILE or the six settings"
        )
    if from_ is not None:
        return batch.designs_from(_read_json(from_), candidate)
    if len(one) < 6:
        missing = ", ".join(f"--{n}" for n, v in given.items() if v is None)
        raise DesignerError(f"missing {missing}", "give all six settings, or --from next.json")
    return [one]


def _print_batch(data: dict) -> None:
    for p in data["prints"]:
        v = p["params"]
        console.print(f"{p['print']}: {design_text(v)}")
    for note in data["notes"]:
        console.print(f"- {note}")
    files = data["files"]
    console.print(
        f"plate: {files['plate']} (PrusaSlicer, OrcaSlicer or Bambu Studio: each object carries its settings)"
    )
    console.print(
        f"per print: {', '.join(Path(s).name for s in files['stl'])} with the .ini of the same name"
    )
    console.print(
        f"runs table: {files['runs']}; after the rig, name the print in each log's sidecar "
        '({"print": "P1"}) and run designer identify LOGS --runs ' + shlex.quote(files["runs"])
    )


def _read_json(path: Path) -> dict:
    if not path.exists():
        raise DesignerError(
            f"no such file: {path}", "give the output of designer next --json or suggest --json"
        )
    try:
        return json.loads(path.read_text())
    except (OSError, ValueError, UnicodeDecodeError) as exc:
        raise DesignerError(
            f"cannot read {path}: {exc}", "give the output of designer next --json or suggest --json"
        ) from None


def register(app: typer.Typer) -> None:
    app.command("print")(print_)
