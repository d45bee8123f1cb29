"""Joint-level (rotational) goals through the pseudo-rigid-body relation the exports use.

A robot engineer asks for a joint's torsional stiffness K (N.mm/rad); the study measured the
specimen's translational k (N/mm). The pseudo-rigid-body model (Howell, Compliant Mechanisms, 2001,
ch. 5) replaces a flexible beam of length L by a rigid link pivoting a characteristic radius gamma L
from its end: a tip load F = k delta turns the link by delta / (gamma L) against a torque F gamma L,
so K = k (gamma L)^2, and likewise the damping. `designer export --axis theta` derives a rotational
axis this way with gamma = 0.85.

gamma itself is not one number: over the direction of the tip load it runs from about 0.80 to 0.87
(Howell's table for a cantilever with a force at its free end), so the relation carries an
uncertainty of its own, log gamma ~ N(log 0.85, GAMMA_LOG_SD^2), that enters K's interval and every
probability computed from it. The relation fails for beams too short and thick to bend as beams
(shear and the clamp's compliance: the study's beams run from L/h = 1.3 to 15), for deflections
beyond the small-angle range, and for loads other than a tip force; the output says it is derived.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields, replace
from typing import TYPE_CHECKING, Any

import casadi as ca
import numpy as np

from .. import units
from ..study import space
from .prediction import Prediction, ResponseSurface

if TYPE_CHECKING:
    from .surrogate import Surrogate

#: Howell's characteristic radius factor for a cantilever with a force at its free end (designer.joint
#: keeps the same number for the exports, which import no CasADi; a test holds them equal)
PRB_GAMMA = 0.85
#: its range over the tip load's direction, and the log-sd that makes it a 95 % interval
GAMMA_RANGE = (0.80, 0.87)
GAMMA_LOG_SD = math.log(GAMMA_RANGE[1] / GAMMA_RANGE[0]) / (2 * 1.96)
#: the translational axis a rotational goal is carried from
SOURCE_AXIS = "x"


def relation_text(axis: str, source: str = SOURCE_AXIS) -> str:
    """The relation as the output states it."""
    return (
        f"{axis} is derived, not measured: pseudo-rigid-body model K = k_{source} (gamma L)^2, gamma = "
        f"{PRB_GAMMA:g} ({GAMMA_RANGE[0]:g}-{GAMMA_RANGE[1]:g} over the load's direction, in every "
        f"interval and P); it fails for short thick beams and large deflections"
    )


@dataclass
class PRBSurface(ResponseSurface):
    """A translational response carried to a rotational axis: `base` times (gamma L)^2, the
    uncertainty of gamma added to its interval (see the module docstring)."""

    base: ResponseSurface | None = field(default=None, repr=False)

    @classmethod
    def from_base(cls, base: ResponseSurface, response: str, observed: tuple[float, float]) -> PRBSurface:
        copied = {f.name: getattr(base, f.name) for f in fields(ResponseSurface)}
        return cls(**(copied | {"response": response, "observed_range": observed}), base=base)

    @property
    def transform(self) -> str:
        return self.base.transform

    @property
    def predictable(self) -> bool:
        return self.base.predictable

    @property
    def accuracy(self) -> dict[str, float]:
        return self.base.accuracy

    def _t95(self) -> float:
        from scipy.special import stdtrit

        return float(stdtrit(self.base.dof, 0.975))

    def predict(self, X: Any) -> Prediction:
        p = self.base.predict(X)
        scale = (PRB_GAMMA * np.asarray(X["length"], dtype=float)) ** 2
        spread = self._t95() * 2 * GAMMA_LOG_SD  # the relation's half-interval, log space
        value = np.asarray(p.value, dtype=float) * scale
        if self.transform == "log":
            half = np.hypot(np.log(np.asarray(p.high) / np.asarray(p.low)) / 2, spread)
            return Prediction(value, value * np.exp(-half), value * np.exp(half))
        half = np.hypot((np.asarray(p.high) - np.asarray(p.low)) / 2 * scale, value * spread)
        return Prediction(value, value - half, value + half)

    def casadi_function(self) -> ca.Function:
        x = ca.SX.sym("x", len(space.FACTOR_NAMES))
        value, lo, hi = self.base.casadi_function()(x)
        scale = (PRB_GAMMA * x[space.FACTOR_NAMES.index("length")]) ** 2
        spread = self._t95() * 2 * GAMMA_LOG_SD
        out = value * scale
        if self.transform == "log":
            half = ca.sqrt((ca.log(hi / lo) / 2) ** 2 + spread**2)
            bounds = [out * ca.exp(-half), out * ca.exp(half)]
        else:
            half = ca.sqrt(((hi - lo) / 2 * scale) ** 2 + (out * spread) ** 2)
            bounds = [out - half, out + half]
        return ca.Function(self.response, [x], [out, *bounds], ["x"], ["value", "lo", "hi"])

    def to_dict(self) -> dict[str, Any]:
        return self.base.to_dict() | {
            "derived": {"from": self.base.response, "gamma": PRB_GAMMA, "gamma_range": list(GAMMA_RANGE)}
        }


def derived_statement(surrogate: Surrogate, axis: str) -> list[str]:
    """The relation's statement when `axis` of `surrogate` is derived through it, else []."""
    derived = isinstance(surrogate.models.get(f"k_{axis}"), PRBSurface)
    return [relation_text(axis)] if derived else []


def with_axis(surrogate: Surrogate, axis: str) -> Surrogate:
    """`surrogate` with k and c of rotational `axis` derived from its translational x axis when it
    has no such axis of its own; otherwise `surrogate` unchanged (its checks name what is missing)."""
    if not units.is_rotational(axis) or axis in surrogate.axes or SOURCE_AXIS not in surrogate.axes:
        return surrogate
    lengths = np.asarray(surrogate.training["length"], dtype=float)
    scale = (PRB_GAMMA * lengths) ** 2
    models, training = dict(surrogate.models), dict(surrogate.training)
    for q in ("k", "c"):
        source = f"{q}_{SOURCE_AXIS}"
        runs = np.asarray(surrogate.training[source], dtype=float) * scale
        training[f"{q}_{axis}"] = runs.tolist()
        observed = (float(np.nanmin(runs)), float(np.nanmax(runs)))
        models[f"{q}_{axis}"] = PRBSurface.from_base(surrogate.models[source], f"{q}_{axis}", observed)
    return replace(surrogate, models=models, training=training)


def _derived_axes(surrogate: Surrogate) -> list[str]:
    return [a for a in surrogate.axes if isinstance(surrogate.models[f"k_{a}"], PRBSurface)]


def with_runs(surrogate: Surrogate, rows: list[dict[str, float]]) -> Surrogate:
    """`designer.model.calibration.with_runs` for a surrogate that may carry derived axes: runs
    imagined on a derived axis are carried back to x through the relation (gamma at its centre),
    the source surrogate recalibrated on them, and the derived axes derived again."""
    from .calibration import with_runs as recalibrated

    derived = _derived_axes(surrogate)
    if not derived:
        return recalibrated(surrogate, rows)
    source_rows = []
    for row in rows:
        out = dict(row)
        scale = (PRB_GAMMA * float(row["length"])) ** 2
        for a in derived:
            for q in ("k", "c"):
                if f"{q}_{a}" in out:
                    out[f"{q}_{SOURCE_AXIS}"] = out.pop(f"{q}_{a}") / scale
        source_rows.append(out)
    names = {f"{q}_{a}" for a in derived for q in ("k", "c")}
    source = replace(
        surrogate,
        models={r: m for r, m in surrogate.models.items() if r not in names},
        training={c: v for c, v in surrogate.training.items() if c not in names},
    )
    result = recalibrated(source, source_rows)
    for a in derived:
        result = with_axis(result, a)
    return result
