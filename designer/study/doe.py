"""Experiment planning: the study's Box-Behnken run sheets and D-optimal augmentation.

The study (Minitab, layer and raster categorical) ran the Box-Behnken design of the four continuous
factors for every combination of the categorical levels: bbdesign(4) (24 edge runs plus centre
runs) x 3 layers x 2 rasters. The all-continuous alternative is Box and Behnken's (1960) six-factor
design: six blocks of three factors from a partially balanced incomplete block design, each a 2^3
factorial with the other three factors at their centre (48 runs), plus centre runs.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np
import pandas as pd

from ..errors import DesignerError
from . import space

#: Box and Behnken (1960), six factors: the factors varied together in each block (0-based)
BB6_BLOCKS: tuple[tuple[int, int, int], ...] = (
    (0, 1, 3),
    (1, 2, 4),
    (2, 3, 5),
    (0, 3, 4),
    (1, 4, 5),
    (0, 2, 5),
)
#: centre runs per categorical combination (study: about 160 specimens = 6 x 27)
CENTER = 3
#: centre runs of the six-factor design (Box and Behnken 1960 list 6)
CENTER_BB6 = 6


def box_behnken_6(center: int = CENTER_BB6) -> np.ndarray:
    """The published six-factor Box-Behnken design in coded units (-1, 0, 1): 48 + center runs."""
    rows = []
    for block in BB6_BLOCKS:
        for signs in itertools.product((-1, 1), repeat=3):
            row = np.zeros(6)
            row[list(block)] = signs
            rows.append(row)
    return np.vstack(rows + [np.zeros((center, 6))])


def _levels(coded: np.ndarray, factor: space.Factor) -> np.ndarray:
    """Map coded -1, 0, 1 to the factor's low, middle, high."""
    low, high = factor.low, factor.high
    return np.where(coded < 0, low, np.where(coded > 0, high, (low + high) / 2))


def _finish(plan: pd.DataFrame, seed: int | None, coded: np.ndarray) -> pd.DataFrame:
    """Number the specimens in design order, randomise the run order."""
    plan.insert(0, "specimen", [f"S{i + 1:03d}" for i in range(len(plan))])
    plan["varied"] = (coded != 0).sum(axis=1)
    order = np.random.default_rng(seed).permutation(len(plan))
    plan = plan.iloc[order].reset_index(drop=True)
    plan.insert(0, "run", np.arange(1, len(plan) + 1))
    return plan


def study_plan(center: int = CENTER, seed: int | None = None) -> pd.DataFrame:
    """bbdesign(4) of density, length, width, height for every layer x raster level, randomised."""
    from pyDOE3 import bbdesign

    if center < 0:
        raise DesignerError(f"center = {center}", "give zero or more centre runs")
    coded4 = bbdesign(4, center=center)
    blocks, coded_all = [], []
    for layer, raster in itertools.product(space.BY_NAME["layer"].levels, space.BY_NAME["raster"].levels):
        block = pd.DataFrame({f.name: _levels(coded4[:, j], f) for j, f in enumerate(space.CONTINUOUS)})
        block["layer"], block["raster"] = layer, raster
        blocks.append(block)
        coded_all.append(coded4)
    plan = pd.concat(blocks, ignore_index=True)[list(space.FACTOR_NAMES)]
    return _finish(plan, seed, np.vstack(coded_all))


def all_continuous_plan(center: int = CENTER_BB6, seed: int | None = None) -> pd.DataFrame:
    """Box and Behnken's six-factor design; raster's middle level (22.5 deg) is untested by the study."""
    if center < 0:
        raise DesignerError(f"center = {center}", "give zero or more centre runs")
    coded = box_behnken_6(center)
    plan = pd.DataFrame({f.name: _levels(coded[:, j], f) for j, f in enumerate(space.FACTORS)})
    return _finish(plan, seed, coded)


def printable_grid() -> pd.DataFrame:
    """Every combination of the study's levels of the six factors (3^5 x 2 = 486 candidates)."""
    return pd.DataFrame(
        list(itertools.product(*(f.levels for f in space.FACTORS))), columns=list(space.FACTOR_NAMES)
    )


#: a target this far (relative) beyond the predicted range of printable designs is out of reach
REACH = 0.10


def near_target(
    predict: Callable[[pd.DataFrame], Mapping[str, np.ndarray]],
    target: Mapping[str, float],
    candidates: pd.DataFrame | None = None,
    fraction: float = 0.05,
) -> pd.DataFrame:
    """The candidates whose predicted responses lie closest to `target` (log distance), at least 5."""
    cand = printable_grid() if candidates is None else candidates.reset_index(drop=True)
    pred = predict(cand)
    for resp, value in target.items():
        if value <= 0:
            raise DesignerError(f"target {resp} = {value:g}", "give a positive target")
    for resp, value in target.items():
        lo, hi = float(np.min(pred[resp])), float(np.max(pred[resp]))
        # a response the model cannot predict (the same value everywhere) has no reach to test
        if hi > lo * (1 + 1e-9) and not lo * (1 - REACH) <= value <= hi * (1 + REACH):
            raise DesignerError(
                f"target {resp} = {value:g} is outside what printable designs are predicted to reach "
                f"({lo:.3g} to {hi:.3g})",
                "give a target inside that range, or augment without a target to narrow the model everywhere",
            )
    dist = sum(np.log(np.maximum(pred[r], 1e-300) / v) ** 2 for r, v in target.items())
    count = max(5, int(round(fraction * len(cand))))
    return cand.iloc[np.argsort(dist)[:count]].reset_index(drop=True)


class _Model:
    """The information of one response's ridge fit, updated as runs are added."""

    def __init__(self, model, existing: pd.DataFrame, cand: pd.DataFrame, target: pd.DataFrame | None):
        self.model = model
        z = model.features(existing)
        penalty = np.eye(z.shape[1])
        penalty[0, 0] = 0.0  # the intercept is not shrunk
        self.inv = np.linalg.pinv(z.T @ z + model.alpha * penalty)
        self.fc = model.features(cand)
        self.ft = self.fc if target is None else model.features(target)
        self.before = self.variance()

    def variance(self) -> np.ndarray:
        """x' A^-1 x at the targets (the PI's variance over sigma^2, less one)."""
        return np.einsum("ij,jk,ik->i", self.ft, self.inv, self.ft)

    def scores(self, i_optimal: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        u = self.fc @ self.inv
        lev = np.einsum("ij,ij->i", u, self.fc)
        if i_optimal:
            score = ((self.ft @ u.T) ** 2).mean(axis=0) / (1.0 + lev) / self.before.mean()
        else:
            score = np.log1p(lev)
        return score, u, lev

    def add(self, u: np.ndarray, lev: float) -> None:
        self.inv = self.inv - np.outer(u, u) / (1.0 + lev)

    def narrowing(self) -> dict[str, float]:
        """Mean 95 % PI half-width at the targets before and after, in the response's fit space."""
        m = self.model
        scale = m.t95 * m.sigma
        return {
            "transform": m.transform,
            "half_width_before": float(np.mean(scale * np.sqrt(1.0 + self.before))),
            "half_width_after": float(np.mean(scale * np.sqrt(1.0 + self.variance()))),
        }


def augment(
    n: int,
    models: Mapping[str, object],
    existing: pd.DataFrame,
    target: pd.DataFrame | None = None,
    candidates: pd.DataFrame | None = None,
    progress: Callable[[float], None] | None = None,
) -> tuple[pd.DataFrame, dict[str, dict[str, float]]]:
    """Pick n printable specimens that most reduce the surrogate's prediction variance.

    `models` maps each response to its fitted model (`.features(X)`, `.alpha`, `.sigma`, `.t95`,
    `.transform`). Greedy D-optimal without `target` (each pick maximises the summed log-det gain
    of A = Z'Z + alpha P); greedy I-optimal with `target` rows (each pick most reduces the mean
    prediction variance there). Returns the picks and, per response, the mean 95 % PI half-width
    (in the fit's space: log for power laws) before and after, at the targets or over the grid.
    """
    if n < 1:
        raise DesignerError(f"n={n} specimens to add", "give the number of specimens to add, 1 or more")
    cand = printable_grid() if candidates is None else candidates.reset_index(drop=True)
    factors = list(space.FACTOR_NAMES)
    states = [
        _Model(m, existing[factors], cand, None if target is None else target[factors])
        for m in models.values()
    ]
    picks = []
    for step in range(n):
        parts = [s.scores(target is not None) for s in states]
        best = int(np.argmax(sum(p[0] for p in parts)))
        for state, (_, u, lev) in zip(states, parts, strict=True):
            state.add(u[best], lev[best])
        picks.append(best)
        if progress is not None:
            progress((step + 1) / n)
    chosen = cand.iloc[picks].reset_index(drop=True)
    chosen.insert(0, "specimen", [f"N{i + 1:03d}" for i in range(len(chosen))])
    return chosen, {resp: s.narrowing() for resp, s in zip(models, states, strict=True)}


def plan_next(
    surrogate: Any,
    *,
    n: int,
    targets: Mapping[str, float | None] | None = None,
    axis: str = "x",
    progress: Callable[[float], None] | None = None,
) -> tuple[pd.DataFrame, dict[str, dict[str, float]]]:
    """The `n` printable specimens that most narrow `surrogate`'s 95 % PIs (see `augment`).

    With `targets` ({"k": .., "c": ..} in rig units on `axis`; None values ignored) the picks narrow
    the PIs of the designs predicted nearest the targets (I-optimal), else the model overall
    (D-optimal).

    Raises:
        DesignerError: `n` below 1, or a target on a response the surrogate does not predict.
    """
    wanted = {f"{q}_{axis}": v for q, v in (targets or {}).items() if v is not None}
    unknown = [r for r in wanted if r not in surrogate.responses]
    if unknown:
        raise DesignerError(
            f"the surrogate has no {unknown[0]}", f"it predicts {', '.join(surrogate.responses)}"
        )
    near = None
    if wanted:
        near = near_target(lambda X: {r: p.value for r, p in surrogate.predict(X).items()}, wanted)
    return augment(n, surrogate.models, surrogate.table, target=near, progress=progress)
