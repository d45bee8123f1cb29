"""Evaluate a batch of cases in one worker: the FMU co-simulation path, or the in-engine fast path.

A task is plain data (the scenario, the path, the cases), so it pickles to any process or Dask
worker; the worker builds its own FMU instances and MuJoCo model. A failing case becomes a row
with status "failed" and its message; it does not stop the batch.
"""

from __future__ import annotations

import atexit
import contextlib
import multiprocessing.util
import os
import time
from collections.abc import Iterator, Sequence
from dataclasses import dataclass

import numpy as np

from ..cosim.master import Trace
from ..cosim.result import Result
from ..cosim.rig_scenario import RigScenario
from ..cosim.robot_scenario import RobotScenario
from ..cosim.scenario import Scenario
from ..cosim.session import Session
from ..errors import DesignerError
from .cases import Case, si_law
from .engine import rollout_traces


@dataclass(frozen=True)
class Task:
    """A batch for one worker: the scenario, the evaluation path ("fmu" | "engine") and the cases.

    `hold`: the worker keeps its prepared Session for the next batch of the same scenario (local
    processes and this process, which close it at their end; not Dask workers, whose end is not
    the sweep's).
    """

    scenario: Scenario
    path: str
    cases: tuple[Case, ...]
    hold: bool = False


#: the Session this process holds between batches of one scenario (Task.hold), by the scenario's full repr
_HELD: dict[str, Session] = {}
#: the processes in which `release` is registered as a multiprocessing finalizer
_FINALIZED: set[int] = set()


def held(sc: Scenario) -> Session:
    """The Session this process holds for `sc`, prepared on first use (the one held before, for
    another scenario, is closed)."""
    from ..cosim import prepare

    with np.printoptions(threshold=2**31, precision=17):  # every sample of a trajectory, exactly
        key = repr(sc)
    session = _HELD.get(key)
    if session is None:
        release()
        session = _HELD[key] = prepare(sc)
        if os.getpid() not in _FINALIZED:
            # a worker process closes it when it ends: multiprocessing runs its finalizers then, also
            # in forked workers, which skip atexit (registered here, in the worker: a fork clears them)
            multiprocessing.util.Finalize(None, release, exitpriority=10)
            _FINALIZED.add(os.getpid())
    return session


def release() -> None:
    """Close the Session this process holds: its FMU instances freed, its temporary folder removed
    (at the end of a sweep in this process, and when a worker process exits)."""
    while _HELD:
        _HELD.popitem()[1].close()


atexit.register(release)

#: how many `holding` blocks are open in this process
_OPEN = [0]


@contextlib.contextmanager
def holding() -> Iterator[None]:
    """Keep the Session this process holds for the block's batches, and close it when the outermost
    block ends (a sweep, or a tune's generations)."""
    _OPEN[0] += 1
    try:
        yield
    finally:
        _OPEN[0] -= 1
        if not _OPEN[0]:
            release()


def metrics(sc: RobotScenario, *, trace: Trace, case: Case) -> dict[str, dict]:
    """Per-joint metrics of an in-engine trace, as `designer cosim` computes them (RobotScenario.metrics)."""
    laws = {j: si_law(src, case.coefficients[j]) for j, src in sc.joints.items()}
    return sc.metrics(trace, laws)


def case_parameters(sc: Scenario, case: Case) -> dict[str, dict[str, float]]:
    """A case's k and c as the FMU parameters `Session.run` takes: {joint: {"axis.k", "axis.c"}}, SI."""
    srcs = sc.sources()
    return {
        j: {f"{src.axis}.{q}": v for q, v in si_law(src, case.coefficients[j]).items()}
        for j, src in srcs.items()
    }


def fmu_result(session: Session, *, case: Case) -> Result:
    """Co-simulate one case in a prepared session: the case's k and c set as FMU parameters (SI).
    Returns the cosim `Result` (time series and per-joint metrics)."""
    return session.run(case_parameters(session.scenario, case))


#: per-case metrics of a rig sweep: the identified coefficients (rig units), their errors, the fit's R2
RIG_METRICS = ("k_identified", "c_identified", "k_error_pct", "c_error_pct", "r2")


def rig_identification(session: Session, *, case: Case) -> dict[str, dict]:
    """Run the virtual rig on one case's joint, identify its log, and compare with the case's k and c.

    The log is the one `designer cosim` writes for the rig (RigScenario.log), read through the
    rig-log validation and identified as a measured log would be.
    """
    from ..rig.identify import identify
    from ..rig.logs import validate_frame

    sc, true = session.scenario, case.coefficients["rig"]
    src = sc.rig_joint
    log = validate_frame(sc.log(fmu_result(session, case=case)), f"virtual rig log of case {case.index}")
    res = identify(log)[0]
    if src.axis in res.failures:
        raise DesignerError(f"case {case.index}: the rig log failed identification: {res.failures[src.axis]}")
    fit = res.axes[src.axis]
    values = (fit.k, fit.c, 100 * (fit.k / true["k"] - 1), 100 * (fit.c / true["c"] - 1), fit.r2)
    return {"rig": dict(zip(RIG_METRICS, map(float, values), strict=True))}


def robot_outcome(session: Session, *, case: Case) -> dict[str, dict]:
    """Co-simulate a robot case and return its per-joint metrics."""
    return fmu_result(session, case=case).metrics


#: what a sweep computes for one case of each scenario type through the FMU path
OUTCOMES = {RobotScenario: robot_outcome, RigScenario: rig_identification}


def case_row(case: Case, *, outcome: dict | Exception, wall: float) -> dict:
    """One table row: case number and key, inputs, k and c per joint, metrics, status, message, wall time."""
    row: dict = {"case": case.index, "key": case.key, **case.inputs}
    for j, coef in case.coefficients.items():
        row.update({f"{j}.{q}": v for q, v in coef.items()})
    if isinstance(outcome, Exception):
        row.update({"status": "failed", "message": str(outcome)})
    else:
        for j, m in outcome.items():
            row.update({f"{j}.{name}": (np.nan if v is None else v) for name, v in m.items()})
        row.update({"status": "ok", "message": ""})
    row["wall_s"] = wall
    return row


def _failure(exc: Exception) -> Exception:
    return exc if isinstance(exc, DesignerError) else RuntimeError(f"{type(exc).__name__}: {exc}")


def _fmu_batch(task: Task) -> list[dict]:
    """The batch's cases through one prepared Session: set-up once, then a reset and a run per case.
    After a failed case the session is closed and the next case prepares a fresh one."""
    from ..cosim import prepare

    outcome_of = OUTCOMES[type(task.scenario)]
    rows = []
    with contextlib.ExitStack() as stack:
        session: Session | None = None
        for case in task.cases:
            start = time.perf_counter()
            try:
                if session is None:
                    session = (
                        held(task.scenario) if task.hold else stack.enter_context(prepare(task.scenario))
                    )
                outcome: dict | Exception = outcome_of(session, case=case)
            except Exception as exc:  # a failed case is recorded, never fatal to the sweep
                outcome = _failure(exc)
                if session is not None:
                    release() if task.hold else session.close()
                    session = None
            rows.append(case_row(case, outcome=outcome, wall=time.perf_counter() - start))
    return rows


def _engine_batch(task: Task) -> list[dict]:
    start = time.perf_counter()
    try:
        outcomes = rollout_traces(task.scenario, task.cases)
    except Exception as exc:  # e.g. a model MuJoCo cannot compile: every case of the batch fails
        outcomes = [_failure(exc)] * len(task.cases)
    wall = (time.perf_counter() - start) / max(len(task.cases), 1)
    rows = []
    for case, out in zip(task.cases, outcomes, strict=True):
        if not isinstance(out, Exception):
            out = metrics(task.scenario, trace=out, case=case)
        rows.append(case_row(case, outcome=out, wall=wall))
    return rows


@contextlib.contextmanager
def _quiet_mujoco() -> Iterator[None]:
    """MuJoCo's warnings (a diverging case) silenced: the row records them; no MUJOCO_LOG.TXT is written."""
    import mujoco

    previous = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(lambda message: None)
    try:
        yield
    finally:
        mujoco.set_mju_user_warning(previous)


def evaluate(task: Task) -> list[dict]:
    """The rows of a batch, in case order (the function an executor runs)."""
    with _quiet_mujoco():
        return _engine_batch(task) if task.path == "engine" else _fmu_batch(task)


def batches(
    scenario: Scenario, *, path: str, cases: Sequence[Case], size: int, hold: bool = False
) -> list[Task]:
    """Cases split into tasks of at most `size` (`hold`: see Task)."""
    return [Task(scenario, path, tuple(cases[i : i + size]), hold) for i in range(0, len(cases), size)]
