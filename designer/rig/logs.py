"""Rig logs: the schema, a validating reader and an atomic writer (CSV or Parquet).

A log has a time column `t` [s], per axis its coordinate (`x y z` [mm], `theta phi psi` [rad]) and
its load (`Fx Fy Fz` [N], `Ttheta Tphi Tpsi` [N.mm]), any subset of axes, and optionally the hub
angle `hub` [rad]. A column may carry its unit as `x [mm]` or `x_mm`; another unit is rejected.
The specimen's six factors live in a JSON sidecar beside the log: `run7.csv` -> `run7.json`
holding `{"factors": {"density": 60, "length": 24, ...}}`; the sidecar may also give
`"load_delay_s"`, how many seconds the load channel lags the position channels (identification
corrects it).
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from .. import units
from ..errors import DesignerError
from ..files import atomic_path, atomic_write
from ..keys import check_keys
from ..study import space
from ..study.data import is_parquet
from . import channel, log_header, saturation

#: the load column of each axis
LOAD: dict[str, str] = {
    "x": "Fx",
    "y": "Fy",
    "z": "Fz",
    "theta": "Ttheta",
    "phi": "Tphi",
    "psi": "Tpsi",
}
#: the unit of every column the schema knows
UNITS: dict[str, str] = {
    "t": "s",
    "hub": "rad",
    **{a: units.rig_unit("r", a) for a in units.AXES},
    **{LOAD[a]: units.rig_unit("F", a) for a in units.AXES},
}
#: the largest magnitude a printed joint's rig can log per unit (far beyond any bench rig: a value
#: above it is a unit or logger error, and identification would return an impossible coefficient)
PLAUSIBLE: dict[str, float] = {"mm": 1e4, "rad": 1e3, "N": 1e6, "N.mm": 1e9}
#: spellings of each unit accepted in a column suffix
_UNIT_SPELLINGS: dict[str, tuple[str, ...]] = {
    "s": ("s",),
    "rad": ("rad",),
    "mm": ("mm",),
    "N": ("N",),
    "N.mm": ("N.mm", "Nmm", "N*mm", "N_mm"),
}
#: a sensor reading exactly zero for at least this many samples is taken as stuck
STUCK_SAMPLES = 5
#: sampling intervals longer than this multiple of the median mark a gap
GAP_FACTOR = 1.5
#: the largest relative spread of sampling intervals (outside gaps) a log may have
JITTER_LIMIT = 0.05
_SUFFIX_RE = re.compile(r"^(?P<name>[A-Za-z]+)(?:\s*\[(?P<b>[^\]]+)\]|_(?P<u>.+))?$")


@dataclass
class RigLog:
    """A validated log: canonical columns, sampling rate, factors and flagged dropout rows per axis."""

    data: pd.DataFrame
    path: Path | None
    factors: dict[str, float] | None
    rate: float
    axes: list[str]
    #: per axis, True where the coordinate or the load is NaN, stuck at zero, or beside a time gap
    dropouts: dict[str, np.ndarray] = field(default_factory=dict)
    #: seconds by which the load channels lag the position channels (from the sidecar), if known
    load_delay_s: float | None = None
    #: the load sensor's low-pass from the sidecar, e.g. "butter2:200Hz" (checked when identified)
    load_filter: str | None = None
    #: per axis column, the fraction of samples the sensor did not deliver (NaN or stuck at zero)
    missing_fraction: dict[str, float] = field(default_factory=dict)
    #: per axis column, the rails it sits on (`saturation.Rail`) when the sensor saturated; those
    #: samples are flagged as dropouts
    rails: dict[str, list[saturation.Rail]] = field(default_factory=dict)
    #: what reading changed in the log, for people (e.g. coarse timestamps rebuilt)
    notes: list[str] = field(default_factory=list)

    @property
    def duration(self) -> float:
        t = self.data["t"].to_numpy()
        return float(t[-1] - t[0])

    def dropout_segments(self, axis: str) -> list[tuple[int, int]]:
        """Flagged (first row, last row) spans of `axis`, 1-based data rows as in the file."""
        mask = self.dropouts[axis].astype(np.int8)
        edges = np.flatnonzero(np.diff(np.concatenate(([0], mask, [0]))))
        return [(int(a) + 1, int(b)) for a, b in zip(edges[::2], edges[1::2], strict=True)]

    def summary(self) -> dict:
        """Plain-data description for printing and JSON."""
        return {
            "path": None if self.path is None else str(self.path),
            "rows": len(self.data),
            "rate_hz": self.rate,
            "duration_s": self.duration,
            "axes": self.axes,
            "factors": self.factors,
            "dropout_fraction": {a: float(self.dropouts[a].mean()) for a in self.axes},
            "dropout_segments": {a: len(self.dropout_segments(a)) for a in self.axes},
        }


#: keys a sidecar may hold: the six factors, the load channel's lag behind the positions (s), the
#: load sensor's filter, and the id of the print logged (`designer print`'s runs table)
SIDECAR_KEYS = ("factors", "load_delay_s", "load_filter", "print")


def sidecar_path(path: str | Path) -> Path:
    """The JSON sidecar holding a log's factors: the log's path with the suffix `.json`."""
    return Path(path).with_suffix(".json")


def _canonical(col: str, source: str) -> str | None:
    """Canonical name of a log column, checking any unit suffix; None for columns not in the schema."""
    m = _SUFFIX_RE.match(str(col).strip())
    if not m or m["name"] not in UNITS:
        return None
    name, unit = m["name"], m["b"] or m["u"]
    if unit is not None and unit.strip() not in _UNIT_SPELLINGS[UNITS[name]]:
        raise DesignerError(
            f"{source}: column '{col}' is in unknown or wrong units '{unit}'",
            f"the rig log gives {name} in {UNITS[name]}: convert it and name the column '{name}'",
        )
    return name


def _first_bad_row(bad: np.ndarray) -> int:
    return int(np.flatnonzero(bad)[0]) + 1


def _run_bounds(mask: np.ndarray, min_len: int) -> tuple[np.ndarray, np.ndarray]:
    """First and one-past-last rows of the runs of True at least `min_len` long (work in proportion
    to the True rows)."""
    rows = np.flatnonzero(mask)
    if rows.size < min_len:
        return np.zeros(0, dtype=np.intp), np.zeros(0, dtype=np.intp)
    breaks = np.flatnonzero(np.diff(rows) > 1)
    starts = rows[np.concatenate(([0], breaks + 1))]
    ends = rows[np.concatenate((breaks, [rows.size - 1]))] + 1
    long = ends - starts >= min_len
    return starts[long], ends[long]


def _runs(mask: np.ndarray, min_len: int) -> np.ndarray:
    """Rows inside runs of True at least `min_len` long."""
    out = np.zeros(mask.shape, dtype=bool)
    for a, b in zip(*_run_bounds(mask, min_len), strict=True):
        out[a:b] = True
    return out


def missing(values: np.ndarray) -> np.ndarray:
    """Samples a sensor did not deliver: NaN or infinite, inside a run stuck at exactly zero, or an
    exact zero in a channel that is not quantized (a noisy analogue reading is never exactly 0.0, so
    a single zero is a glitch; on an ADC's integer counts a zero is a reading like any other).

    On a quantized channel a run of zeros entered and left from one step either side is a reading
    too: a coarse encoder reads 0 while the position crosses its middle count (a 0.1 mm encoder on a
    1.85 Hz, 1.5 mm motion for 6 ms, longer at lower frequencies); a stuck sensor jumps to 0.
    """
    zero = values == 0.0
    quantized = bool(zero.any()) and _quantized(values)
    out = ~np.isfinite(values)
    starts, ends = _run_bounds(zero, STUCK_SAMPLES)
    if quantized and starts.size:
        keep = ~_crossing_zero(values, starts, ends)
        starts, ends = starts[keep], ends[keep]
    for a, b in zip(starts, ends, strict=True):
        out[a:b] = True
    if zero.any() and not quantized:
        out |= zero
    return out


def _crossing_zero(values: np.ndarray, starts: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """Per zero run of a quantized channel, whether it is entered and left within one quantization
    step of zero (a reading as the signal passes), not from further away (a sensor dropping to 0).
    A run at either end of the log is judged by its one neighbour; NaN neighbours tell nothing."""
    sample = values[:: max(values.size // 2000, 1)]
    levels = np.unique(sample[np.isfinite(sample)])
    steps = np.diff(levels)
    step = float(steps.min()) if steps.size else 0.0
    n = values.size
    before = np.where(starts > 0, values[np.maximum(starts - 1, 0)], np.nan)
    after = np.where(ends < n, values[np.minimum(ends, n - 1)], np.nan)
    near = 1.5 * step
    with np.errstate(invalid="ignore"):
        ok_before = np.isnan(before) | (np.abs(before) <= near)
        ok_after = np.isnan(after) | (np.abs(after) <= near)
    return ok_before & ok_after & ~(np.isnan(before) & np.isnan(after)) & (step > 0)


def _quantized(values: np.ndarray, probe: int = 2000) -> bool:
    """Whether the channel takes few distinct values (an ADC's steps): judged on an even sample."""
    sample = values[:: max(values.size // probe, 1)]
    sample = sample[np.isfinite(sample)]
    return np.unique(sample).size < 0.5 * sample.size


def _check_factors(factors: dict | None, source: str) -> dict[str, float] | None:
    if factors is None:
        return None
    try:
        return space.check_design(factors, allow_extrapolation=True)
    except DesignerError as exc:
        raise DesignerError(f"{source}: {exc.problem}", exc.fix) from None


def _read_sidecar(path: Path) -> tuple[dict[str, float] | None, float | None, str | None]:
    """The sidecar's factors, load delay (s) and load filter, each None when not given."""
    side = sidecar_path(path)
    if not side.exists():
        return None, None, None
    try:
        doc = json.loads(side.read_text())
    except (OSError, ValueError) as exc:
        raise DesignerError(f"cannot read {side}: {exc}", 'write it as {"factors": {...}}') from None
    form = 'write it as {"factors": {"density": 60, ...}, "load_delay_s": 0.002}'
    if isinstance(doc, dict):
        check_keys(doc, SIDECAR_KEYS, where=side.name)
    if not isinstance(doc, dict) or not any(key in doc for key in SIDECAR_KEYS):
        raise DesignerError(f"{side}: none of 'factors', 'load_delay_s', 'load_filter'", form)
    if "factors" in doc and not isinstance(doc["factors"], dict):
        raise DesignerError(f"{side}: 'factors' is not an object", form)
    delay = doc.get("load_delay_s")
    if delay is not None and (
        isinstance(delay, bool) or not isinstance(delay, (int, float)) or not np.isfinite(delay)
    ):
        raise DesignerError(f"{side}: load_delay_s = {delay!r} is not a number of seconds", form)
    lowpass = doc.get("load_filter")
    if lowpass is not None:
        try:
            lowpass = str(channel.parse(lowpass, where="load_filter"))
        except DesignerError as exc:
            raise DesignerError(f"{side}: {exc.problem}", exc.fix) from None
    return _check_factors(doc.get("factors"), side.name), None if delay is None else float(delay), lowpass


def validate_frame(
    raw: pd.DataFrame, source: str = "log", factors: dict | None = None, path: Path | None = None
) -> RigLog:
    """Check a log's columns, time and units, flag dropouts; raise DesignerError naming column and row."""
    df, axes = _columns(raw, source)
    cols = _numbers(df, source)
    notes: list[str] = []
    step, gaps = _time_step(cols, source, notes)
    gap_rows = np.zeros(len(cols["t"]), dtype=bool)
    gap_rows[1:] |= gaps
    gap_rows[:-1] |= gaps
    _check_magnitudes(cols, axes, source)
    dropouts, fractions, rails = {}, {}, {}
    for a in axes:
        dropouts[a] = _dropouts(cols, a, gap_rows, fractions, source)
        for col in (a, LOAD[a]):
            found = saturation.rails(cols[col])
            if found:
                rails[col] = found
                dropouts[a] |= saturation.on_rails(cols[col], found)
    order = ["t"] + [c for a in axes for c in (a, LOAD[a])] + (["hub"] if "hub" in cols else [])
    return RigLog(
        # one block per column, sharing the arrays: no consolidating copy of a long log
        data=pd.DataFrame({c: cols[c] for c in order}, copy=False),
        path=path,
        factors=_check_factors(factors, source),
        rate=1.0 / step,
        axes=axes,
        dropouts=dropouts,
        missing_fraction=fractions,
        rails=rails,
        notes=notes,
    )


def _check_magnitudes(cols: dict[str, np.ndarray], axes: list[str], source: str) -> None:
    """Raise for a position or load beyond what a printed joint's rig can see (PLAUSIBLE)."""
    for col in [c for a in axes for c in (a, LOAD[a])]:
        unit = UNITS[col]
        with np.errstate(invalid="ignore"):
            big = np.abs(cols[col]) > PLAUSIBLE[unit]
        big &= np.isfinite(cols[col])
        if big.any():
            row = _first_bad_row(big)
            raise DesignerError(
                f"{source}: column '{col}' row {row} is {cols[col][row - 1]:.3g} {unit}, beyond any "
                f"printed joint's rig (at most {PLAUSIBLE[unit]:g} {unit})",
                f"check the logger's scale and units (the log's are {unit}) or remove the corrupt rows",
            )


def _columns(raw: pd.DataFrame, source: str) -> tuple[pd.DataFrame, list[str]]:
    """The log's known columns under their canonical names, and the axes that have both r and load."""
    mapping: dict[str, str] = {}
    for col in raw.columns:
        name = _canonical(col, source)
        if name is None:
            continue
        if name in mapping.values():
            raise DesignerError(f"{source}: two columns give '{name}'", "keep one of them")
        mapping[col] = name
    df = raw[list(mapping)].rename(columns=mapping)
    if "t" not in df.columns:
        raise DesignerError(
            f"{source}: missing column 't'{_columns_found(raw)}",
            "a rig log needs the time t in s: name the columns as the schema does (t, x/Fx, ..., a unit as "
            "'x [mm]' or 'x_mm')",
        )
    axes = []
    for a in units.AXES:
        have_r, have_f = a in df.columns, LOAD[a] in df.columns
        if have_r != have_f:
            absent = LOAD[a] if have_r else a
            raise DesignerError(
                f"{source}: missing column '{absent}' ({UNITS[absent]}) for axis {a}",
                f"give both {a} and {LOAD[a]}, or neither",
            )
        if have_r:
            axes.append(a)
    if not axes:
        raise DesignerError(
            f"{source}: no axis columns{_columns_found(raw)}",
            "give at least one coordinate and its load: x/Fx, y/Fy, z/Fz, theta/Ttheta, phi/Tphi, psi/Tpsi",
        )
    if len(df) < 3:
        raise DesignerError(f"{source}: only {len(df)} rows", "a rig log needs a time series")
    return df, axes


def _columns_found(raw: pd.DataFrame, most: int = 8) -> str:
    """' (its columns are ...)': what a log that lacks the schema's columns has instead."""
    names = [repr(str(c)) for c in raw.columns[:most]]
    more = f" and {len(raw.columns) - most} more" if len(raw.columns) > most else ""
    return f" (its columns are {', '.join(names)}{more})" if names else " (it has no columns)"


def _numbers(df: pd.DataFrame, source: str) -> dict[str, np.ndarray]:
    """Every column as float64; a cell that is text and not a number is an error naming its row."""
    cols = {}
    for col in df.columns:
        values = df[col]
        if values.dtype.kind not in "fiu":
            numeric = pd.to_numeric(values, errors="coerce")
            bad = numeric.isna().to_numpy() & values.notna().to_numpy()
            if bad.any():
                row = _first_bad_row(bad)
                raise DesignerError(
                    f"{source}: column '{col}' row {row} is '{values.iloc[row - 1]}', not a number",
                    "fix that row or leave it empty (an empty value counts as a dropout)",
                )
            values = numeric
        cols[col] = values.to_numpy(dtype=np.float64)
    return cols


def _time_step(cols: dict[str, np.ndarray], source: str, notes: list[str]) -> tuple[float, np.ndarray]:
    """The sample interval (median) and the gaps; time must be finite, increasing and regular.

    Timestamps from a clock coarser than the sampling (repeated or uneven only by their rounding)
    are rebuilt from the sample index, in place in `cols`, and a note says so.
    """
    t = cols["t"]
    if not np.isfinite(t).all():
        raise DesignerError(
            f"{source}: column 't' row {_first_bad_row(~np.isfinite(t))} is empty or not finite",
            "every row needs its time",
        )
    dt = np.diff(t)
    if (dt <= 0).any():
        rebuilt = _rebuilt_time(t, notes)
        if rebuilt is not None:
            cols["t"] = rebuilt
            return _time_step(cols, source, notes)
        row = int(np.flatnonzero(dt <= 0)[0]) + 2
        what = "repeated" if dt[row - 2] == 0 else "going backwards"
        backwards = int(np.count_nonzero(dt < 0))
        reversed_log = backwards > dt.size // 2
        raise DesignerError(
            f"{source}: time {what} at row {row} (t = {t[row - 1]:g} s after {t[row - 2]:g} s)"
            + (
                f"; it decreases in {backwards} of {dt.size} steps (the log is reversed)"
                if reversed_log
                else ""
            ),
            "sort the log by t and remove repeated rows"
            if not reversed_log
            else "reverse the rows (sort by t)",
        )
    step = float(np.median(dt))
    gaps = dt > GAP_FACTOR * step
    regular = dt[~gaps]
    jitter = float(np.max(np.abs(regular - step)) / step) if regular.size else 0.0
    if jitter > JITTER_LIMIT or gaps.any():
        rebuilt = _rebuilt_time(t, notes)
        if rebuilt is not None:
            cols["t"] = rebuilt
            return _time_step(cols, source, notes)
    if jitter > JITTER_LIMIT:
        row = int(np.flatnonzero(~gaps & (np.abs(dt - step) > JITTER_LIMIT * step))[0]) + 2
        raise DesignerError(
            f"{source}: irregular sampling in column 't' at row {row} "
            f"(interval {dt[row - 2]:g} s against {step:g} s)",
            "resample the log to a constant rate",
        )
    if gaps.any():
        notes.append(_gaps_note(dt, gaps, step))
    return step, gaps


def _gaps_note(dt: np.ndarray, gaps: np.ndarray, step: float) -> str:
    """The note on time gaps: how many, the longest with its row, and the samples missing."""
    rows = np.flatnonzero(gaps)
    longest = int(rows[np.argmax(dt[rows])])
    lost = int(np.round(dt[rows] / step).sum()) - rows.size
    return (
        f"t has {rows.size} gap{'s' if rows.size > 1 else ''} (the longest {dt[longest]:.3g} s, after row "
        f"{longest + 1}; about {lost} samples missing): the rows around each are left out of the fit"
    )


#: timestamps count as a coarse clock's when they spread at most this many resolutions about a
#: constant rate (rounding or truncation spread one, plus the fit's own error) ...
COARSE_CLOCK_SPREAD = 1.02
#: ... and the resolution differs from the sampling interval by at least this fraction (a repeated
#: or missing row of a log on a fine clock spreads one interval too)
COARSE_CLOCK_MARGIN = 0.05


def _rebuilt_time(t: np.ndarray, notes: list[str]) -> np.ndarray | None:
    """t rebuilt from the sample index at a constant rate, when the log's clock was only coarse.

    That is: t never decreases, every interval is a whole number of one resolution (the smallest
    interval), the resolution is not the sampling interval itself, and the timestamps spread at
    most one resolution about the straight line through them (what rounding or truncation leave;
    a repeated row, a gap or real jitter spread further). None when t is not such a log; else the
    rebuilt t, with a note appended to `notes`.
    """
    dt = np.diff(t)
    positive = dt[dt > 0]
    if (dt < 0).any() or positive.size == 0:
        return None
    resolution = float(positive.min())
    steps = dt / resolution
    if np.max(np.abs(steps - np.round(steps))) > 1e-6:
        return None
    index = np.arange(t.size, dtype=np.float64)
    centred = index - index.mean()
    interval = float(centred @ (t - t.mean()) / (centred @ centred))
    line = t.mean() + interval * centred
    spread = float(np.ptp(t - line)) / resolution
    if interval <= 0 or abs(resolution / interval - 1) < COARSE_CLOCK_MARGIN or spread > COARSE_CLOCK_SPREAD:
        return None
    repeated = int(np.count_nonzero(dt == 0))
    notes.append(
        f"t is on a {resolution:.3g} s clock"
        + (f" ({repeated} repeated timestamps)" if repeated else "")
        + f": rebuilt from the sample index at {1.0 / interval:.6g} Hz (the logged times lie in a band "
        f"{spread:.2g} clock steps wide about it)"
    )
    return line


def _dropouts(
    cols: dict[str, np.ndarray], a: str, gap_rows: np.ndarray, fractions: dict[str, float], source: str
) -> np.ndarray:
    """Rows of axis `a` to leave out (gaps, empty or stuck samples); records each column's missing share."""
    flagged = gap_rows.copy()
    for col in (a, LOAD[a]):
        v = cols[col]
        if not np.isfinite(v).any():
            what = "infinite" if np.isinf(v).all() else "NaN or infinite" if np.isinf(v).any() else "NaN"
            raise DesignerError(f"{source}: column '{col}' is all {what}", f"drop axis {a} or fix the sensor")
        absent = missing(v)
        fractions[col] = float(absent.mean())
        flagged |= absent
    if flagged.all():
        raise DesignerError(
            f"{source}: axis {a} ('{a}', '{LOAD[a]}') has no valid samples "
            "(all NaN, infinite or stuck at zero)",
            f"drop axis {a} or fix the sensor",
        )
    return flagged


def _read_frame(p: Path) -> tuple[pd.DataFrame, list[str]]:
    """The file's columns and a CSV's comment lines above its header: Parquet by pyarrow (one block
    per column, `self_destruct` freeing each Arrow column as it is converted, so the peak holds one
    copy), CSV by pandas' C parser.

    Why pandas for CSV: on a 2-core machine shared with other work, pyarrow's threaded CSV reader
    took as much CPU as pandas' single-threaded C parser and more memory (a 2200 s six-axis log:
    peak RSS 1.28-1.39 GiB against 1.11 GiB, issue 38), and both give the same float64 values.
    """
    import pyarrow.parquet as pq

    from ..files import check_table_file

    check_table_file(p, parquet=is_parquet(p))
    if not is_parquet(p):  # by path: from an open file pandas decodes through Python, at 1.35x the CPU
        comments = log_header.comment_lines(p)
        return pd.read_csv(p, engine="c", skiprows=len(comments)), comments
    # opened here: pyarrow refuses a path with bytes that are not UTF-8 (log\xff.csv), a file it reads
    with open(p, "rb") as fh:
        table = pq.read_table(fh)
    return table.to_pandas(split_blocks=True, self_destruct=True), []


def read_log(path: str | Path) -> RigLog:
    """Read and validate a rig log (CSV, or Parquet by suffix) and its factor sidecar."""
    p = Path(path)
    if not p.exists():
        raise DesignerError(f"no such log: {p}", "give the path of a CSV or Parquet rig log")
    try:
        raw, comments = _read_frame(p)
    except DesignerError:
        raise
    except (ValueError, OSError, pd.errors.ParserError, UnicodeDecodeError) as exc:
        first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise DesignerError(f"cannot read {p}: {first}", "give a CSV or Parquet rig log") from None
    factors, delay, lowpass = _read_sidecar(p)
    log = validate_frame(raw, source=p.name, factors=factors, path=p)
    log_header.check_stated_rate(log.rate, comments, p.name)
    log.load_delay_s, log.load_filter = delay, lowpass
    return log


def write_log(df: pd.DataFrame, path: str | Path, factors: dict | None = None) -> Path:
    """Validate and write a log atomically (Parquet for .parquet/.pq, else CSV) and its factor sidecar."""
    p = Path(path)
    log = validate_frame(df, source=p.name, factors=factors)
    if is_parquet(p):
        with atomic_path(p) as tmp:
            log.data.to_parquet(tmp, index=False)
    else:
        import pyarrow as pa
        import pyarrow.csv as pacsv

        with atomic_path(p) as tmp:
            pacsv.write_csv(pa.Table.from_pandas(log.data, preserve_index=False), tmp)
    if log.factors is not None:
        with atomic_write(sidecar_path(p)) as fh:
            json.dump({"factors": log.factors}, fh, indent=2)
    return p
