"""The runs table a batch of prints fills: one row per print id, its settings, and the measured
columns (named with their units) left empty until the rig's logs are identified.

The same file is the template `designer print` writes, the table `identify` fills from the prints'
rig logs (each log's JSON sidecar names its print: `{"print": "P1"}`), and the table `calibrate`
reads; a row still empty (a print not measured yet) is left out of a calibration and said so.
"""

from __future__ import annotations

import json
import os
import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from .. import units
from ..errors import DesignerError
from ..study import space
from ..study.data import canonical_columns, load_table, read_frame
from . import settings

#: the print id column
PRINT = "print"
#: the column of the log each row was identified from
LOG = "log"
#: factor columns as the template names them (the unit in brackets; load_table reads either form)
FACTOR_HEADERS = {f.name: f"{f.name} [{'%' if f.name == 'density' else f.unit}]" for f in space.FACTORS}


def coefficient_header(quantity: str, axis: str) -> str:
    """A measured column's name in the template, e.g. 'k_x [N/mm]'."""
    return f"{quantity}_{axis} [{units.rig_unit(quantity, axis)}]"


def template(prints: Sequence[tuple[str, dict[str, float]]], axis: str = "x") -> pd.DataFrame:
    """The runs table of `prints` ((id, settings) pairs): settings filled, k and c of `axis` empty."""
    rows = []
    for print_id, params in prints:
        row: dict[str, Any] = {PRINT: print_id}
        row |= {FACTOR_HEADERS[n]: params[n] for n in space.FACTOR_NAMES}
        row |= {coefficient_header(q, axis): np.nan for q in ("k", "c")}
        row[LOG] = ""
        rows.append(row)
    return pd.DataFrame(rows)


def next_ids(existing: pd.DataFrame | None, n: int, prefix: str = "P") -> list[str]:
    """`n` print ids continuing the `prefix`-numbered ids of an existing runs table (P1, P2, ...)."""
    used = [] if existing is None or PRINT not in existing.columns else list(existing[PRINT].astype(str))
    numbers = [
        int(m[1]) for u in used if (m := re.fullmatch(rf"{re.escape(prefix)}(\d+)", u.strip().upper()))
    ]
    start = max(numbers, default=0) + 1
    return [f"{prefix}{i}" for i in range(start, start + n)]


def read_runs(path: str | Path) -> pd.DataFrame:
    """A runs table as written (template or filled), its columns as in the file."""
    raw = read_frame(path)
    if PRINT not in raw.columns:
        raise DesignerError(
            f"{Path(path).name}: no '{PRINT}' column",
            "give the runs table designer print wrote (one row per print id)",
        )
    raw[PRINT] = raw[PRINT].astype(str).str.strip().str.upper()
    return raw


def measured(table: Any, source: str = "runs") -> tuple[pd.DataFrame, list[str]]:
    """The rows of a runs table that carry measurements, through `load_table`, and a note per print
    left out because nothing is measured in it yet.

    Raises:
        DesignerError: a row with one coefficient of an axis but not the other (identify gives both),
            or what `load_table` refuses (a missing column, a value that is not a number, ...).
    """
    raw = table if isinstance(table, pd.DataFrame) else read_frame(table)
    named = canonical_columns(raw, source=source)
    measured_cols = [c for c in named.columns if re.fullmatch(r"[ck]_(x|y|z|theta|phi|psi)", str(c))]
    if not measured_cols:
        return load_table(raw), []  # load_table names what is missing
    cells = named[measured_cols].notna() & named[measured_cols].astype(str).apply(
        lambda col: col.str.strip() != ""
    )
    empty = ~cells.any(axis=1)
    partial = cells.any(axis=1) & ~cells.all(axis=1)
    if partial.any():
        i = int(np.flatnonzero(partial.to_numpy())[0])
        missing = [c for c in measured_cols if not cells.iloc[i][c]]
        label = f" (print {raw[PRINT].iloc[i]})" if PRINT in raw.columns else ""
        raise DesignerError(
            f"{source}: row {i + 1}{label} has {', '.join(c for c in measured_cols if c not in missing)} "
            f"but no {', '.join(missing)}",
            "fill both k and c of the axis (designer identify writes both) or leave the row empty",
        )
    notes = []
    if empty.any():
        ids = (
            list(raw.loc[empty, PRINT].astype(str))
            if PRINT in raw.columns
            else [str(i + 1) for i in np.flatnonzero(empty)]
        )
        notes.append(f"not measured yet, left out: {', '.join(ids)}")
    kept = raw.loc[~empty].reset_index(drop=True)
    if kept.empty:
        raise DesignerError(
            f"{source}: no print is measured yet", "identify the prints' rig logs into it first"
        )
    return load_table(kept), notes


def settings_and_coefficients(table: pd.DataFrame) -> list[str]:
    """The columns of a loaded table that calibration reads: the six settings and the coefficients
    (the print ids and log paths ride along in the file, not into the model)."""
    from ..study.data import coefficient_columns

    return list(space.FACTOR_NAMES) + coefficient_columns(table)


def print_key(value: Any) -> str:
    """A print id as the runs table holds it, whoever typed it: 'p1 ' is 'P1'."""
    return str(value).strip().upper()


def sidecar_print(log: str | Path) -> str | None:
    """The print id a rig log's JSON sidecar names (`"print"`), or None."""
    from ..rig.logs import sidecar_path

    side = sidecar_path(log)
    if not side.exists():
        return None
    try:
        doc = json.loads(side.read_text())
    except (OSError, ValueError):
        return None  # read_log reports an unreadable sidecar
    value = doc.get("print") if isinstance(doc, dict) else None
    return None if value is None else print_key(value)


def fill(
    runs: pd.DataFrame, results: Sequence[Any], axis: str = "x", print_id: str | None = None
) -> tuple[pd.DataFrame, list[str]]:
    """`runs` with each passed log's k and c of `axis` written into the row of the print its sidecar
    names, and the ids filled.

    Args:
        runs: a runs table as `read_runs` gives it.
        results: `designer.rig.identify.Identification`s of the prints' logs (failed ones skipped).
        print_id: the print of the one log in `results`, for a log without a sidecar naming it (a
            rig's software that writes none); a sidecar that names another print is refused.

    Raises:
        DesignerError: a log whose sidecar names no print (and no `print_id`) or a print not in the
            table, `print_id` with several logs or against its sidecar, two logs of one print, a log
            whose sidecar factors differ from its print's row (prints mixed up), a log of a print
            measured already from another log (or by hand), or a log without `axis`.
    """
    if print_id is not None:
        print_id = print_key(print_id)
        if len(results) != 1:
            raise DesignerError(
                f"print_id='{print_id}' names the print of one log, and {len(results)} logs were given",
                "identify one log at a time with print_id=, or name each log's print in its sidecar",
            )
    out = runs.copy()
    factors = canonical_columns(runs.drop(columns=[PRINT]), source="runs")
    k_col, c_col = coefficient_header("k", axis), coefficient_header("c", axis)
    for col in (k_col, c_col, LOG):
        if col not in out.columns:
            out[col] = np.nan if col != LOG else ""
    out[LOG] = out[LOG].fillna("").astype(str)
    filled: list[str] = []
    for res in results:
        if not res.ok:
            continue
        named = sidecar_print(res.path) if res.path is not None else None
        if print_id is not None and named not in (None, print_id):
            raise DesignerError(
                f"{res.path}: its sidecar names print {named}, print_id='{print_id}'",
                "the prints may be mixed up: check the id engraved on the specimen",
            )
        pid = print_id or named
        if pid is None:
            raise DesignerError(
                f"{res.path}: its sidecar names no print",
                f"give print_id='P1' (the id engraved on the specimen), or write it into "
                f'{Path(str(res.path)).with_suffix(".json").name}: {{"print": "P1"}}',
            )
        rows = np.flatnonzero(out[PRINT].to_numpy() == pid)
        if not rows.size:
            raise DesignerError(
                f"{res.path}: print {pid} is not in the runs table ({', '.join(out[PRINT])})",
                "give the runs table of that batch, or fix the print id",
            )
        if pid in filled:
            raise DesignerError(f"two logs of print {pid}", "identify one log per print")
        i = int(rows[0])
        if res.factors is not None:
            table_row = {n: float(factors[n].iloc[i]) for n in space.FACTOR_NAMES}
            off = [n for n in space.FACTOR_NAMES if not _same_setting(n, res.factors, table_row)]
            if off:
                logged = ", ".join(f"{n} {res.factors[n]:g}" for n in off)
                raise DesignerError(
                    f"{res.path}: print {pid}'s sidecar gives {logged}, "
                    f"the runs table {', '.join(f'{n} {table_row[n]:g}' for n in off)}",
                    "the prints may be mixed up: check the id engraved on the specimen",
                )
        if axis not in res.axes:
            raise DesignerError(
                f"{res.path}: no {axis} axis identified", f"log the {axis} axis of print {pid}"
            )
        _check_not_measured(out, i, pid, (k_col, c_col), str(res.path))
        fit = res.axes[axis]
        out.loc[i, k_col], out.loc[i, c_col], out.loc[i, LOG] = fit.k, fit.c, str(res.path)
        filled.append(pid)
    return out, filled


def _check_not_measured(table: pd.DataFrame, i: int, pid: str, columns: tuple[str, str], log: str) -> None:
    """Refuse to replace row `i`'s measurement (`columns`) by another log than the one it came from:
    a log named with the wrong print would overwrite a measured print (one log per print)."""
    values = pd.to_numeric(table.loc[i, list(columns)], errors="coerce")
    source = str(table.loc[i, LOG])
    if values.isna().all() or (source and os.path.abspath(source) == os.path.abspath(log)):
        return
    held = ", ".join(f"{c} {v:.4g}" for c, v in values.items() if not np.isnan(v))
    raise DesignerError(
        f"{log}: print {pid} is measured already ({held}, {f'from {source}' if source else 'typed in'})",
        "the prints may be mixed up: check the id engraved on the specimen; to measure it again, "
        "empty its row's k, c and log first",
    )


def _same_setting(name: str, logged: dict[str, float], row: dict[str, float]) -> bool:
    """Whether a log's sidecar and the runs table give one print's setting `name`: equal to the
    hundredth, or, for the height, the design's height that `designer print` rounded to the whole
    layers it printed (the table holds the height printed, a rig's software may log the design's)."""
    if np.isclose(logged[name], row[name], atol=0.011):
        return True
    return (
        name == "height"
        and np.isclose(logged["layer"], row["layer"], atol=0.011)
        and np.isclose(settings.printed_height(logged[name], row["layer"]), row[name], atol=0.011)
    )


def table_axis(table: pd.DataFrame) -> str:
    """The axis whose k column a runs table has (the first in axis order; x when none)."""
    named = canonical_columns(table.drop(columns=[PRINT], errors="ignore"), source="runs")
    return next((a for a in units.AXES if f"k_{a}" in named.columns), "x")


def fill_file(
    path: str | Path,
    results: Sequence[Any],
    *,
    print_id: str | None = None,
    surrogate: Any = None,
    accept_implausible: bool = False,
) -> dict[str, list[str]]:
    """Fill the runs table at `path` (atomically) from identified logs (see `fill`, and its
    `print_id`), after checking each value against what a printer can give
    (`designer.model.plausibility`, with the study's surrogate unless `surrogate` is given; on a
    rotational axis the surrogate lacks, through `designer.model.rotational`'s relation).

    Returns:
        {"filled": ids filled now, "waiting": ids of the table still without a measurement}.
    """
    from ..model.plausibility import check_measured
    from ..model.rotational import with_axis
    from ..model.surrogate import Surrogate
    from ..study.data import write_frame

    table = read_runs(path)
    axis = table_axis(table)
    out, filled = fill(table, results, axis=axis, print_id=print_id)
    done = out[PRINT].isin(filled).to_numpy()
    if done.any():
        study = surrogate or Surrogate.load()
        check_measured(
            # a rotational table is compared through the relation `export --axis theta` uses
            with_axis(study.prior if study.calibration else study, axis),
            load_table(out.loc[done].reset_index(drop=True)),
            accept_implausible=accept_implausible,
        )
        write_frame(out, path)
    return {"filled": filled, "waiting": measured_rows(out)[1]}


def measured_rows(table: pd.DataFrame) -> tuple[list[str], list[str]]:
    """(ids with a measurement, ids without) of a runs table."""
    named = canonical_columns(table.drop(columns=[PRINT]), source="runs")
    cols = [c for c in named.columns if re.fullmatch(r"[ck]_(x|y|z|theta|phi|psi)", str(c))]
    given = named[cols].notna().any(axis=1).to_numpy() if cols else np.zeros(len(table), bool)
    ids = table[PRINT].astype(str).to_numpy()
    return list(ids[given]), list(ids[~given])
