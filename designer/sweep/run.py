"""Run a sweep: cases -> batches -> executor -> one table, resumable through a journal of finished cases."""

from __future__ import annotations

import contextlib
import json
import math
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import Executor, Future, ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path
from typing import IO

import pandas as pd

from ..errors import DesignerError, describe
from .cases import MAX_CASES, Case, make_cases
from .evaluate import Task, batches, evaluate, holding
from .spec import Spec, check

Progress = Callable[[float], None] | None
#: columns every table ends with
TAIL = ("status", "message", "wall_s")


@dataclass
class SweepResult:
    """A sweep's outcome: one row per case (see the README for the columns), its summary, the spec."""

    table: pd.DataFrame
    summary: dict
    spec: Spec
    #: cases found finished in the journal and not run again
    resumed: int = 0


def read_journal(path: Path | None) -> dict[str, dict]:
    """Finished rows by case key from a journal (JSON lines); a torn last line is ignored."""
    rows: dict[str, dict] = {}
    if path is None or not path.is_file():
        return rows
    for line in path.read_text().splitlines():
        try:
            row = json.loads(line)
        except ValueError:
            continue
        if isinstance(row, dict) and "key" in row:
            rows[row["key"]] = row
    return rows


def _batch_size(spec: Spec, n_cases: int, workers: int) -> int:
    if spec.batch is not None:
        return spec.batch
    # a batch is one prepared Session (FMU path, tens of ms to set up, a few ms a 1 s case) or one
    # mujoco.rollout (engine path): large batches; four per worker keep the bar moving
    return max(1, min(256, math.ceil(n_cases / (4 * max(workers, 1)))))


@contextlib.contextmanager
def _default_executor(spec: Spec, given: Executor | None) -> Iterator[Executor]:
    if given is not None:
        if not callable(getattr(given, "submit", None)):
            raise DesignerError(
                f"executor is {describe(given)}, not a concurrent.futures Executor",
                "give e.g. concurrent.futures.ProcessPoolExecutor(), or None for local processes",
            )
        yield given
        return
    from .executors import executor

    with executor(workers=spec.workers, cluster=spec.cluster) as ex:
        yield ex


def _failed_rows(task: Task, exc: BaseException) -> list[dict]:
    """Rows for a batch whose worker failed as a whole (a lost worker, an unpicklable result)."""
    from .evaluate import case_row

    message = RuntimeError(f"the worker failed: {type(exc).__name__}: {exc}")
    return [case_row(case, outcome=message, wall=math.nan) for case in task.cases]


@contextlib.contextmanager
def _journal(path: Path | None) -> Iterator[IO | None]:
    """The journal opened for appending, after the newline an interrupted run may not have written."""
    if path is None:
        yield None
        return
    torn = path.is_file() and path.stat().st_size > 0 and not path.read_bytes().endswith(b"\n")
    with open(path, "a") as fh:
        if torn:
            fh.write("\n")
        yield fh


def _finished(ex: Executor, tasks: Sequence[Task]) -> Iterator[list[dict]]:
    """The rows of each task as it finishes; a serial executor runs one task at a time, so its rows
    reach the journal and the progress bar as they come (submitting all first would run them all)."""
    from .executors import SerialExecutor

    if isinstance(ex, SerialExecutor):
        for task in tasks:
            yield _rows(ex.submit(evaluate, task), task)
        return
    futures = {ex.submit(evaluate, task): task for task in tasks}
    for future in as_completed(futures):
        yield _rows(future, futures[future])


def _rows(future: Future, task: Task) -> list[dict]:
    try:
        return future.result()
    except Exception as exc:  # the batch as a whole failed (a lost worker...): record it, go on
        return _failed_rows(task, exc)


def evaluate_cases(
    spec: Spec,
    cases: Sequence[Case],
    *,
    executor: Executor | None = None,
    journal: Path | None = None,
    progress: Progress = None,
) -> tuple[list[dict], int]:
    """Rows of `cases` in case order, running only those the journal has not finished (status ok);
    new rows are appended to the journal as batches finish. Returns the rows and the resumed count."""
    done = read_journal(journal)
    todo = [c for c in cases if done.get(c.key, {}).get("status") != "ok"]
    resumed = len(cases) - len(todo)
    new: dict[str, dict] = {}
    if todo:
        from .executors import SerialExecutor, local_workers

        workers = 1 if isinstance(executor, SerialExecutor) else local_workers(spec.workers)
        size = _batch_size(spec, len(todo), workers)
        with _default_executor(spec, executor) as ex, _journal(journal) as fh, holding():
            # this process and local worker processes keep one Session between batches
            hold = isinstance(ex, (SerialExecutor, ProcessPoolExecutor))
            tasks = batches(spec.scenario, path=spec.path, cases=todo, size=size, hold=hold)
            finished = 0
            for rows in _finished(ex, tasks):
                for row in rows:
                    new[row["key"]] = row
                    if fh is not None:
                        fh.write(json.dumps(row) + "\n")
                if fh is not None:
                    fh.flush()
                finished += len(rows)
                if progress is not None:
                    progress(finished / len(todo))
    rows = []
    for case in cases:
        row = dict(new.get(case.key) or done[case.key])
        row["case"] = case.index
        rows.append(row)
    return rows, resumed


def table(rows: Sequence[dict]) -> pd.DataFrame:
    """The tidy table: one row per case, columns in first-seen order with status, message, wall_s last."""
    columns: dict[str, None] = {}
    for row in rows:
        columns.update(dict.fromkeys(row))
    order = [c for c in columns if c not in TAIL] + list(TAIL)
    frame = pd.DataFrame(list(rows), columns=order)
    return frame.sort_values("case", kind="stable").reset_index(drop=True)


def run(
    spec: Spec,
    *,
    executor: Executor | None = None,
    journal: str | Path | None = None,
    progress: Progress = None,
    max_cases: int = MAX_CASES,
) -> SweepResult:
    """Evaluate every case of a sweep and summarise; nothing is written but the optional journal.

    `executor` is any `concurrent.futures` executor (default: local processes, or the spec's
    [cluster]); `journal` a JSON-lines file of finished cases, read to skip them and appended to;
    `max_cases` the most cases built (`check_size`, checked before any is).
    """
    from .summary import summarize

    spec = check(spec)
    journal = None if journal is None else Path(journal)
    cases = make_cases(spec, max_cases=max_cases)
    rows, resumed = evaluate_cases(spec, cases, executor=executor, journal=journal, progress=progress)
    frame = table(rows)
    return SweepResult(frame, summarize(spec, frame=frame, cases=cases), spec, resumed)
