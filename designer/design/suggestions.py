"""Inverse design: printable settings for goals on k and c, ranked by the chance of meeting them.

The engineering standard of response optimisers (Minitab Response Optimizer, JMP Profiler): per
response a goal (a target value, or min or max) with Derringer-Suich desirability bounds, weight and
importance; the importance-weighted geometric mean of the predictable responses' desirabilities as
the composite D; and a multi-start IPOPT search (CasADi ``nlpsol``) over the continuous factors for
every combination of the categorical levels. IPOPT minimises a smooth surrogate of the goals
(squared deviation from a target, the predicted value itself for min or max, plus a small term on
the prediction interval); the candidates, rounded to printable values, are ranked by the
probability that a printed joint lands within a tolerance of the target (`probability_within`),
then by D.
"""

from __future__ import annotations

import numbers
from collections.abc import Mapping
from typing import Any

import numpy as np

from .. import units
from ..errors import DesignerError, check_type, number_argument
from ..model.plausibility import unit_slip
from ..model.prediction import Prediction
from ..model.rotational import PRBSurface, derived_statement, with_axis
from ..model.surrogate import Surrogate, check_surrogate
from ..study import space
from .candidates import Candidate, Suggestion
from .search import (
    DISTINCT,
    GRID_BEST,
    Box,
    Problem,
    distance,
    grid,
    polish,
    reachable_range,
    search,
    search_box,
    weighted,
)
from .targets import TOLERANCE, Target, make_target, prefetch_t_distribution, probability_within

N_NEAREST_RUNS = 3


def predictability(surrogate: Surrogate, axis: str) -> dict[str, dict[str, Any]]:
    """Per response: nested LOO Q2, form, and a plain statement of how much of it the data explains."""
    out = {}
    for q in ("k", "c"):
        m = surrogate.model(f"{q}_{axis}")
        q2 = m.accuracy["q2"]
        label = "nested leave-one-out" if m.loo_nested else "leave-one-out"
        own = int(np.sum(getattr(m, "own", 0)))  # the user's runs of a calibrated response
        if not m.predictable and own:
            text = (
                f"{q}_{axis} is not predictable from the six factors on the study's runs ({label} Q2 = "
                f"{q2:.2f}): your {own} run(s) set its level for your printer and pin it down near the "
                "designs you printed; elsewhere its interval stays wide"
            )
        elif not m.predictable and isinstance(m, PRBSurface):
            text = (
                f"{q}_{axis} is not predictable from the six factors ({q}_{m.base.axis}'s {label} Q2 = "
                f"{q2:.2f}): its prediction is {q}_{m.base.axis}'s mean carried through the relation, so it "
                "follows the length alone"
            )
        elif not m.predictable:
            text = (
                f"{q}_{axis} is not predictable from the six factors: no form beats the mean of the "
                f"runs ({label} Q2 = {q2:.2f}); every design gets the same prediction"
            )
        else:
            text = (
                f"{q}_{axis}: the factors explain about {100 * max(q2, 0):.0f} % of its variation "
                f"({label} Q2 = {q2:.2f}, {m.form} form); the 95 % PIs show the rest"
            )
        out[q] = {"q2": q2, "form": m.form, "predictable": m.predictable, "dof": m.dof, "statement": text}
    return out


def distinct(ranked: list[Candidate], top: int, spans: Mapping[str, float]) -> list[Candidate]:
    """The first `top` of `ranked` lying more than DISTINCT apart (distances scaled by `spans`)."""
    picked: list[Candidate] = []
    for cand in ranked:
        if len(picked) < top and all(distance(cand.params, o.params, spans) > DISTINCT for o in picked):
            picked.append(cand)
    return picked


def suggest(
    surrogate: Surrogate,
    *,
    k: float | str | None = None,
    c: float | str | None = None,
    axis: str = "x",
    fixed: Mapping[str, float] | None = None,
    top: int = 5,
    importance: Mapping[str, float] | None = None,
    bounds: Mapping[str, tuple[float | None, float | None]] | None = None,
    weight: Mapping[str, float] | None = None,
    tolerance: float = TOLERANCE,
    allow_extrapolation: bool = False,
) -> Suggestion:
    """Ranked printable designs for goals on k and/or c (rig units) of one axis.

    Args:
        surrogate: the fitted surrogate (`Surrogate.load()` for the shipped one).
        k, c: a target value, "min" or "max"; None leaves that response free.
        axis: the goals' axis; a rotational one the surrogate lacks comes from x (model.rotational).
        fixed: factors held at a value, e.g. {"width": 4.5}.
        top: how many distinct candidates to return (fewer are explained in `statements`).
        importance, bounds, weight: per response, the composite's importance, the desirability's
            (low, high) bounds (None: the measured range) and its shape exponent.
        tolerance: relative band around a target for `probability_within` (0.10 = +-10 %).
        allow_extrapolation: search half a range beyond the tested ranges, within printable limits.

    Returns:
        A `Suggestion`: candidates ranked by the probability of meeting the predictable targets
        within the tolerance, then by composite desirability; `reachable` False when the best
        candidate's predicted value misses a target by more than the tolerance.

    Raises:
        DesignerError: no goal, an unknown axis or factor, a fixed value out of range, a
            non-positive target, importance or weight, bounds not enclosing a target, top < 1, or
            tolerance not in (0, 1).
    """
    surrogate = with_axis(surrogate, axis)  # a rotational goal through the PRB relation
    check_request(surrogate, axis, k is None and c is None, top, tolerance)
    prefetch_t_distribution()  # P's t distribution loads while IPOPT searches
    for name, value in (("fixed", fixed), ("importance", importance), ("bounds", bounds), ("weight", weight)):
        if value is not None:
            fix = f"give {name} as a dict, e.g. {name}={MAPPING_EXAMPLES[name]}"
            check_type(value, Mapping, name, expected="a mapping", fix=fix)
    importance, bounds, weight = importance or {}, bounds or {}, weight or {}
    targets = {
        q: make_target(
            surrogate, q, axis, v, importance.get(q, 1.0), *bounds.get(q, (None, None)), weight.get(q, 1.0)
        )
        for q, v in (("k", k), ("c", c))
        if v is not None
    }
    fixed = {name: space.check_value(name, v, allow_extrapolation) for name, v in (fixed or {}).items()}
    info = predictability(surrogate, axis)
    # a fixed width or height that leaves one nozzle line inside makes the infill irrelevant: solid
    thin = any(
        n in fixed and fixed[n] - 2 * space.WALL_MM <= space.NOZZLE_MM + 1e-9 for n in ("width", "height")
    )
    search_fixed = fixed | {"density": 100.0} if thin else fixed
    box = search_box(search_fixed, allow_extrapolation)
    problem = Problem(surrogate, axis, weighted(targets, info))
    raw = search(problem, box, targets, info, search_fixed)
    ranked = rank(surrogate, axis, raw, targets, info, tolerance)
    judged = judged_targets(targets, info)
    if not any(meets(c, judged, tolerance) for c in ranked):  # IPOPT is local: back it up with a grid
        near = grid_nearest(surrogate, axis, box, targets, judged, search_fixed)
        raw += near + polish(problem, box, targets, info, near, search_fixed)
        ranked = rank(surrogate, axis, raw, targets, info, tolerance)
    picked = distinct(
        ranked, top, {f.name: float(s) for f, s in zip(space.CONTINUOUS, box.spans, strict=True)}
    )
    sug = Suggestion(axis, targets, picked, True, [], info, surrogate.id, fixed, tolerance)
    assess(sug, surrogate, problem, box, ranked)
    if len(picked) < top:
        sug.statements.append(
            f"{len(picked)} distinct design(s) instead of the {top} asked for: every start of the search "
            "ended at one of these" + (" (the fixed factors leave little to choose)" if fixed else "")
        )
    return sug


def printer_statement(surrogate: Surrogate) -> str:
    """Which printer the predictions and P are for: the study's own, or the user's once calibrated."""
    if surrogate.calibration is None:
        return (
            "printer: the study's own (one Ender 3, one spool of TPU); yours departs from it by a factor "
            "of its own: designer next states P with that unknown, designer calibrate learns it"
        )
    n = surrogate.calibration.n_runs
    if not n:
        return "printer: yours, not measured yet: P counts how it may depart from the study's printer"
    return f"printer: yours, the study calibrated on {n} run(s) of yours"


MAPPING_EXAMPLES = {
    "fixed": "{'width': 3.0}",
    "importance": "{'k': 2.0}",
    "bounds": "{'k': (0.5, 1.2)}",
    "weight": "{'k': 1.0}",
}


def check_request(surrogate: Surrogate, axis: str, no_goal: bool, top: int, tolerance: float) -> None:
    """Raise DesignerError for an axis the surrogate lacks, no goal, top < 1 or a tolerance not in (0, 1)."""
    check_surrogate(surrogate)
    check_type(top, numbers.Integral, "top", expected="a whole number", fix="give e.g. top=5")
    number_argument(tolerance, "tolerance", example="0.1")
    units.check_axis(axis)
    if axis not in surrogate.axes:
        raise DesignerError(
            f"the surrogate has no axis '{axis}'",
            f"it has {', '.join(surrogate.axes) or 'none'}; "
            "fit one on a table with that axis: Surrogate().fit(table)",
        )
    if no_goal:
        raise DesignerError("no target given", "give k= and/or c= (a value, 'min' or 'max')")
    if top < 1:
        raise DesignerError(f"top={top} must be at least 1", "give a positive number of candidates")
    if not 0 < tolerance < 1:
        raise DesignerError(
            f"tolerance={tolerance:g} is not between 0 and 1", "give e.g. tolerance=0.1 (+-10 %)"
        )


def rank(
    surrogate: Surrogate,
    axis: str,
    designs: list[dict[str, float]],
    targets: Mapping[str, Target],
    info: Mapping[str, Mapping[str, Any]],
    tolerance: float,
) -> list[Candidate]:
    """Predict and score each design; sort by P(within tolerance), then D, then the narrower k PI."""
    cols = {n: np.array([d[n] for d in designs]) for n in space.FACTOR_NAMES}
    preds = surrogate.predict(cols, responses=[f"k_{axis}", f"c_{axis}"], allow_extrapolation=True)
    models = {q: surrogate.model(f"{q}_{axis}") for q in ("k", "c")}
    out = []
    for i, design in enumerate(designs):
        predicted = {q: preds[f"{q}_{axis}"].at(i) for q in ("k", "c")}
        rel_error, prob, ds, ws = {}, {}, [], []
        for q, t in targets.items():
            p = predicted[q]
            if t.has_value:
                rel_error[q] = (p.value - t.value) / t.value
                prob[q] = probability_within(
                    p, t.value, tolerance, models[q].dof, log=models[q].transform == "log"
                )
            if info[q]["predictable"]:
                ds.append(t.desirability(p.value))
                ws.append(t.importance)
        scored = [prob[q] for q in prob if info[q]["predictable"]]
        extrapolated = space.extrapolated(design)
        notes = space.printability_notes(design)
        if extrapolated:
            notes.append(
                f"{', '.join(extrapolated)} outside the tested ranges: the prediction is an extrapolation"
            )
        out.append(
            Candidate(
                params=design,
                predicted=predicted,
                desirability=float(np.prod(np.power(ds, np.array(ws) / np.sum(ws)))) if ds else None,
                rel_error=rel_error,
                extrapolated=extrapolated,
                notes=notes,
                p_within=float(np.prod(scored)) if scored else None,
                probability=prob,
                any=[] if space.infill_matters(design) else ["density"],
            )
        )

    def key(c: Candidate) -> tuple[float, float, float]:
        k = c.predicted["k"]
        return (-(c.p_within or 0.0), -(c.desirability or 0.0), float(np.log(k.high / k.low)))

    return sorted(out, key=key)


def judged_targets(targets: Mapping[str, Target], info: Mapping[str, Mapping[str, Any]]) -> list[str]:
    """The goals reachability is judged on: the predictable target values, else every target value."""
    scored = [q for q, t in targets.items() if t.has_value and info[q]["predictable"]]
    return scored or [q for q, t in targets.items() if t.has_value]


def meets(candidate: Candidate, judged: list[str], tolerance: float) -> bool:
    """Whether a candidate's prediction lies within the tolerance of every judged target."""
    return all(abs(candidate.rel_error[q]) <= tolerance for q in judged)


def grid_nearest(
    surrogate: Surrogate,
    axis: str,
    box: Box,
    targets: Mapping[str, Target],
    judged: list[str],
    fixed: Mapping[str, float],
) -> list[dict[str, float]]:
    """The GRID_BEST designs of the printable grid whose predictions come nearest every judged target."""
    designs = grid(box, fixed)
    preds = grid_predictions(surrogate, axis, designs, judged)
    miss = np.max([np.abs(preds[q] / targets[q].value - 1.0) for q in judged], axis=0)
    return [designs[i] for i in np.argsort(miss, kind="stable")[:GRID_BEST]]


def grid_predictions(
    surrogate: Surrogate, axis: str, designs: list[dict[str, float]], quantities: list[str]
) -> dict[str, np.ndarray]:
    """Predicted values of `quantities` at `designs`, shape (n,) each."""
    cols = {n: np.array([d[n] for d in designs]) for n in space.FACTOR_NAMES}
    preds = surrogate.predict(cols, responses=[f"{q}_{axis}" for q in quantities], allow_extrapolation=True)
    return {q: np.asarray(preds[f"{q}_{axis}"].value, dtype=float) for q in quantities}


def assess(
    sug: Suggestion, surrogate: Surrogate, problem: Problem, box: Box, ranked: list[Candidate]
) -> None:
    """Fill reachable, statements, ranges and nearest runs of a suggestion, goal by goal. A target is
    reachable when any design the search found (`ranked`) is predicted within the tolerance of it."""
    best = sug.candidates[0]
    tol = sug.tolerance
    sug.reachable = any(meets(c, judged_targets(sug.targets, sug.predictability), tol) for c in ranked)
    for q, t in sug.targets.items():
        model = surrogate.model(f"{q}_{sug.axis}")
        unit = model.unit
        sug.ranges[q] = {"measured": list(model.observed_range), "predicted": None}
        p = best.predicted[q]
        if not sug.predictability[q]["predictable"]:
            sug.statements.append(unpredictable_statement(sug, q, t, p, unit))
            continue
        if not t.has_value:
            word = "largest" if t.sense > 0 else "smallest"
            sug.statements.append(
                f"{q} {t.kind}imised: the best design is predicted at {p.text(unit)}, the {word} the "
                f"surrogate predicts within the {'extended' if box.extrapolate else 'tested'} ranges "
                f"(measured runs span {model.observed_range[0]:.3g} to {model.observed_range[1]:.3g} {unit})"
            )
            continue
        band = f"+-{100 * tol:.0f} %"
        prob = f"a printed joint lands within {band} of it with probability {best.probability[q]:.2f}"
        if abs(best.rel_error[q]) <= tol:
            sug.statements.append(
                f"{q} = {t.value:g} {unit} is reached within {band}: predicted {p.text(unit)}; {prob}"
            )
            continue
        reached = [c for c in ranked if abs(c.rel_error[q]) <= tol]
        if reached:
            sug.statements.append(
                f"{q} = {t.value:g} {unit} is reached within {band} (a design is predicted at "
                f"{reached[0].predicted[q].text(unit)}); design #1, predicted at {p.text(unit)} "
                f"({100 * best.rel_error[q]:+.0f} %), ranks first by its chance: {prob}"
            )
            continue
        lo_r, hi_r = reachable_range(problem, q, box)
        on_grid = grid_predictions(surrogate, sug.axis, grid(box, sug.fixed), [q])[q]
        lo_r, hi_r = min(lo_r, float(on_grid.min()), p.value), max(hi_r, float(on_grid.max()), p.value)
        sug.ranges[q]["predicted"] = [lo_r, hi_r]
        obs_lo, obs_hi = model.observed_range
        sug.statements.append(
            f"{q} = {t.value:g} {unit} is out of reach within {band}: over the "
            f"{'extended' if box.extrapolate else 'tested'} ranges the surrogate predicts "
            f"{q}_{sug.axis} from {lo_r:.3g} to {hi_r:.3g} {unit}, the runs measured {obs_lo:.3g} to "
            f"{obs_hi:.3g} {unit}; the nearest design is predicted at {p.text(unit)} "
            f"({100 * best.rel_error[q]:+.0f} %) and {prob}"
        )
        if obs_lo <= t.value <= obs_hi:
            sug.nearest_runs = nearest_runs(surrogate, q, sug.axis, t.value)
            sug.statements += [r["statement"] for r in sug.nearest_runs]
        else:
            sug.statements.append(
                f"{q} = {t.value:g} {unit} lies outside the measured range of {q}_{sug.axis}: "
                f"the data does not support it{slip_hint(q, sug.axis, t.value, (obs_lo, obs_hi))}"
            )

    if len(best.probability) > 1:
        every = float(np.prod(list(best.probability.values())))
        sug.statements.append(
            f"every goal at once: design #1 meets {' and '.join(best.probability)} within "
            f"+-{100 * tol:.0f} % together with probability {every:.2f} (the product: given the model, "
            "the responses scatter independently)"
        )
    sug.statements += [printer_statement(surrogate), *derived_statement(surrogate, sug.axis)]


def slip_hint(q: str, axis: str, value: float, measured: tuple[float, float]) -> str:
    """' (a value in N/m rather than N/mm? that is k=0.8 N/mm)' when a target lies about a unit's
    thousand from the `measured` range (its geometric middle), else ''."""
    slip = unit_slip(q, axis, value / float(np.sqrt(measured[0] * measured[1])), logged=False)
    return f" ({slip[0]}? that is {q}={value * slip[1]:g} {units.rig_unit(q, axis)})" if slip else ""


def unpredictable_statement(sug: Suggestion, q: str, t: Target, p: Prediction, unit: str) -> str:
    """What the data can and cannot tell about a goal on a response no form predicts."""
    head = f"{sug.predictability[q]['statement']}: {p.text(unit)} for any design"
    if not t.has_value:
        verb = "raises" if t.sense > 0 else "lowers"
        return f"{head}; '{t.kind}' cannot be acted on: the data shows no setting that {verb} it"
    inside = "inside" if p.low <= t.value <= p.high else "outside"
    hint = "" if inside == "inside" else slip_hint(q, sug.axis, t.value, (p.low, p.high))
    chance = probability_within(p, t.value, sug.tolerance, sug.predictability[q]["dof"], log=False)
    return (
        f"{head}; the target {q} = {t.value:g} {unit} lies {inside} that interval{hint} and any design meets "
        f"it within +-{100 * sug.tolerance:.0f} % with probability {chance:.2f}: no setting can be chosen "
        "for it from this data"
    )


def nearest_runs(surrogate: Surrogate, q: str, axis: str, target: float) -> list[dict[str, Any]]:
    """The measured runs closest to a target (log ratio), with the surrogate's prediction there."""
    response = f"{q}_{axis}"
    train = surrogate.training
    y = np.asarray(train[response], dtype=float)
    order = np.argsort(np.abs(np.log(y / target)))[:N_NEAREST_RUNS]
    unit = units.rig_unit(q, axis)
    out = []
    for i in order:
        design = {n: float(train[n][i]) for n in space.FACTOR_NAMES}
        p = surrogate.predict(design, responses=[response], allow_extrapolation=True)[response].at(0)
        run = int(train["run"][i]) if "run" in train else int(i) + 1
        where = ", ".join(f"{n} {design[n]:g} {space.BY_NAME[n].unit}" for n in space.FACTOR_NAMES)
        out.append(
            {
                "run": run,
                "params": design,
                "measured": float(y[i]),
                "predicted": p.to_dict(),
                "statement": f"run {run} measured {y[i]:.3g} {unit} at {where}; the surrogate predicts "
                f"{p.text(unit)} there",
            }
        )
    return out
