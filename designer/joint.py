"""A flexible joint: per-axis m, c, k in rig units with their provenance, and its SI view.

A `Joint` is what every exporter (FMU, Modelica, MJCF, URDF) and the co-simulation consume. It is
built from coefficients typed by hand, from a design through the surrogate, or from a suggestion.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import Any

from . import units
from .errors import DesignerError
from .mass import specimen_mass

#: Howell's pseudo-rigid-body characteristic radius factor for a fixed-guided/cantilever beam
PRB_GAMMA = 0.85


@dataclass(frozen=True)
class AxisCoefficients:
    """One axis of a joint in rig units; `m` may be None (force element needs none)."""

    axis: str
    k: float
    c: float
    m: float | None = None
    k_pi95: tuple[float, float] | None = None
    c_pi95: tuple[float, float] | None = None
    #: where these numbers come from, e.g. "measured", "surrogate", "derived (PRB model)"
    origin: str = "entered by hand"

    def __post_init__(self) -> None:
        units.check_axis(self.axis)
        for q in ("k", "c", "m"):
            v = getattr(self, q)
            if v is None:
                continue
            if not math.isfinite(v) or v < 0 or (q != "c" and v == 0):
                raise DesignerError(
                    f"{q} on axis {self.axis} = {v:g} {units.rig_unit(q, self.axis)} is not a valid value",
                    f"give a finite, {'non-negative' if q == 'c' else 'positive'} number",
                )

    def si(self) -> dict[str, float | None]:
        """m, c, k in SI units (kg or kg.m^2; N.s/m or N.m.s/rad; N/m or N.m/rad)."""
        return {
            "m": None if self.m is None else units.to_si("m", self.axis, self.m),
            "c": units.to_si("c", self.axis, self.c),
            "k": units.to_si("k", self.axis, self.k),
        }


@dataclass(frozen=True)
class Joint:
    """A joint: its axes and a provenance record (print settings, surrogate id, PIs, notes)."""

    name: str
    axes: dict[str, AxisCoefficients]
    provenance: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not self.axes:
            raise DesignerError("a joint needs at least one axis", "give --k and --c for an axis")
        if not self.name.isidentifier():
            raise DesignerError(
                f"joint name '{self.name}' is not an identifier",
                "use letters, digits and underscores, starting with a letter",
            )

    def axis(self, name: str) -> AxisCoefficients:
        try:
            return self.axes[units.check_axis(name)]
        except KeyError:
            raise DesignerError(
                f"joint '{self.name}' has no axis '{name}'", f"it has: {', '.join(self.axes)}"
            ) from None

    def with_masses(self) -> Joint:
        """Fill missing masses from the design's geometry; an error if there is no design."""
        params = self.provenance.get("params")
        out = {}
        for a, ac in self.axes.items():
            if ac.m is not None:
                out[a] = ac
                continue
            if params is None:
                raise DesignerError(
                    f"axis {a} of joint '{self.name}' has no mass",
                    "give --m in kg, or build the joint from a design so its mass follows from geometry",
                )
            m = specimen_mass(params)
            if units.is_rotational(a):
                m = m * (PRB_GAMMA * params["length"] * units.MM) ** 2
            out[a] = replace(ac, m=m)
        prov = dict(self.provenance)
        prov.setdefault("notes", [])
        prov["notes"] = list(prov["notes"]) + [
            "mass from geometry: 0.8 mm solid walls, infilled core, TPU 1210 kg/m^3"
        ]
        return replace(self, axes=out, provenance=prov)

    def to_dict(self) -> dict[str, Any]:
        """Plain data (rig units and SI) for joint.json and --json output."""
        return {
            "name": self.name,
            "axes": {
                a: {
                    "rig": {"k": ac.k, "c": ac.c, "m": ac.m, "k_pi95": ac.k_pi95, "c_pi95": ac.c_pi95},
                    "rig_units": {q: units.rig_unit(q, a) for q in ("k", "c", "m")},
                    "si": ac.si(),
                    "si_units": {q: units.si_unit(q, a) for q in ("k", "c", "m")},
                    "origin": ac.origin,
                }
                for a, ac in self.axes.items()
            },
            "provenance": self.provenance,
        }


def rotational_from_translational(ac: AxisCoefficients, axis: str, length_mm: float) -> AxisCoefficients:
    """Pseudo-rigid-body conversion: K_rot = k (gamma L)^2, likewise c and the inertia of m."""
    if units.is_rotational(ac.axis) or not units.is_rotational(axis):
        raise DesignerError(
            f"cannot derive axis {axis} from axis {ac.axis}",
            "the PRB conversion maps a translational axis onto a rotational one",
        )
    arm_mm = PRB_GAMMA * length_mm
    scale = arm_mm**2  # N/mm * mm^2 = N.mm/rad

    def pi(p):
        return None if p is None else (p[0] * scale, p[1] * scale)

    return AxisCoefficients(
        axis=axis,
        k=ac.k * scale,
        c=ac.c * scale,
        m=None if ac.m is None else ac.m * (arm_mm * units.MM) ** 2,
        k_pi95=pi(ac.k_pi95),
        c_pi95=pi(ac.c_pi95),
        origin=f"derived, not measured: pseudo-rigid-body model from axis {ac.axis}, "
        f"K = k (gamma L)^2, gamma = {PRB_GAMMA}, L = {length_mm:g} mm",
    )


def from_coefficients(
    coefficients: Mapping[str, Mapping[str, float | None]], name: str = "FlexJoint"
) -> Joint:
    """A joint from numbers typed by hand: {axis: {"k": .., "c": .., "m": ..}} in rig units."""
    axes = {
        a: AxisCoefficients(axis=a, k=float(v["k"]), c=float(v["c"]), m=v.get("m"))
        for a, v in coefficients.items()
    }
    return Joint(name=name, axes=axes, provenance={"source": "entered by hand"})
