"""Axes and units: the only place that converts between the rig's units and SI.

Tables, CLI flags and printed output use the rig's units (lengths mm; k N/mm, c N.s/mm for the
translational axes, k N.mm/rad, c N.mm.s/rad for the rotational ones; mass kg, inertia kg.m^2).
FMUs, Modelica, MJCF and URDF use SI.
"""

from __future__ import annotations

import math

from .errors import DesignerError

TRANSLATIONAL: tuple[str, ...] = ("x", "y", "z")
ROTATIONAL: tuple[str, ...] = ("theta", "phi", "psi")
AXES: tuple[str, ...] = TRANSLATIONAL + ROTATIONAL
#: the coefficients of one axis, m r'' + c r' + k r = F
QUANTITIES: tuple[str, ...] = ("m", "c", "k")

# (rig unit, SI unit, factor such that SI = factor * rig) per quantity and axis kind
_UNITS: dict[tuple[str, bool], tuple[str, str, float]] = {
    ("k", False): ("N/mm", "N/m", 1e3),
    ("c", False): ("N.s/mm", "N.s/m", 1e3),
    ("m", False): ("kg", "kg", 1.0),
    ("k", True): ("N.mm/rad", "N.m/rad", 1e-3),
    ("c", True): ("N.mm.s/rad", "N.m.s/rad", 1e-3),
    ("m", True): ("kg.m^2", "kg.m^2", 1.0),
    # the axis' coordinate and its load
    ("r", False): ("mm", "m", 1e-3),
    ("r", True): ("rad", "rad", 1.0),
    ("F", False): ("N", "N", 1.0),
    ("F", True): ("N.mm", "N.m", 1e-3),
    # a rig log's inertia coefficient F / r'' (N over mm/s^2, N.mm over rad/s^2) against m in kg, kg.m^2
    ("m_log", False): ("N.s^2/mm", "kg", 1e3),
    ("m_log", True): ("N.mm.s^2/rad", "kg.m^2", 1e-3),
}

MM = 1e-3  # metres per millimetre
#: density of 95A TPU, kg/m^3 (about 1.21 g/cm^3)
TPU_DENSITY = 1210.0


def check_axis(axis: str) -> str:
    """Return `axis` if it is one of the six, else raise a DesignerError listing them."""
    if not isinstance(axis, str) or axis not in AXES:
        raise DesignerError(f"unknown axis '{axis}'", f"use one of: {', '.join(AXES)}")
    return axis


def is_rotational(axis: str) -> bool:
    return check_axis(axis) in ROTATIONAL


def _entry(quantity: str, axis: str) -> tuple[str, str, float]:
    try:
        return _UNITS[(quantity, is_rotational(axis))]
    except KeyError:
        raise DesignerError(f"unknown quantity '{quantity}'", "use m, c, k, r, F or m_log") from None


def rig_unit(quantity: str, axis: str) -> str:
    """The rig (table and CLI) unit of `quantity` on `axis`, e.g. rig_unit('k', 'x') == 'N/mm'."""
    return _entry(quantity, axis)[0]


def si_unit(quantity: str, axis: str) -> str:
    """The SI unit of `quantity` on `axis`, e.g. si_unit('k', 'x') == 'N/m'."""
    return _entry(quantity, axis)[1]


def to_si(quantity: str, axis: str, value: float) -> float:
    """Convert a value in rig units to SI."""
    return value * _entry(quantity, axis)[2]


def from_si(quantity: str, axis: str, value: float) -> float:
    """Convert a value in SI to rig units."""
    return value / _entry(quantity, axis)[2]


def fmt(value: float, quantity: str, axis: str, digits: int = 4) -> str:
    """A value with its rig unit, for people: fmt(0.8, 'k', 'x') == '0.8 N/mm'."""
    return f"{value:.{digits}g} {rig_unit(quantity, axis)}"


#: per (quantity, rotational) of a UsdPhysics joint value: the powers of kilogramsPerUnit and of
#: metersPerUnit in its stage unit, whether it is per degree (1) or in degrees (-1), and its unit in a
#: stage of 1 kg and 1 m per unit. Quantities: k, c (drive stiffness, damping), m (armature), r (drive
#: target, limits), F (drive maxForce)
_USD: dict[tuple[str, bool], tuple[int, int, int, str]] = {
    ("k", False): (1, 0, 0, "N/m"),
    ("c", False): (1, 0, 0, "N.s/m"),
    ("m", False): (1, 0, 0, "kg"),
    ("r", False): (0, 1, 0, "m"),
    ("F", False): (1, 1, 0, "N"),
    ("k", True): (1, 2, 1, "N.m/deg"),
    ("c", True): (1, 2, 1, "N.m.s/deg"),
    ("m", True): (1, 2, 0, "kg.m^2"),
    ("r", True): (0, 0, -1, "deg"),
    ("F", True): (1, 2, 0, "N.m"),
}


def _usd_entry(quantity: str, rotational: bool) -> tuple[int, int, int, str]:
    try:
        return _USD[(quantity, rotational)]
    except KeyError:
        raise DesignerError(f"unknown USD quantity '{quantity}'", "use k, c, m, r or F") from None


def usd_factor(quantity: str, rotational: bool, meters_per_unit: float, kilograms_per_unit: float) -> float:
    """The factor such that USD = factor * SI for a joint value in a stage with these units.

    UsdPhysics states angular drives per degree (stiffness N.m/deg, damping N.m.s/deg, targetPosition
    and limits in degrees) and everything else in the stage's units: a stage unit of force is
    kilogramsPerUnit * metersPerUnit N, of torque kilogramsPerUnit * metersPerUnit^2 N.m. So a linear
    stiffness in N/m becomes k / kilogramsPerUnit, an angular one k * (pi / 180) / (kilogramsPerUnit *
    metersPerUnit^2); a linear position r / metersPerUnit, an angular one degrees(r).
    """
    kg, m, deg, _ = _usd_entry(quantity, rotational)
    return (math.pi / 180) ** deg / (kilograms_per_unit**kg * meters_per_unit**m)


def usd_unit(quantity: str, rotational: bool) -> str:
    """The unit of a UsdPhysics joint value in a stage of 1 kg and 1 m per unit, e.g. 'N.m/deg'."""
    return _usd_entry(quantity, rotational)[3]
