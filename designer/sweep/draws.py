"""Draws from the surrogate's predictive distribution: what a printed joint's k and c may turn out to be.

The surrogate's 95 % prediction interval (designer/surrogate.py) is, in the response's fitted space
(log for the power law, raw otherwise), mean +/- t(0.975, dof) * sigma * sqrt(1 + z' V z), with dof
the effective residual degrees of freedom of the ridge fit. The matching predictive distribution is
that location-scale Student t: a draw is mean + sigma * sqrt(1 + z' V z) * T, T ~ t(dof), and log
forms are exponentiated, so 95 % of the draws fall inside the reported interval. k and c are drawn
independently (the surrogate fits them separately and does not estimate their correlation). A
raw-space form can put a small share of its distribution below zero (c_x's: about 1 %); such
physically impossible draws are redrawn, i.e. the distribution is truncated at zero.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from .. import units
from ..errors import DesignerError
from ..joint import AxisCoefficients, rotational_from_translational
from ..model.prediction import ResponseSurface
from ..model.surrogate import Surrogate

#: redraw rounds for non-positive raw-space draws before giving up
_REDRAWS = 100


def draw(
    model: ResponseSurface, design: Mapping[str, float], *, n: int, rng: np.random.Generator
) -> np.ndarray:
    """`n` draws (rig units) of one response's predictive distribution at one design.

    Raises:
        DesignerError: positive draws cannot be had (the distribution lies almost wholly below zero).
    """
    z = model.features({k: [v] for k, v in design.items()})[0]
    mean = float(z @ model.coef)
    scale = model.sigma * float(np.sqrt(1.0 + z @ model.vcov @ z))
    out = mean + scale * rng.standard_t(model.dof, size=n)
    if model.transform == "log":
        return np.exp(out)
    for _ in range(_REDRAWS):
        bad = out <= 0
        if not bad.any():
            return out
        out[bad] = mean + scale * rng.standard_t(model.dof, size=int(bad.sum()))
    raise DesignerError(
        f"the predictive distribution of {model.response} lies almost wholly below zero at {dict(design)}",
        "choose a design inside the tested ranges",
    )


def on_axis(
    coefficients: tuple[float, float], *, source: str, axis: str, length_mm: float
) -> tuple[float, float]:
    """(k, c) on the surrogate's axis `source` carried to the joint's `axis` (PRB for a rotational one)."""
    k, c = coefficients
    if axis == source:
        return k, c
    ac = rotational_from_translational(AxisCoefficients(axis=source, k=k, c=c), axis, length_mm)
    return ac.k, ac.c


def source_axis(surrogate: Surrogate, axis: str) -> str:
    """The surrogate axis a joint axis is predicted from: itself, or a translational one via PRB."""
    if axis in surrogate.axes:
        return axis
    translational = [a for a in surrogate.axes if not units.is_rotational(a)]
    if units.is_rotational(axis) and translational:
        return translational[0]
    raise DesignerError(
        f"the surrogate cannot predict axis {axis}", f"it has {', '.join(surrogate.axes) or 'no axis'}"
    )


def joint_draws(
    surrogate: Surrogate, *, design: Mapping[str, float], axis: str, n: int, rng: np.random.Generator
) -> dict[str, np.ndarray]:
    """`n` draws of k and c on a joint's axis (rig units), plus the surrogate-axis draws they came from."""
    src = source_axis(surrogate, axis)
    k = draw(surrogate.model(f"k_{src}"), design, n=n, rng=rng)
    c = draw(surrogate.model(f"c_{src}"), design, n=n, rng=rng)
    length = design["length"]
    scaled = [on_axis((ki, ci), source=src, axis=axis, length_mm=length) for ki, ci in zip(k, c, strict=True)]
    return {
        "k": np.array([s[0] for s in scaled]),
        "c": np.array([s[1] for s in scaled]),
        f"k_{src}": k,
        f"c_{src}": c,
    }
