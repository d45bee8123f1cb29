"""Task-level tuning: the k and c per joint that minimise a task objective subject to limits, then the
designs to print (suggest) and their robustness under the prediction intervals (a Monte Carlo sweep).

The optimiser is scipy's differential evolution, derivative-free and population-based: each
generation is one batch of co-simulations evaluated through the sweep's executor. It searches
log k and log c, so bounds spanning decades are searched evenly. The metrics are piecewise constant
in k and c (settling is read on the time grid, overshoot is zero on a whole region), which rules
out gradient and simplex methods; no polishing step is run for the same reason. Scores: the sum
of the objective over the joints for a case meeting every limit; 1e6 when the objective is
missing (never settled in the run); 1e9 times (1 + the limits' excess) when a limit is missed;
1e12 for a failed case.
"""

from __future__ import annotations

import contextlib
import itertools
import math
from collections.abc import Callable, Iterator, Mapping, Sequence
from concurrent.futures import Executor
from dataclasses import dataclass, field

import numpy as np

from ..cosim.robot_scenario import RobotScenario
from ..cosim.scenario import Scenario
from ..errors import DesignerError
from ..model.surrogate import Surrogate
from ..study import space
from .cases import Case, finish
from .draws import on_axis, source_axis
from .evaluate import holding
from .limits import Limit, applies, metric
from .run import evaluate_cases
from .spec import PATHS, Cases, Spec

#: scores above any sum of metrics (% , s, rad, J): the ranks of what went wrong
MISSING, INFEASIBLE, FAILED = 1e6, 1e9, 1e12


@dataclass
class TuneResult:
    """Tuned k and c per joint (rig units), the objective there, its FMU check, designs and robustness."""

    objective: str
    limits: list[str]
    coefficients: dict[str, dict[str, float]]
    bounds: dict[str, dict[str, tuple[float, float]]]
    score: float
    metrics: dict[str, float]
    evaluations: int
    fmu_check: dict | None = None
    designs: dict[str, dict] = field(default_factory=dict)
    robustness: dict | None = None

    @property
    def feasible(self) -> bool:
        return self.score < MISSING

    def to_dict(self) -> dict:
        return {
            "objective": self.objective,
            "limits": self.limits,
            "feasible": self.feasible,
            "joints": self.coefficients,
            "bounds": self.bounds,
            "score": self.score,
            "metrics": self.metrics,
            "evaluations": self.evaluations,
            "fmu_check": self.fmu_check,
            "designs": self.designs,
            "robustness": self.robustness,
        }


def _level_grid() -> dict[str, np.ndarray]:
    combos = np.array(list(itertools.product(*[f.levels for f in space.FACTORS])), dtype=float)
    return {n: combos[:, i] for i, n in enumerate(space.FACTOR_NAMES)}


def reachable(surrogate: Surrogate, axis: str) -> dict[str, tuple[float, float]]:
    """k and c (rig units, on `axis`) the surrogate predicts over every combination of the tested levels.

    A response the factors do not predict (the mean form, e.g. c_x) has one value everywhere; its
    range is then the envelope of the 95 % prediction intervals instead, what a print may land on.
    """
    src = source_axis(surrogate, axis)
    grid = _level_grid()
    pred = surrogate.predict(grid, responses=[f"k_{src}", f"c_{src}"])
    out = {}
    for q in ("k", "c"):
        p = pred[f"{q}_{src}"]
        lo, hi = (p.value, p.value) if surrogate.model(f"{q}_{src}").predictable else (p.low, p.high)
        scale = np.array(
            [on_axis((1.0, 1.0), source=src, axis=axis, length_mm=length)[0] for length in grid["length"]]
        )
        out[q] = (float(np.min(lo * scale)), float(np.max(hi * scale)))
    return out


def score(row: Mapping, *, sc: RobotScenario, objective: str, limits: Sequence[Limit]) -> float:
    """The minimised score of one evaluated case (see the module's docstring); step metrics count
    at the joints with a step reference only."""
    if row.get("status") != "ok":
        return FAILED
    excess = 0.0
    for limit in limits:
        for j in sc.joints:
            if applies(limit.metric, sc.motors[j]):
                excess += min(limit.excess(_value(row, f"{j}.{limit.metric}")), 1e3)
    if excess > 0:
        return INFEASIBLE * (1.0 + excess)
    values = [_value(row, f"{j}.{objective}") for j in sc.joints if applies(objective, sc.motors[j])]
    if any(v is None for v in values):
        return MISSING
    return float(sum(values))


def _value(row: Mapping, column: str) -> float | None:
    v = row.get(column)
    return None if v is None or not math.isfinite(v) else float(v)


def _bounds(
    sc: RobotScenario,
    joints: Sequence[str],
    given: Mapping[str, tuple[float, float]],
    surrogate: Surrogate | None,
) -> dict[str, dict[str, tuple[float, float]]]:
    out = {}
    for j in joints:
        reach = None
        for q in ("k", "c"):
            if f"{j}.{q}" not in given:
                reach = reach or reachable(surrogate or Surrogate.load(), sc.joints[j].axis)
        out[j] = {q: tuple(map(float, given.get(f"{j}.{q}") or reach[q])) for q in ("k", "c")}
        for q, (lo, hi) in out[j].items():
            if not 0 < lo <= hi or not math.isfinite(hi):
                raise DesignerError(
                    f"bounds of {j}.{q} ({lo:g} to {hi:g}) are not usable", "give 0 < low <= high"
                )
    for key in given:
        if key.partition(".")[0] not in joints:
            raise DesignerError(
                f"bounds given for {key}, not a tuned joint", f"tuned joints: {', '.join(joints)}"
            )
    return out


@contextlib.contextmanager
def _executor(given: Executor | None, workers: int | None) -> Iterator[Executor]:
    if given is not None:
        yield given
        return
    from .executors import executor

    with executor(workers=workers) as ex:
        yield ex


def tune(
    scenario: Scenario,
    *,
    objective: str = "settling_time",
    limits: Sequence[Limit] = (),
    bounds: Mapping[str, tuple[float, float]] | None = None,
    joints: Sequence[str] | None = None,
    path: str = "engine",
    surrogate: Surrogate | None = None,
    executor: Executor | None = None,
    workers: int | None = None,
    seed: int = 0,
    maxiter: int = 40,
    popsize: int = 10,
    robustness: int = 100,
    progress: Callable[[float], None] | None = None,
) -> TuneResult:
    """Tune k and c of `joints` (default all) of a robot scenario; see the module docstring.

    `bounds` maps "joint.k" / "joint.c" to (low, high) in rig units (equal ends hold it fixed);
    missing ones are the range the surrogate reaches. `path` "engine" searches with the in-engine
    fast path and checks the optimum by FMU co-simulation; "fmu" co-simulates every evaluation.
    `robustness`: Monte Carlo draws of the suggested designs (0: none).

    Raises:
        DesignerError: unknown objective, joint or path; unusable bounds; a non-robot scenario.
    """
    objective = metric(objective)
    if path not in PATHS:
        raise DesignerError(f"path={path!r} is not allowed", "use path='engine' or path='fmu'")
    if not isinstance(scenario, RobotScenario):
        raise DesignerError("tune needs a robot scenario", "give a scenario with [robot] and [joints]")
    if not any(applies(objective, ref) for ref in scenario.motors.values()):
        raise DesignerError(f"no joint of the scenario has {objective}", "give a joint a step reference")
    joints = list(joints or scenario.joints)
    unknown = [j for j in joints if j not in scenario.joints]
    if unknown:
        raise DesignerError(
            f"the scenario has no joint {', '.join(unknown)}", f"it has {', '.join(scenario.joints)}"
        )
    surrogate = surrogate or Surrogate.load()
    box = _bounds(scenario, joints, dict(bounds or {}), surrogate)
    spec = Spec(scenario=scenario, cases=Cases(type="grid"), path=path, limits=tuple(limits), check=0)
    with _executor(executor, workers) as ex, holding():  # one Session for every generation
        search = _Search(spec, [(j, q) for j in joints for q in ("k", "c")], objective, ex)
        result = _optimise(search, box, seed=seed, maxiter=maxiter, popsize=popsize, progress=progress)
        best = search.coefficients(result.x)
        tuned = TuneResult(
            objective=objective,
            limits=[str(x) for x in limits],
            coefficients=best,
            bounds=box,
            score=float(result.fun),
            metrics={},
            evaluations=search.evaluations,
        )
        _confirm(tuned, spec, best, ex)
        _designs(tuned, spec, surrogate, robustness, seed, ex)
    if progress is not None:
        progress(1.0)
    return tuned


class _Search:
    """The optimiser's objective: a generation of (log k, log c) vectors evaluated as one batch of cases."""

    def __init__(self, spec: Spec, keys: list[tuple[str, str]], objective: str, ex: Executor) -> None:
        self.spec, self.keys, self.objective, self.executor = spec, keys, objective, ex
        self.evaluations = 0

    def coefficients(self, x: np.ndarray) -> dict[str, dict[str, float]]:
        """{joint: {"k", "c"}} in rig units from one vector of logs."""
        out: dict[str, dict[str, float]] = {}
        for (j, q), v in zip(self.keys, x, strict=True):
            out.setdefault(j, {})[q] = float(np.exp(v))
        return out

    def __call__(self, xs: np.ndarray) -> np.ndarray:
        """Scores of the columns of xs (parameters x population), as scipy's vectorized mode passes them."""
        start = self.evaluations
        cases = [Case(start + i, self.coefficients(x)) for i, x in enumerate(xs.T)]
        rows, _ = evaluate_cases(self.spec, finish(cases, self.spec), executor=self.executor)
        self.evaluations += len(rows)
        sc, limits = self.spec.scenario, self.spec.limits
        return np.array([score(r, sc=sc, objective=self.objective, limits=limits) for r in rows])


def _optimise(
    search: _Search,
    box: Mapping[str, Mapping[str, tuple[float, float]]],
    *,
    seed: int,
    maxiter: int,
    popsize: int,
    progress: Callable[[float], None] | None,
):
    """Differential evolution over log k, log c within the box; scipy's OptimizeResult."""
    from scipy.optimize import differential_evolution

    generation = itertools.count(1)

    def report(*_args, **_kwargs) -> None:
        if progress is not None:
            progress(next(generation) / (maxiter + 1))

    return differential_evolution(
        search,
        [tuple(np.log(box[j][q])) for j, q in search.keys],
        maxiter=maxiter,
        popsize=popsize,
        rng=np.random.default_rng(seed),
        polish=False,
        updating="deferred",
        vectorized=True,
        callback=report,
    )


def _confirm(tuned: TuneResult, spec: Spec, best: dict, ex: Executor) -> None:
    """The tuned case's metrics, and (engine path) the same case co-simulated with the FMUs."""
    from dataclasses import replace

    rows, _ = evaluate_cases(spec, finish([Case(0, best)], spec), executor=ex)
    joints = spec.scenario.joints
    metrics = [c for c in rows[0] if c.partition(".")[0] in joints and c.partition(".")[2] not in ("k", "c")]
    tuned.metrics = {c: _value(rows[0], c) for c in metrics}  # None: not settled within the run
    if spec.path != "engine":
        return
    fmu_spec = replace(spec, path="fmu")
    fmu, _ = evaluate_cases(fmu_spec, finish([Case(0, best)], fmu_spec), executor=ex)
    diffs = {c: abs(float(rows[0][c]) - float(fmu[0].get(c, math.nan))) for c in metrics}
    tuned.fmu_check = {
        "status": fmu[0]["status"],
        "message": fmu[0]["message"],
        "max_metric_difference": {c: d for c, d in diffs.items() if not math.isnan(d)},
    }


def _designs(
    tuned: TuneResult, spec: Spec, surrogate: Surrogate, draws: int, seed: int, ex: Executor
) -> None:
    """Suggest designs for each tuned joint, then a Monte Carlo sweep over the best designs' PIs."""
    from ..design.suggestions import suggest
    from .cases import make_cases
    from .run import table
    from .summary import summarize

    sc = spec.scenario
    chosen = {}
    for j, coef in tuned.coefficients.items():
        axis = sc.joints[j].axis
        src = source_axis(surrogate, axis)
        fixed = None
        if src != axis:  # PRB: the length sets the scale, so it is held where the joint has it
            length = _length(sc, j)
            fixed = {"length": length}
        scale_k, scale_c = (
            on_axis((1.0, 1.0), source=src, axis=axis, length_mm=fixed["length"]) if fixed else (1.0, 1.0)
        )
        s = suggest(surrogate, k=coef["k"] / scale_k, c=coef["c"] / scale_c, axis=src, fixed=fixed, top=3)
        tuned.designs[j] = {"axis": src, "targets": {"k": coef["k"] / scale_k, "c": coef["c"] / scale_c}} | {
            key: s.to_dict()[key] for key in ("units", "fixed", "statements", "candidates")
        }
        chosen[j] = s.candidates[0].params
    if not draws:
        return
    from dataclasses import replace

    mc = replace(
        spec, cases=Cases(type="montecarlo", joints=dict.fromkeys(chosen), n=draws, seed=seed, designs=chosen)
    )
    cases = make_cases(mc)
    rows, _ = evaluate_cases(mc, cases, executor=ex)
    summary = summarize(mc, frame=table(rows), cases=cases)
    tuned.robustness = {k: summary[k] for k in ("cases", "ok", "failed", "percentiles") if k in summary}
    tuned.robustness |= {k: summary[k] for k in ("limits", "share_meeting_all") if k in summary}
    tuned.robustness["designs"] = chosen


def _length(sc: RobotScenario, joint: str) -> float:
    """The joint's printed length (mm): its design's, else the middle of the tested range."""
    src = sc.joints[joint]
    params = None if src.joint is None else src.joint.provenance.get("params")
    if params:
        return float(params["length"])
    f = space.BY_NAME["length"]
    return (f.low + f.high) / 2
