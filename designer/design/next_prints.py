"""The next prints: which designs to print and measure now so the recommendation lands on target.

The first print is the current recommendation, the design most likely to land now: on simulated
printers it reached the target in fewer prints than any exploratory design the criterion below
prefers (benchmarks/bench_loop.py, 79 runs each of layer-adhesion and combined-mechanism printers:
0.27 and 0.25 fewer prints on average, paired; p90 3 instead of 4 on adhesion).

Further prints of a batch (n > 1) are chosen by a knowledge gradient on the product's answer: for a
candidate print x (one of the search's near-target designs), the value of printing it is the chance
of holding a joint within the tolerance of every predictable target after it and the recommendation
that follows:

    V(x) = P(x lands) + P(x misses) E_y[ max_r P(r within tolerance | runs + (x, y)) | x missed ],

with y drawn from the calibrated surrogate's predictive distribution at x (Gauss-Hermite quadrature
in log space) and r over the current search's candidate designs. Each is valued with the prints
before it assumed measured at their predicted values, and must be distinct from them. The expected
P after the batch is a Monte Carlo over joint draws of the batch's measurements. When the current
recommendation already lands with probability >= `stop`, nothing more is worth printing before it.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import DesignerError, number_argument
from ..model.calibration import new_printer
from ..model.prediction import Prediction
from ..model.rotational import derived_statement, with_axis, with_runs
from ..model.surrogate import Surrogate, check_surrogate
from ..study import space
from .candidates import Candidate
from .search import DISTINCT, distance
from .suggestions import suggest
from .targets import TOLERANCE, probability_within

#: quadrature nodes of the fantasised measurement
NODES = 9
#: candidate designs searched for the prints and for the recommendation after them
POOL = 8
#: joint draws of the batch's measurements for the expected P after it
DRAWS = 48
#: the probability of landing at which printing the recommendation is the best next step
STOP = 0.9


@dataclass(frozen=True)
class NextPrint:
    """One design to print and measure now, what the model expects of it, and why it was chosen."""

    params: dict[str, float]
    predicted: dict[str, Prediction]
    expected_p: float  # expected best P after measuring this print (and the ones before it)
    recommended: bool  # the current recommendation itself
    reason: str

    def to_dict(self) -> dict[str, Any]:
        return {
            "params": self.params,
            "predicted": {q: p.to_dict() for q, p in self.predicted.items()},
            "expected_p": self.expected_p,
            "recommended": self.recommended,
            "reason": self.reason,
        }


@dataclass(frozen=True)
class NextPrints:
    """The result of `next_prints`: the current recommendation, its P, and the prints to make now."""

    axis: str
    targets: dict[str, float | str]
    tolerance: float
    recommendation: Candidate
    p_now: float
    stop: bool
    prints: list[NextPrint]
    p_after: float  # expected P of the best recommendation once `prints` are measured
    statements: list[str] = field(default_factory=list)
    #: False when no design's prediction reaches a target within the tolerance (then no print)
    reachable: bool = True

    def to_dict(self) -> dict[str, Any]:
        return {
            "axis": self.axis,
            "targets": self.targets,
            "tolerance": self.tolerance,
            "recommendation": self.recommendation.to_dict(),
            "p_now": self.p_now,
            "stop": self.stop,
            "p_after": self.p_after,
            "prints": [p.to_dict() for p in self.prints],
            "statements": self.statements,
            "reachable": self.reachable,
        }


class _Scorer:
    """P(within tolerance of every predictable target) of fixed designs under updated surrogates."""

    def __init__(self, surrogate: Surrogate, axis: str, targets: Mapping[str, float], tolerance: float):
        self.axis, self.targets, self.tolerance = axis, dict(targets), tolerance
        self.responses = [f"{q}_{axis}" for q in targets]
        #: what a print measures: both coefficients of the axis
        self.measured = [f"{q}_{axis}" for q in ("k", "c")]

    def lands(self, values: Mapping[str, float]) -> bool:
        """Whether measured values (by response name) are within the tolerance of every target."""
        return all(
            abs(values[f"{q}_{self.axis}"] / t - 1.0) <= self.tolerance for q, t in self.targets.items()
        )

    def best(self, surrogate: Surrogate, designs: Mapping[str, np.ndarray]) -> float:
        preds = surrogate.predict(designs, responses=self.responses, allow_extrapolation=True)
        n = len(next(iter(designs.values())))
        p = np.ones(n)
        for q, target in self.targets.items():
            r = f"{q}_{self.axis}"
            m = surrogate.model(r)
            log = m.transform == "log"
            p *= [
                probability_within(preds[r].at(i), target, self.tolerance, m.dof, log=log) for i in range(n)
            ]
        return float(p.max())


def _log_predictive(surrogate: Surrogate, response: str, design: Mapping[str, float]) -> tuple[float, float]:
    """Mean and scale of log y at one design (Student t in log space, read back from the PI)."""
    m = surrogate.model(response)
    p = surrogate.predict({n: [v] for n, v in design.items()}, responses=[response], allow_extrapolation=True)
    value, high = float(p[response].value[0]), float(p[response].high[0])
    mu = float(np.log(value))
    return mu, (float(np.log(high)) - mu) / m.t95


def _run(design: Mapping[str, float], values: Mapping[str, float]) -> dict[str, float]:
    return {**{n: float(design[n]) for n in space.FACTOR_NAMES}, **values}


def _expected_best(
    surrogate: Surrogate,
    scorer: _Scorer,
    design: dict[str, float],
    known: list[dict[str, float]],
    base: Surrogate,
    pool: Any,
) -> float:
    """Chance of holding a joint that lands after printing `design` and then the best recommendation
    (after the `known`, fantasised, runs; `base` is `surrogate` calibrated on them, shared by every
    candidate of a step): P(design lands) + P(it misses) E[best P | it missed].

    The measurement is integrated by Gauss-Hermite quadrature in log space; the nodes where the
    print lands are left out of the second term's average (renormalised over the missing nodes).
    """
    p_lands = scorer.best(base, {n: np.array([design[n]]) for n in space.FACTOR_NAMES})
    nodes, weights = np.polynomial.hermite_e.hermegauss(NODES)
    weights = weights / weights.sum()
    moments = {r: _log_predictive(base, r, design) for r in scorer.measured}
    best, missed = [], []
    for z in nodes:
        # the targeted responses at the quadrature node, the others at their median
        values = {
            r: float(np.exp(mu + (z * s if r in scorer.responses else 0.0))) for r, (mu, s) in moments.items()
        }
        best.append(scorer.best(with_runs(surrogate, known + [_run(design, values)]), pool))
        missed.append(not scorer.lands(values))
    miss = weights * np.array(missed, dtype=float)
    after_miss = float(miss @ best / miss.sum()) if miss.sum() > 0 else float(weights @ best)
    return p_lands + (1.0 - p_lands) * after_miss


def _batch_p(surrogate: Surrogate, scorer: _Scorer, designs: list[dict[str, float]], pool: Any) -> float:
    """Expected best P once every design of the batch is measured: joint draws, each conditioned on
    the draws before it (seeded, so the answer is repeatable). The first design has no draw before
    it: its predictive distribution is the same in every draw, computed once."""
    rng = np.random.default_rng(20261125)
    first = {r: _log_predictive(surrogate, r, designs[0]) for r in scorer.measured} if designs else {}
    total = 0.0
    for _ in range(DRAWS):
        runs: list[dict[str, float]] = []
        for d in designs:
            current = with_runs(surrogate, runs)
            values = {}
            for r in scorer.measured:
                mu, s = _log_predictive(current, r, d) if runs else first[r]
                values[r] = float(np.exp(mu + s * rng.standard_normal()))
            runs.append(_run(d, values))
        total += scorer.best(with_runs(surrogate, runs), pool)
    return total / DRAWS


def _predictable_targets(sug: Any, axis: str) -> dict[str, float]:
    """The predictable target values of a suggestion's goals: what a print can raise the chance of.

    Raises:
        DesignerError: there is none.
    """
    targets = {
        q: t.value for q, t in sug.targets.items() if t.has_value and sug.predictability[q]["predictable"]
    }
    if not targets:
        raise DesignerError(
            "no predictable target value is given, so no print can raise the chance of landing on it",
            f"give k= a target value (k_{axis} is predictable); min or max goals have no landing chance",
        )
    return targets


def _chance_text(best: Candidate, targets: Mapping[str, float], tolerance: float) -> str:
    """The recommendation's chance in words: of the predictable targets (what the loop acts on) and,
    with other goals, of meeting every goal at once (the responses are independent given the model)."""
    band = f"+-{100 * tolerance:g} %"
    text = f"{' and '.join(targets)} within {band} with probability {float(best.p_within or 0.0):.2f}"
    if set(best.probability) - set(targets):
        every = float(np.prod(list(best.probability.values())))
        text += f" ({' and '.join(best.probability)} all within {band}: {every:.2f})"
    return text


def _doubt_text(surrogate: Surrogate) -> str:
    """What the stated chance counts: the printer's departure from the study, as far as the user's
    prints leave it open."""
    n = len(next(iter(surrogate.calibration["columns"].values()), []))
    mechanisms = "its factor, width and height offsets, infill, layer and raster adhesion"
    if n == 0:
        return f"counting how your printer may depart from the study's ({mechanisms})"
    return (
        f"counting the doubt your {n} print(s) leave about how your printer departs from the study's "
        f"({mechanisms})"
    )


def _them(n: int) -> str:
    """The prints of a batch of `n` in a sentence: "it" or "these 3"."""
    return "it" if n == 1 else f"these {n}"


def _check_arguments(n: int, stop: float) -> None:
    if not 1 <= number_argument(n, "n", example="3") <= 10 or int(n) != n:
        raise DesignerError(f"n={n} is not a whole number from 1 to 10", "give a whole number such as 3")
    if not 0 < number_argument(stop, "stop", example="0.9") <= 1:
        raise DesignerError(f"stop={stop} is not in (0, 1]", "give a probability such as 0.9")


def _pool(candidates: list[Any]) -> dict[str, np.ndarray]:
    """The search's near-target designs as factor columns: where the best design after a print is sought."""
    return {name: np.array([c.params[name] for c in candidates]) for name in space.FACTOR_NAMES}


def _greedy_batch(
    surrogate: Surrogate,
    scorer: _Scorer,
    candidates: list[Any],
    best: Any,
    n: int,
    progress: Callable[[float], None] | None,
) -> list[NextPrint]:
    """Up to `n` distinct prints: the recommendation `best`, then each the candidate of highest value
    given the ones before it (those taken as measured at their predicted values)."""
    pool = _pool(candidates)
    spans = {f.name: f.high - f.low for f in space.CONTINUOUS}
    chosen: list[NextPrint] = []
    known: list[dict[str, float]] = []
    for step in range(n):
        if progress is not None:
            progress(step / (n + 1))
        base = with_runs(surrogate, known)
        if step == 0:
            pick, score = best, _expected_best(surrogate, scorer, best.params, known, base, pool)
            reason = "the current recommendation, the design most likely to land now; measuring it tests it"
        else:
            free = [
                c for c in candidates if all(distance(c.params, p.params, spans) > DISTINCT for p in chosen)
            ]
            if not free:
                break
            scores = [_expected_best(surrogate, scorer, c.params, known, base, pool) for c in free]
            i = int(np.argmax(scores))
            pick, score = free[i], scores[i]
            reason = "tests the model where another near-target design may do better than the current one"
        chosen.append(NextPrint(pick.params, pick.predicted, float(score), pick is best, reason))
        predicted = {r: float(np.exp(_log_predictive(base, r, pick.params)[0])) for r in scorer.measured}
        known.append(_run(pick.params, predicted))
    return chosen


def next_prints(
    surrogate: Surrogate,
    *,
    k: float | str | None = None,
    c: float | str | None = None,
    axis: str = "x",
    fixed: Mapping[str, float] | None = None,
    n: int = 3,
    tolerance: float = TOLERANCE,
    stop: float = STOP,
    progress: Callable[[float], None] | None = None,
) -> NextPrints:
    """The `n` designs to print and measure now that most raise the chance the final recommendation
    lands within `tolerance` of every predictable target.

    Args:
        surrogate: the study surrogate or one calibrated to the user's printer (`designer.calibrate`).
        k, c: goals as in `designer.suggest` (a target value in rig units, "min" or "max"); at least
            one predictable target value is needed: the criterion is the probability of landing on it.
        axis, fixed, tolerance: as in `designer.suggest`.
        n: how many designs to print now (1 to 10).
        stop: when the current recommendation lands with at least this probability, propose no
            print but the recommendation itself.
        progress: called with the fraction of the work done (0..1).

    Returns:
        A `NextPrints`: the current recommendation and its P, `prints` (empty when `stop`), the
        expected P after them, and plain statements.

    Raises:
        DesignerError: the goals of `designer.suggest` are invalid, no predictable target value is
            given, n is not in 1..10, or stop is not in (0, 1]. An unreachable target is not an
            error: the result has `reachable` False, the reason in `statements`, and no print.
    """
    check_surrogate(surrogate)
    _check_arguments(n, stop)
    statements = []
    if surrogate.calibration is None:
        surrogate = new_printer(surrogate)
        statements.append(
            "not calibrated to your printer yet: P counts how an unmeasured printer may depart from "
            "the study's (suggest states P for the study's own printer)"
        )
    surrogate = with_axis(surrogate, axis)  # a rotational goal through the PRB relation
    statements += derived_statement(surrogate, axis)
    sug = suggest(surrogate, k=k, c=c, axis=axis, fixed=fixed, top=POOL, tolerance=tolerance)
    targets = _predictable_targets(sug, axis)
    scorer = _Scorer(surrogate, axis, targets, tolerance)
    best = sug.candidates[0]
    p_now = float(best.p_within or 0.0)
    goals = {q: t.goal for q, t in sug.targets.items()}
    if not sug.reachable:
        statements += [
            st for st in sug.statements if "distinct design" not in st and not st.startswith("printer:")
        ] + ["no print is proposed: the target lies outside what the data supports (see above)"]
        return NextPrints(axis, goals, tolerance, best, p_now, False, [], p_now, statements, False)
    chance = _chance_text(best, targets, tolerance)
    if p_now >= stop:
        text = (
            f"print design #1: {chance} (>= {stop:g}), {_doubt_text(surrogate)}; no other print is "
            "expected to do better first"
        )
        return NextPrints(axis, goals, tolerance, best, p_now, True, [], p_now, statements + [text])
    chosen = _greedy_batch(surrogate, scorer, sug.candidates, best, int(n), progress)
    if progress is not None:
        progress(n / (n + 1))
    pool = _pool(sug.candidates)
    p_after = _batch_p(surrogate, scorer, [p.params for p in chosen], pool)
    if progress is not None:
        progress(1.0)
    statements += [
        f"the best design now: {chance}, {_doubt_text(surrogate)}; after printing and measuring "
        f"{_them(len(chosen))}, the best is expected to land with {p_after:.2f}",
        "then: designer print makes them (a 3MF plate, each object with its settings, and the runs table); "
        "measure each, designer identify fills the table from the rig logs, designer calibrate, "
        "designer next again",
    ]
    if len(chosen) < n:
        statements.append(f"{len(chosen)} distinct design(s) instead of {n}: the search found no more")
    return NextPrints(axis, goals, tolerance, best, p_now, False, chosen, p_after, statements)
