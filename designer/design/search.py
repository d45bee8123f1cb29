"""The multi-start IPOPT search of `suggest` over the continuous factors, per categorical combination.

IPOPT minimises a smooth surrogate of the goals (squared deviation from a target, the predicted
value itself for min or max, plus a small term on the prediction interval) over the search box.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np

from ..model.surrogate import Surrogate
from ..study import space
from .targets import Target

#: weight of the (normalised) squared PI width in the objective: a tie-breaker only
PI_WEIGHT = 1e-3
#: IPOPT starts in all (the centre, then fixed pseudo-random points), shared among the categorical
#: combinations left free, at least 2 each: 12 solves of ~5 ms when all 6 are searched
N_STARTS = 12
#: designs closer than this in normalised factor space are the same design
DISTINCT = 0.05
#: measured runs listed when a target lies between the predicted and the measured range
#: points per free continuous factor of the grid that backs up the search where no design it found
#: meets the targets (IPOPT is local: a calibrated surface has bumps at the user's prints)
GRID_POINTS = 5
#: grid designs nearest the targets that IPOPT polishes
GRID_BEST = 4
IPOPT = {
    "ipopt.print_level": 0,
    "print_time": False,
    "ipopt.sb": "yes",
    "ipopt.tol": 1e-9,
    "ipopt.max_iter": 300,
    "error_on_fail": False,
}
#: IPOPT's status when an exception left its callbacks. With these problems (CasADi expressions, no
#: Python callbacks) only a stop signal does: CasADi turns the KeyboardInterrupt (or the CLI's stop) raised
#: in its interrupt check into this status and returns normally, with the search cut short
INTERRUPTED = "NonIpopt_Exception_Thrown"


def solved(solver: ca.Function, **args: Any) -> dict[str, Any]:
    """`solver(**args)`, raising KeyboardInterrupt when a stop signal ended IPOPT (see INTERRUPTED): an
    interrupted search must stop the command, never be answered from."""
    sol = solver(**args)
    if solver.stats()["return_status"] == INTERRUPTED:
        raise KeyboardInterrupt("stopped inside IPOPT")
    return sol


class Problem:
    """One IPOPT problem over the coded continuous factors; levels, box and goals as parameters.

    The cost per response q is wsq_q (value - goal_q)^2 + wlin_q value + wpi_q (high - low)^2:
    a target sets wsq, min a positive and max a negative wlin; zero weights switch a response off.
    Only the `weighted` responses enter the cost (those `weighted` names for the goals): a response
    whose weights are all zero adds exactly zero to the cost and its derivatives, yet its terms
    would double the exact Hessian IPOPT builds and evaluates (a calibrated surface's runs and
    mechanism gradients make it about 140 000 operations per response).
    """

    def __init__(self, surrogate: Surrogate, axis: str, weighted: Sequence[str] = ("k", "c")) -> None:
        self.functions = {q: surrogate.model(f"{q}_{axis}").casadi_function() for q in ("k", "c")}
        n_cont = len(space.CONTINUOUS)
        u = ca.SX.sym("u", n_cont)  # continuous factors scaled to [0, 1] of the search box
        cat = ca.SX.sym("cat", len(space.CATEGORICAL))
        lows, spans = ca.SX.sym("lows", n_cont), ca.SX.sym("spans", n_cont)
        goal, wsq, wlin, wpi = (ca.SX.sym(name, 2) for name in ("goal", "wsq", "wlin", "wpi"))
        x = ca.vertcat(lows + spans * u, cat)  # factor order: continuous first, then layer, raster
        cost = 0
        for i, q in enumerate(("k", "c")):
            if q not in weighted:
                continue
            value, lo, hi = self.functions[q](x)
            cost += wsq[i] * (value - goal[i]) ** 2 + wlin[i] * value + wpi[i] * (hi - lo) ** 2
        self._u, self._x = u, x
        self._box = ca.vertcat(cat, lows, spans)
        p = ca.vertcat(self._box, goal, wsq, wlin, wpi)
        self.solver = ca.nlpsol("suggest", "ipopt", {"x": u, "p": p, "f": cost}, IPOPT)

    def extreme_solver(self, q: str) -> ca.Function:
        """IPOPT minimising sign * predicted value of one response (sign is the last parameter)."""
        sign = ca.SX.sym("sign")
        value = self.functions[q](self._x)[0]
        nlp = {"x": self._u, "p": ca.vertcat(self._box, sign), "f": sign * value}
        return ca.nlpsol(f"extreme_{q}", "ipopt", nlp, IPOPT)

    def solve(self, u0: np.ndarray, ubounds: tuple[np.ndarray, np.ndarray], p: np.ndarray) -> np.ndarray:
        sol = solved(self.solver, x0=u0, lbx=ubounds[0], ubx=ubounds[1], p=p)
        return np.asarray(sol["x"]).ravel()


@dataclass(frozen=True)
class Box:
    """The search box of the continuous factors (rig units) and the categorical combinations."""

    lows: np.ndarray
    spans: np.ndarray
    lbu: np.ndarray  # bounds of the coded factors, [0, 1], equal where a factor is fixed
    ubu: np.ndarray
    combos: list[tuple[float, ...]]
    extrapolate: bool

    def design(self, u: np.ndarray, combo: tuple[float, ...]) -> dict[str, float]:
        design = dict(zip([f.name for f in space.CONTINUOUS], self.lows + self.spans * u, strict=True))
        return design | dict(zip([f.name for f in space.CATEGORICAL], combo, strict=True))


def search_box(fixed: Mapping[str, float], allow_extrapolation: bool) -> Box:
    ranges = [space.extended_range(f) if allow_extrapolation else (f.low, f.high) for f in space.CONTINUOUS]
    lows = np.array([r[0] for r in ranges])
    spans = np.array([r[1] - r[0] for r in ranges])
    lbu, ubu = np.zeros(len(lows)), np.ones(len(lows))
    for i, f in enumerate(space.CONTINUOUS):
        if f.name in fixed:
            lbu[i] = ubu[i] = (fixed[f.name] - lows[i]) / spans[i]
    combos = [
        combo
        for combo in itertools.product(*[f.levels for f in space.CATEGORICAL])
        if all(np.isclose(fixed.get(f.name, lv), lv) for f, lv in zip(space.CATEGORICAL, combo, strict=True))
    ]
    return Box(lows, spans, lbu, ubu, combos, allow_extrapolation)


def starts(n: int, dim: int) -> np.ndarray:
    """The centre and n - 1 fixed pseudo-random points of the unit box (deterministic results)."""
    rng = np.random.default_rng(20251122)
    return np.vstack([np.full(dim, 0.5), rng.uniform(0.05, 0.95, size=(n - 1, dim))])


def distance(a: Mapping[str, float], b: Mapping[str, float], spans: Mapping[str, float]) -> float:
    """Distance in normalised factor space; density counts only where it changes both designs."""
    names = [
        f.name
        for f in space.CONTINUOUS
        if f.name != "density" or (space.infill_matters(a) and space.infill_matters(b))
    ]
    cont = [(a[n] - b[n]) / spans[n] for n in names]
    cat = [float(not np.isclose(a[f.name], b[f.name])) for f in space.CATEGORICAL]
    return float(np.sqrt(np.sum(np.square(cont)) + np.sum(cat)))


def weighted(targets: Mapping[str, Target], info: Mapping[str, Mapping[str, Any]]) -> list[str]:
    """The responses the search's cost weighs: those with a goal that are predictable."""
    return [q for q in ("k", "c") if q in targets and info[q]["predictable"]]


def weights(targets: Mapping[str, Target], info: Mapping[str, Mapping[str, Any]]) -> np.ndarray:
    """The NLP's goal and weight parameters [goal, wsq, wlin, wpi] for k and c; unpredictable: 0."""
    goal, wsq, wlin, wpi = np.ones(2), np.zeros(2), np.zeros(2), np.zeros(2)
    for i, q in enumerate(("k", "c")):
        if q not in weighted(targets, info):
            continue
        t = targets[q]
        scale = t.high - t.low
        wpi[i] = PI_WEIGHT * t.importance / scale**2
        if t.has_value:
            goal[i], wsq[i] = t.value, t.importance / scale**2
        else:
            wlin[i] = -t.sense * t.importance / scale
    return np.concatenate([goal, wsq, wlin, wpi])


def search(
    problem: Problem,
    box: Box,
    targets: Mapping[str, Target],
    info: Mapping[str, Mapping[str, Any]],
    fixed: Mapping[str, float],
) -> list[dict[str, float]]:
    """IPOPT from every start in every categorical combination; rounded, printable designs.

    Where the walls fill the section (2.0 mm width) the infill has no effect: the part prints
    solid. When a start ends there, that combination is searched again with width 2.0 mm and
    density 100 % held, so the optimum as printed is found, not the optimum of a tuned infill.
    """
    params = weights(targets, info)
    names = [f.name for f in space.CONTINUOUS]
    iw, idens = names.index("width"), names.index("density")
    solid = box.lbu.copy(), box.ubu.copy()
    solid[0][iw] = solid[1][iw] = (space.PRINTABLE_MIN_MM - box.lows[iw]) / box.spans[iw]
    solid[0][idens] = solid[1][idens] = (100.0 - box.lows[idens]) / box.spans[idens]
    may_be_solid = "width" not in fixed and "density" not in fixed and 0 <= solid[0][iw] <= 1
    raw: list[dict[str, float]] = []
    for combo in box.combos:
        p = np.concatenate([combo, box.lows, box.spans, params])
        found = []
        for u0 in starts(max(2, -(-N_STARTS // len(box.combos))), len(names)):
            u = problem.solve(np.clip(u0, box.lbu, box.ubu), (box.lbu, box.ubu), p)
            found.append(box.design(u, combo))
        if may_be_solid and not all(space.infill_matters(space.round_printable(d)) for d in found):
            found.append(box.design(problem.solve(np.clip(0.5, *solid), solid, p), combo))
        held = {n: v for n, v in fixed.items() if n in names}
        raw += [as_solid(space.round_printable(d | held)) for d in found]
    return raw


def as_solid(design: dict[str, float]) -> dict[str, float]:
    """Where infill has no effect the part prints solid: predict it at 100 % density."""
    return design if space.infill_matters(design) else design | {"density": 100.0}


def reachable_range(problem: Problem, q: str, box: Box) -> tuple[float, float]:
    """Smallest and largest predicted value of one response over the search box (IPOPT, per combo),
    each extreme evaluated as printed (solid where the walls fill the section)."""
    solver, f = problem.extreme_solver(q), problem.functions[q]
    values = []
    for combo in box.combos:
        for sign in (1.0, -1.0):
            p = np.concatenate([combo, box.lows, box.spans, [sign]])
            sol = solved(solver, x0=np.clip(0.5, box.lbu, box.ubu), lbx=box.lbu, ubx=box.ubu, p=p)
            design = as_solid(box.design(np.asarray(sol["x"]).ravel(), combo))  # as printed
            values.append(float(f([design[n] for n in space.FACTOR_NAMES])[0]))
    return min(values), max(values)


def grid(box: Box, fixed: Mapping[str, float]) -> list[dict[str, float]]:
    """Printable designs on a grid over the search box: GRID_POINTS values per free continuous factor
    (fixed ones held), every categorical combination, each as printed."""
    axes = [
        np.linspace(lo, hi, GRID_POINTS) if hi > lo else np.array([lo])
        for lo, hi in zip(box.lbu, box.ubu, strict=True)
    ]
    coded = np.array(list(itertools.product(*axes)))
    held = {f.name: fixed[f.name] for f in space.CONTINUOUS if f.name in fixed}
    return [
        as_solid(space.round_printable(box.design(u, combo) | held)) for combo in box.combos for u in coded
    ]


def polish(
    problem: Problem,
    box: Box,
    targets: Mapping[str, Target],
    info: Mapping[str, Mapping[str, Any]],
    designs: list[dict[str, float]],
    fixed: Mapping[str, float],
) -> list[dict[str, float]]:
    """IPOPT on the search's cost from each of `designs` (within its categorical combination)."""
    params = weights(targets, info)
    held = {f.name: fixed[f.name] for f in space.CONTINUOUS if f.name in fixed}
    out = []
    for d in designs:
        combo = tuple(d[f.name] for f in space.CATEGORICAL)
        u0 = (np.array([d[f.name] for f in space.CONTINUOUS]) - box.lows) / box.spans
        p = np.concatenate([combo, box.lows, box.spans, params])
        u = problem.solve(np.clip(u0, box.lbu, box.ubu), (box.lbu, box.ubu), p)
        out.append(as_solid(space.round_printable(box.design(u, combo) | held)))
    return out
