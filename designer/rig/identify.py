"""Identification: per axis, m, c, k of F = m r'' + c r' + k r (the study's Eq 5) from rig logs.

`identify` reads and validates each log, fits its axes in parallel (`axis_fit.fit_axis`: how and
why the fit is built is told there), and returns per log the fits, the failed axes with their
reasons and the axes that do not move; `results_table` makes the coefficient table `designer fit`
reads from the logs that passed.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd
from threadpoolctl import threadpool_limits

from .. import units
from ..errors import DesignerError, describe, names_argument, number_argument
from ..files import display_path
from ..study import space
from . import channel
from .axis_fit import AxisFailed, AxisFit, StillAxis, check_time, fit_axis
from .logs import RigLog, read_log, validate_frame

#: the longest load-channel delay taken: a tenth of the study's shortest excitation period (0.54 s)
MAX_LOAD_DELAY_S = 0.05


@dataclass(frozen=True)
class _Still:
    reason: str


@dataclass(frozen=True)
class Identification:
    """The fits of one log, keyed by axis; `failures` gives each failed axis' reason."""

    path: Path | None
    factors: dict[str, float] | None
    rate: float
    axes: dict[str, AxisFit]
    failures: dict[str, str] = field(default_factory=dict)
    #: axes logged but not moving (only noise): not identified, and no reason to fail the log
    still: dict[str, str] = field(default_factory=dict)
    #: what reading changed in the log (`RigLog.notes`), for people: not warnings
    notes: list[str] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        """Whether every moving axis gave a possible fit and one did move (only then is the log a row
        of the table, with the moving axes)."""
        return not self.failures and bool(self.axes)

    @property
    def warnings(self) -> list[str]:
        return [f"{a}: {w}" for a, f in self.axes.items() for w in f.warnings]

    def to_dict(self) -> dict:
        return {
            "path": None if self.path is None else str(self.path),
            "ok": self.ok,
            "failures": self.failures,
            "still": self.still,
            "warnings": self.warnings,
            "notes": self.notes,
            "factors": self.factors,
            "rate_hz": self.rate,
            "axes": {a: f.to_dict() for a, f in self.axes.items()},
        }


LogSource = str | Path | pd.DataFrame | RigLog


def _as_log(source: LogSource) -> RigLog:
    if isinstance(source, RigLog):
        return source
    if isinstance(source, pd.DataFrame):
        return validate_frame(source, source="frame")
    if isinstance(source, (str, Path)):
        return read_log(source)
    raise DesignerError(
        f"logs holds a {type(source).__name__}", "give paths, pandas DataFrames or RigLog objects"
    )


def identify_log(
    source: LogSource,
    *,
    axes: list[str] | None = None,
    load_delay_s: float | None = None,
    load_filter: str | None = None,
) -> Identification:
    """Identify one log (path, DataFrame or RigLog); see `identify`.

    Raises:
        DesignerError: the log cannot be read or validated, an axis is not in it, or load_delay_s
            is not a finite number.
    """
    log = _as_log(source)
    chosen = log.axes if axes is None else names_argument(axes, "axes", example='["x"]')
    if not chosen:
        raise DesignerError("axes=[] names no axis", f"give some of {', '.join(log.axes)}, or None for all")
    absent = [a for a in chosen if a not in log.axes]
    if absent:
        raise DesignerError(f"axes={absent} not in the log", f"the log has {', '.join(log.axes)}")
    delay = log.load_delay_s or 0.0
    if load_delay_s is not None:
        delay = number_argument(load_delay_s, "load_delay_s", example="0.002 (s)")
    if not np.isfinite(delay):
        raise DesignerError(f"load_delay_s={load_delay_s} is not finite", "give the delay in seconds")
    if abs(delay) >= MAX_LOAD_DELAY_S:  # beyond that, the lag is no channel's: c would mean nothing
        raise DesignerError(
            f"load_delay_s={delay:g} s is not a sensor channel's delay (|delay| < {MAX_LOAD_DELAY_S:g} s)",
            "give the load channel's delay in seconds, e.g. 0.002",
        )
    lowpass = channel.parse(load_filter if load_filter is not None else log.load_filter)

    def one(axis: str) -> AxisFit | _Still | str:
        try:
            check_time(log)
            return fit_axis(log, axis, load_delay_s=float(delay), load_filter=lowpass)
        except StillAxis as exc:
            return _Still(str(exc))
        except (AxisFailed, np.linalg.LinAlgError) as exc:
            return str(exc) if isinstance(exc, AxisFailed) else "the fit is degenerate (singular equations)"

    # one thread per axis: the FFTs and array arithmetic release the GIL. BLAS keeps to one thread
    # in each: its own threads on top of those spun on the small normal equations (a third of the
    # fit's CPU on 2 cores, issue 38) and gave the same numbers
    with (
        threadpool_limits(limits=1, user_api="blas"),
        ThreadPoolExecutor(max_workers=min(len(chosen), os.cpu_count() or 1)) as pool,
    ):
        outcomes = dict(zip(chosen, pool.map(one, chosen), strict=True))
    fits = {a: o for a, o in outcomes.items() if isinstance(o, AxisFit)}
    still = {a: o.reason for a, o in outcomes.items() if isinstance(o, _Still)}
    failures = {a: o for a, o in outcomes.items() if isinstance(o, str)}
    if not fits:  # nothing moved: the still axes are why the log fails
        failures, still = failures | still, {}
    return Identification(
        path=log.path,
        factors=log.factors,
        rate=log.rate,
        axes=fits,
        failures=failures,
        still=still,
        notes=list(log.notes),
    )


def identify(
    logs: LogSource | Iterable[LogSource],
    *,
    axes: list[str] | None = None,
    load_delay_s: float | None = None,
    load_filter: str | None = None,
    progress: Callable[[float], None] | None = None,
) -> list[Identification]:
    """Identify m, c, k per axis of each log: a list of `Identification`, one per log, in order.

    logs: a path (CSV or Parquet, with its JSON sidecar), a pandas DataFrame in the log schema, a
    RigLog, or an iterable of these. axes: the axes to fit (default every axis in the log).
    load_delay_s: seconds by which the load channel lags the position (default: the sidecar's
    `load_delay_s`, else 0); it is corrected exactly. load_filter: the load sensor's low-pass,
    e.g. "butter2:200Hz" (default: the sidecar's `load_filter`, else none), undone exactly in the
    frequency domain. progress: called with the fraction done.
    A log that cannot support a fit, or whose fit is physically impossible, is returned with
    `ok` False and the reason in `failures`; doubtful fits carry `warnings`.

    Raises:
        DesignerError: a log cannot be read or validated (names the column and row), axes names an
            axis not in a log, or load_delay_s is not finite.
    """
    one = (str, os.PathLike, pd.DataFrame, RigLog)
    if not isinstance(logs, (*one, Iterable)) or isinstance(logs, np.ndarray):
        raise DesignerError(
            f"logs is {describe(logs)}, not a log or a list of logs",
            "give paths of rig logs (CSV or Parquet), DataFrames in the log schema, or a list of them",
        )
    sources = [logs] if isinstance(logs, one) else list(logs)
    out = []
    for i, source in enumerate(sources):
        out.append(identify_log(source, axes=axes, load_delay_s=load_delay_s, load_filter=load_filter))
        if progress is not None:
            progress((i + 1) / len(sources))
    return out


def results_table(results: list[Identification]) -> pd.DataFrame:
    """The coefficient table `designer fit` reads: factors, c and k per axis, m where identified.

    Only logs whose every axis passed (`ok`) become rows. An axis's m column appears only when m
    was identified in every log; fit quality (`r2_<axis>`, `nrmse_<axis>`) and the log's path ride
    along as extra columns.

    Raises:
        DesignerError: a log has no factors, no log passed, or the logs share no axis.
    """
    results = [r for r in results if r.ok]
    if not results:
        raise DesignerError("no log passed identification", "fix or re-record the failed logs")
    rows = []
    for res in results:
        if res.factors is None:
            raise DesignerError(
                f"{res.path}: no factors", "write them to the log's JSON sidecar to build a coefficient table"
            )
        rows.append(dict(res.factors))
    axes = [a for a in units.AXES if all(a in r.axes for r in results)]
    if not axes:
        raise DesignerError("the logs share no axis", "identify logs of the same axes together")
    for row, res in zip(rows, results, strict=True):
        for a in axes:
            f = res.axes[a]
            row[f"c_{a}"], row[f"k_{a}"] = f.c, f.k
            if all(r.axes[a].m_identified for r in results):
                row[f"m_{a}"] = f.m
            row[f"r2_{a}"], row[f"nrmse_{a}"] = f.r2, f.nrmse
        row["log"] = display_path(res.path)  # a table cell: bytes that are not UTF-8 escaped
    table = pd.DataFrame(rows)
    front = list(space.FACTOR_NAMES) + [
        f"{q}_{a}" for a in axes for q in units.QUANTITIES if f"{q}_{a}" in table
    ]
    return table[front + [col for col in table.columns if col not in front]]
