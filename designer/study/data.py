"""Coefficient tables: the schema, the loader with its checks, and the bundled study table.

A coefficient table has one row per specimen: the six factors (`density`, `length`, `width`,
`height`, `layer`, `raster`) and, per identified axis, `c_<axis>`, `k_<axis>` and optionally
`m_<axis>`, all in rig units (see `designer.units`). Column names may carry the study's unit
suffixes (`density_pct`, `k_x_N_per_mm`, ...) or a unit in brackets (`density [%]`, `k_x [N/mm]`,
as `designer print`'s runs table names them); a unit other than the table's is rejected.
"""

from __future__ import annotations

import hashlib
import os
import re
from importlib import resources
from pathlib import Path

import numpy as np
import pandas as pd

from .. import units
from ..errors import DesignerError, describe
from . import space

BUNDLED_NAME = "study_table3_x.csv"
#: the widest a printed joint's coefficients can be, per (quantity, rotational), rig units: far
#: beyond the study's (k_x 0.25-2.1 N/mm, c_x 5e-4-4.5e-3 N.s/mm); a value outside is a unit or
#: identification error, and a fit would carry it into every prediction
PLAUSIBLE = {
    ("k", False): (1e-6, 1e4),
    ("c", False): (1e-12, 1e3),
    ("m", False): (1e-9, 1e3),
    ("k", True): (1e-3, 1e9),
    ("c", True): (1e-9, 1e8),
    ("m", True): (1e-15, 1e3),
}

# accepted unit suffixes per factor and per (quantity, rotational)
_FACTOR_SUFFIXES = {
    "density": ("pct", "percent", "%"),
    "length": ("mm",),
    "width": ("mm",),
    "height": ("mm",),
    "layer": ("mm",),
    "raster": ("deg",),
}
_COEF_SUFFIXES = {
    ("k", False): ("N_per_mm", "N/mm"),
    ("c", False): ("Ns_per_mm", "N.s/mm", "N_s_per_mm"),
    ("m", False): ("kg",),
    ("k", True): ("Nmm_per_rad", "N.mm/rad", "N_mm_per_rad"),
    ("c", True): ("Nmms_per_rad", "N.mm.s/rad", "N_mm_s_per_rad"),
    ("m", True): ("kg_m2", "kg.m^2", "kgm2"),
}
_COEF_RE = re.compile(r"^(?P<q>[mck])_(?P<axis>x|y|z|theta|phi|psi)(?:_(?P<unit>.+))?$")


def bundled_path() -> Path:
    """Path of the study's 44-run table shipped inside the package."""
    return Path(str(resources.files("designer") / "bundled" / BUNDLED_NAME))


def coefficient_columns(table: pd.DataFrame) -> list[str]:
    """The canonical coefficient columns present (`c_x`, `k_x`, `m_theta`, ...), in axis order."""
    return [f"{q}_{a}" for a in units.AXES for q in units.QUANTITIES if f"{q}_{a}" in table.columns]


def axes_present(table: pd.DataFrame) -> list[str]:
    """Axes that have both c and k in the table."""
    return [a for a in units.AXES if f"c_{a}" in table.columns and f"k_{a}" in table.columns]


def _canonical_name(col: str, source: str) -> str | None:
    """Map a column name to its canonical name, checking any unit suffix (`length_mm`, or in
    brackets: `length [mm]`, `k_x [N/mm]`); None if not ours."""
    name = col.strip()
    bracketed = re.fullmatch(r"(\S+)\s*\[\s*(.+?)\s*\]", name)
    if bracketed:
        name = f"{bracketed[1]}_{bracketed[2]}"
    for fac, suffixes in _FACTOR_SUFFIXES.items():
        if name == fac:
            return fac
        if name.startswith(fac + "_"):
            suffix = name[len(fac) + 1 :]
            if suffix in suffixes:
                return fac
            raise DesignerError(
                f"{source}: column '{col}' gives {fac} in '{suffix}'",
                f"the table uses {space.factor(fac).unit}: convert the column and name it '{fac}'",
            )
    m = _COEF_RE.match(name)
    if not m:
        return None
    q, axis, unit = m["q"], m["axis"], m["unit"]
    if unit is not None and unit not in _COEF_SUFFIXES[(q, units.is_rotational(axis))]:
        raise DesignerError(
            f"{source}: column '{col}' gives {q}_{axis} in '{unit}'",
            f"the table uses {units.rig_unit(q, axis)}: convert the column and name it '{q}_{axis}'",
        )
    return f"{q}_{axis}"


def canonical_columns(raw: pd.DataFrame, *, source: str = "table") -> pd.DataFrame:
    """`raw` with unit-suffixed names (`k_x [N/mm]`, `length_mm`) renamed canonical, values untouched.

    Raises:
        DesignerError: a column in another unit, or two columns giving the same quantity.
    """
    mapping: dict[str, str] = {}
    for col in raw.columns:
        canon = _canonical_name(str(col), source)
        if canon is None:
            # a CSV reader names a repeated header 'k_x.1': the same quantity twice
            base = re.match(r"^(.*)\.\d+$", str(col))
            if base and base[1] in raw.columns and _canonical_name(base[1], source) is not None:
                raise DesignerError(f"{source}: the column '{base[1]}' appears twice", "keep one of them")
            continue
        if canon in mapping.values():
            raise DesignerError(f"{source}: two columns give '{canon}'", "keep one of them")
        mapping[col] = canon
    return raw.rename(columns=mapping)


def normalise(raw: pd.DataFrame, source: str = "table") -> pd.DataFrame:
    """Rename, check and order a raw table; raise DesignerError naming the first problem."""
    table = canonical_columns(raw, source=source)
    missing = [f for f in space.FACTOR_NAMES if f not in table.columns]
    if missing:
        raise DesignerError(
            f"{source}: missing factor column(s) {', '.join(missing)}",
            "a coefficient table needs density, length, width, height, layer, raster",
        )
    if not axes_present(table):
        alone = [c for c in coefficient_columns(table) if not c.startswith("m_")]
        if alone:
            pairs = ", ".join(f"{'c' if c[0] == 'k' else 'k'}{c[1:]}" for c in alone)
            raise DesignerError(
                f"{source}: {', '.join(alone)} without {pairs}",
                "give both k and c of an axis (designer identify writes both)",
            )
        raise DesignerError(
            f"{source}: no coefficient columns",
            "give c_<axis> and k_<axis> for at least one axis (x y z theta phi psi)",
        )
    if len(table) == 0:
        raise DesignerError(f"{source}: the table has no rows", "add at least one specimen")
    keep = list(space.FACTOR_NAMES) + coefficient_columns(table)
    extra = [c for c in table.columns if c not in keep]
    out = table[keep + extra].copy()
    for col in keep:
        values = pd.to_numeric(out[col], errors="coerce")
        bad = values.isna() | ~np.isfinite(values.to_numpy(dtype=float, na_value=np.nan))
        if bad.any():
            row = int(np.flatnonzero(bad.to_numpy())[0])
            raise not_a_number(source, col, row, out[col].iloc[row])
        out[col] = values.astype(float)
    for col in coefficient_columns(out):
        q, axis = col.split("_", 1)
        bad = out[col] <= 0 if q in ("k", "m") else out[col] < 0
        if bad.any():
            row = int(np.flatnonzero(bad.to_numpy())[0])
            raise DesignerError(
                f"{source}: column '{col}' row {row + 1} is {out[col].iloc[row]:g}; "
                + ("it must be positive" if q in ("k", "m") else "it must not be negative"),
                "check the identification of that run or remove it",
            )
        lo, hi = PLAUSIBLE[(q, units.is_rotational(axis))]
        odd = (out[col] > hi) | ((out[col] > 0) & (out[col] < lo))
        if odd.any():
            row = int(np.flatnonzero(odd.to_numpy())[0])
            unit = units.rig_unit(q, axis)
            raise DesignerError(
                f"{source}: column '{col}' row {row + 1} is {out[col].iloc[row]:.3g} {unit}, outside what a "
                f"printed joint can have ({lo:g} to {hi:g} {unit})",
                "check the units of that column and the identification of that run",
            )
    for f in space.CONTINUOUS:  # physically possible (positive, infill at most 100 %); ranges may extend
        for row, v in enumerate(out[f.name]):
            try:
                space.check_value(f.name, v, allow_extrapolation=True)
            except DesignerError as exc:
                raise DesignerError(f"{source}: row {row + 1}: {exc.problem}", exc.fix) from None
    for f in space.CATEGORICAL:
        levels = np.asarray(f.levels)
        off = ~np.isclose(out[f.name].to_numpy()[:, None], levels[None, :]).any(axis=1)
        if off.any():
            row = int(np.flatnonzero(off)[0])
            raise DesignerError(
                f"{source}: {f.name} = {out[f.name].iloc[row]:g} in row {row + 1} is not a level "
                f"of the study ({f.describe_range()})",
                "the surrogate treats it as categorical: use a tested level",
            )
    return out.reset_index(drop=True)


def load_table(source: str | Path | pd.DataFrame | None = None) -> pd.DataFrame:
    """A validated coefficient table: the six factors, then c_<axis>, k_<axis> (rig units).

    Args:
        source: a CSV or Parquet path (by suffix), a DataFrame, or None for the bundled study table
            (44 runs, x axis). Column names may carry units (`k_x [N/mm]`, `length_mm`).

    Returns:
        A new DataFrame, factor columns first, floats, index 0..n-1.

    Raises:
        DesignerError: naming the first problem with its column and row (missing factor, no
            coefficient column, a value that is not a finite number, k <= 0, c < 0, an untested level).
    """
    check_table_argument(source, "source")
    if isinstance(source, pd.DataFrame):
        return normalise(source, source="table")
    p = bundled_path() if source is None else Path(source)
    if not p.exists():
        raise DesignerError(f"no such table: {p}", "give the path of a CSV or Parquet file")
    try:
        raw = read_frame(p)
    except DesignerError:
        raise
    except (ValueError, OSError, pd.errors.ParserError, UnicodeDecodeError) as exc:
        raise DesignerError(
            f"cannot read {p}: {str(exc).splitlines()[0]}", "give a CSV or Parquet coefficient table"
        ) from None
    return normalise(raw, source=p.name)


def not_a_number(source: str, col: str, row: int, cell: object) -> DesignerError:
    """The error for a cell that is not a finite number (0-based `row`); a decimal comma is named."""
    if isinstance(cell, str) and re.fullmatch(r"\s*[-+]?\d*,\d+\s*", cell):
        return DesignerError(
            f"{source}: column '{col}' row {row + 1} is '{cell}': a decimal comma",
            "save the table with a decimal point (0.8, not 0,8) and commas between columns",
        )
    return DesignerError(
        f"{source}: column '{col}' row {row + 1} is '{cell}', not a finite number",
        "fix or remove that row (designer clean drops runs with missing sensor data)",
    )


def check_text_cells(raw: pd.DataFrame, columns: list[str], source: str) -> None:
    """Raise for the first cell of `columns` holding text that is not a number ('stiff', '0,8'); empty
    cells and NaN pass (missing sensor data, which designer clean drops as dropouts).

    Raises:
        DesignerError: naming the column, the row and the cell (a decimal comma by name).
    """
    for col in columns:
        values = pd.to_numeric(raw[col], errors="coerce")
        text = values.isna() & raw[col].notna()
        if text.any():
            row = int(np.flatnonzero(text.to_numpy())[0])
            raise not_a_number(source, col, row, raw[col].iloc[row])


def check_table_argument(value: object, name: str) -> None:
    """Raise unless `value` can be a table for `load_table`: a path, a DataFrame or None.

    Raises:
        DesignerError: naming the argument `name` (a numpy array, a list, a number...).
    """
    if value is None or isinstance(value, (str, os.PathLike, pd.DataFrame)):
        return
    raise DesignerError(
        f"{name} is {describe(value)}, not a table",
        f"give {name} as a pandas DataFrame with named columns (the six factors, then c_x, k_x...: "
        "pd.DataFrame(array, columns=[...])) or the path of a CSV or Parquet file",
    )


def is_parquet(path: str | Path) -> bool:
    """Whether a table path names Parquet (suffix .parquet or .pq); anything else is CSV."""
    return Path(path).suffix.lower() in (".parquet", ".pq")


def read_frame(path: str | Path) -> pd.DataFrame:
    """A CSV or Parquet file (by suffix) as a DataFrame, unvalidated (DesignerError naming a wrong
    delimiter, binary content or an empty file)."""
    from ..files import check_table_file

    check_table_file(path, parquet=is_parquet(path))
    if is_parquet(path):
        return pd.read_parquet(path)
    with open(path, "rb") as fh:  # Excel's "CSV (comma delimited)" may start with a line sep=,
        excel = fh.readline().lstrip(b"\xef\xbb\xbf").strip() == b"sep=,"
    return pd.read_csv(path, skiprows=1 if excel else 0)


def write_frame(frame: pd.DataFrame, path: str | Path) -> Path:
    """Write a table atomically as CSV or Parquet (by suffix)."""
    from ..files import atomic_path, atomic_write

    if is_parquet(path):
        with atomic_path(path) as tmp:
            frame.to_parquet(tmp, index=False)
    else:
        with atomic_write(path) as fh:
            frame.to_csv(fh, index=False)
    return Path(path)


def table_hash(table: pd.DataFrame) -> str:
    """SHA-256 of the factor and coefficient values, independent of column spelling and extras."""
    cols = list(space.FACTOR_NAMES) + coefficient_columns(table)
    h = hashlib.sha256(",".join(cols).encode())
    h.update(np.ascontiguousarray(table[cols].to_numpy(dtype=np.float64)).tobytes())
    return h.hexdigest()
