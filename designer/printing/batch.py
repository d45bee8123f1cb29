"""A batch of prints from designs: ids, meshes, settings, and the files a printer and a rig need.

`designs_from` reads the designs of a `designer next --json` (its prints, or its recommendation
once it says to print it) or `designer suggest --json` (one candidate) output; `prepare` makes the
specimens, each beam's height in whole layers as the slicer prints it; `write_batch` writes the 3MF
plate, an STL and a PrusaSlicer `.ini` per print, and the runs table.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..errors import DesignerError
from ..study import space
from . import runs, settings
from .plate import write_plate
from .specimen import Clamp, Specimen, specimen


@dataclass(frozen=True)
class Batch:
    """Specimens ready to print and what changed on the way from the designs (`notes`)."""

    prints: list[Specimen]
    notes: list[str] = field(default_factory=list)


def designs_from(doc: Mapping[str, Any], candidate: int | None = None) -> list[dict[str, float]]:
    """The designs of a `designer next --json` or `designer suggest --json` output.

    `next`: every proposed print, or its recommendation when it proposes none (it says to print
    design #1). `suggest`: candidate `candidate` (1 = the best; default 1).

    Raises:
        DesignerError: neither output, or a candidate it does not hold.
    """
    if not isinstance(doc, Mapping):
        raise DesignerError(
            "the file is not a designer next or suggest JSON output",
            "give what designer next or designer suggest writes as JSON",
        )
    if "prints" in doc and "recommendation" in doc:
        if candidate is not None:
            raise DesignerError("candidate is for a suggest output", "a next output's prints are all printed")
        chosen = [p["params"] for p in doc["prints"]] or [doc["recommendation"]["params"]]
        return [dict(p) for p in chosen]
    if "candidates" in doc:
        n = 1 if candidate is None else candidate
        if not 1 <= n <= len(doc["candidates"]):
            raise DesignerError(
                f"candidate={n} is not in the suggestion (it holds {len(doc['candidates'])})",
                f"give candidate 1 to {len(doc['candidates'])}",
            )
        return [dict(doc["candidates"][n - 1]["params"])]
    raise DesignerError(
        "the file is neither a designer next nor a designer suggest JSON output",
        "give what designer next or designer suggest writes as JSON",
    )


def prepare(designs: Sequence[Mapping[str, Any]], ids: Sequence[str], clamp: Clamp | None = None) -> Batch:
    """The specimens of `designs` (the six settings; a density of "any", a solid section, prints
    at 100 %) with `ids`, each beam's height rounded to whole layers.

    Raises:
        DesignerError: a design that cannot be printed, an id that cannot be engraved, a beam that
            does not fit the clamp.
    """
    if len(ids) != len(designs):
        raise DesignerError(f"{len(ids)} ids for {len(designs)} designs", "give one id per design")
    prints, notes = [], []
    for print_id, design in zip(ids, designs, strict=True):
        params = {n: design[n] for n in space.FACTOR_NAMES if n in design}
        if params.get("density") == "any":
            params["density"] = 100.0
        params = space.check_design(params, allow_extrapolation=True)
        height = settings.printed_height(params["height"], params["layer"])
        if abs(height - params["height"]) > 1e-9:
            notes.append(
                f"{print_id}: height {params['height']:g} -> {height:g} mm, whole {params['layer']:g} mm "
                f"layers over the {settings.FIRST_LAYER_MM:g} mm first layer (the height the slicer prints)"
            )
            params["height"] = height
        density = settings.printed_density(params)
        if density != params["density"]:
            notes.append(
                f"{print_id}: sliced at {density:g} % infill, not {params['density']:g} %: its two "
                f"{space.WALL_MM:g} mm walls leave at most one line inside, a section the model "
                "predicts solid whatever the density"
            )
        prints.append(specimen(params, print_id, clamp))
    return Batch(prints=prints, notes=notes)


def write_batch(
    batch: Batch, folder: str | Path, *, runs_path: str | Path | None = None, axis: str = "x"
) -> dict[str, Any]:
    """Write the plate, each print's STL and PrusaSlicer `.ini`, and the runs table.

    The files go into `folder` (filled beside it and moved in at the end); the runs table is
    `folder/runs.csv`, or `runs_path`, to which the batch's rows are appended when it exists. A
    `folder/runs.csv` already there is kept as it is when it holds this batch (the same ids and
    settings: parts made again, its measurements stay), and refused otherwise.

    Raises:
        DesignerError: `folder/runs.csv` holds other prints (see `_holds_batch`), or `runs_path`
            holds one of the batch's ids.

    Returns:
        {"plate": path, "stl": [paths], "ini": [paths], "runs": path}.
    """
    from ..files import atomic_folder
    from ..study.data import write_frame

    existing = runs.read_runs(runs_path) if runs_path is not None and Path(runs_path).exists() else None
    rows = runs.template([(p.print_id, p.params) for p in batch.prints], axis=axis)
    if existing is not None:
        clash = sorted(set(existing[runs.PRINT]) & set(rows[runs.PRINT]))
        if clash:
            raise DesignerError(
                f"{runs_path} already holds print(s) {', '.join(clash)}",
                "give new print ids (or leave them to designer)",
            )
        rows = pd.concat([existing, rows], ignore_index=True)
    folder = Path(folder)
    table = Path(runs_path) if runs_path is not None else folder / "runs.csv"
    keep = runs_path is None and _holds_batch(table, rows)
    with atomic_folder(folder) as stage:
        write_plate(batch.prints, stage / "plate.3mf")
        for p in batch.prints:
            p.mesh.export(stage / f"{p.print_id}.stl")
            (stage / f"{p.print_id}.ini").write_text(settings.prusa_ini(p.params, p.print_id))
        if runs_path is None and not keep:
            write_frame(rows, stage / "runs.csv")
    if runs_path is not None:
        write_frame(rows, table)
    return {
        "plate": str(folder / "plate.3mf"),
        "stl": [str(folder / f"{p.print_id}.stl") for p in batch.prints],
        "ini": [str(folder / f"{p.print_id}.ini") for p in batch.prints],
        "runs": str(table),
    }


def _holds_batch(table: Path, rows: pd.DataFrame) -> bool:
    """Whether the runs table `table` in a batch's folder holds the batch of `rows` already (the
    same print ids and settings, measured or not), so that it is kept; False when there is none.

    Replacing any other table would lose what it holds: the measured k and c of prints already
    made, or the settings of specimens already engraved with the ids this batch would reuse.

    Raises:
        DesignerError: `table` holds other prints or other settings, naming those measured.
    """
    from ..study.data import canonical_columns

    if not table.exists():
        return False
    try:
        old = runs.read_runs(table)
        named = canonical_columns(old.drop(columns=[runs.PRINT]), source=str(table))
        same = list(old[runs.PRINT]) == list(rows[runs.PRINT]) and all(
            np.allclose(
                pd.to_numeric(named[n], errors="coerce"), rows[runs.FACTOR_HEADERS[n]], rtol=0, atol=1e-9
            )
            for n in space.FACTOR_NAMES
        )
    except (DesignerError, KeyError, ValueError, TypeError):
        old, same = None, False
    if same:
        return True
    held = "" if old is None else f" (prints {', '.join(old[runs.PRINT])}"
    if old is not None:
        done = runs.measured_rows(old)[0]
        held += f"; measured: {', '.join(done)})" if done else ")"
    raise DesignerError(
        f"{table} already holds another batch{held}, which this one would replace",
        f"append this batch to it with runs_path='{table}' (its ids continue), or write to another folder",
    )
