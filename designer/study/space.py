"""The study's six design factors: units, tested ranges, levels, and validation of a design."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

from ..errors import DesignerError

#: Printed shell (perimeter) thickness of the study's specimens, mm (Table 1).
WALL_MM = 0.8
#: Nozzle diameter, mm (Table 1): the narrowest infill line the printer lays.
NOZZLE_MM = 0.4
#: The thinnest printable width or height: two walls and one nozzle line between them, mm.
PRINTABLE_MIN_MM = 2 * WALL_MM + NOZZLE_MM
#: Infill density limits of a slicer, % (the power law needs a density above zero).
DENSITY_LIMITS = (1.0, 100.0)
#: no printer makes a specimen longer than this (mm): a value beyond it is a unit or typing error
#: (k_x fitted on width = 1e308 mm ended as 'SVD did not converge')
BUILD_MAX_MM = 1000.0


@dataclass(frozen=True)
class Factor:
    """One design factor; categorical factors take only their listed levels."""

    name: str
    unit: str
    low: float
    high: float
    levels: tuple[float, ...]
    categorical: bool = False
    label: str = ""
    #: resolution a printer or slicer can realise (continuous factors are rounded to it)
    resolution: float = 0.0

    def describe_range(self) -> str:
        if self.categorical:
            return "one of " + ", ".join(f"{v:g}" for v in self.levels) + f" {self.unit}"
        return f"{self.low:g} to {self.high:g} {self.unit}"


FACTORS: tuple[Factor, ...] = (
    Factor("density", "%", 20, 100, (20, 60, 100), label="infill density", resolution=1.0),
    Factor("length", "mm", 18, 30, (18, 24, 30), label="length", resolution=0.01),
    Factor("width", "mm", 2, 7, (2, 4.5, 7), label="width", resolution=0.01),
    Factor("height", "mm", 4, 14, (4, 9, 14), label="height", resolution=0.01),
    Factor("layer", "mm", 0.12, 0.2, (0.12, 0.16, 0.2), categorical=True, label="layer thickness"),
    Factor("raster", "deg", 0, 45, (0, 45), categorical=True, label="raster angle"),
)
FACTOR_NAMES: tuple[str, ...] = tuple(f.name for f in FACTORS)
CONTINUOUS: tuple[Factor, ...] = tuple(f for f in FACTORS if not f.categorical)
CATEGORICAL: tuple[Factor, ...] = tuple(f for f in FACTORS if f.categorical)
BY_NAME: dict[str, Factor] = {f.name: f for f in FACTORS}


def factor(name: str) -> Factor:
    """The factor called `name`, or a DesignerError listing the known names."""
    try:
        return BY_NAME[name]
    except KeyError:
        raise DesignerError(f"unknown factor '{name}'", f"use one of: {', '.join(FACTOR_NAMES)}") from None


def check_value(name: str, value: float, allow_extrapolation: bool = False) -> float:
    """Check one factor value: finite, a level for categorical factors, in range otherwise."""
    f = factor(name)
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise DesignerError(f"{name} = {value!r} is not a number", f"give {f.describe_range()}") from None
    if not math.isfinite(v):
        raise DesignerError(f"{name} = {value} is not a finite number", f"give {f.describe_range()}")
    if f.categorical:
        for level in f.levels:
            if math.isclose(v, level, rel_tol=1e-9, abs_tol=1e-9):
                return float(level)
        raise DesignerError(
            f"{name} = {v:g} {f.unit} is not a tested level",
            f"{f.label} is categorical in the study: use {f.describe_range()}",
        )
    if not allow_extrapolation and not (f.low - 1e-9 <= v <= f.high + 1e-9):
        raise DesignerError(
            f"{name} = {v:g} {f.unit} is outside the tested range {f.describe_range()}",
            "choose a value inside it, or pass allow_extrapolation=True to accept an unsupported prediction",
        )
    lo, hi = printable_limits(f)
    if not lo - 1e-9 <= v <= hi + 1e-9:
        why = {
            "width": f"two {WALL_MM:g} mm walls and one {NOZZLE_MM:g} mm line need {PRINTABLE_MIN_MM:g} mm",
            "height": f"two {WALL_MM:g} mm walls and one {NOZZLE_MM:g} mm line need {PRINTABLE_MIN_MM:g} mm",
            "density": "a slicer's infill runs from 1 to 100 %",
        }.get(name, "a length must be positive")
        if v > hi and name != "density":
            why = f"larger than a printer's build volume, {BUILD_MAX_MM:g} mm"
        raise DesignerError(
            f"{name} = {v:g} {f.unit} cannot be printed ({why})", f"give {lo:g} to {hi:g} {f.unit}"
        )
    return v


def printable_limits(f: Factor) -> tuple[float, float]:
    """What a printer can make of a continuous factor, beyond any tested range (mm or %)."""
    if f.name in ("width", "height"):
        return PRINTABLE_MIN_MM, BUILD_MAX_MM
    if f.name == "density":
        return DENSITY_LIMITS
    return 1e-9, BUILD_MAX_MM


def extended_range(f: Factor) -> tuple[float, float]:
    """The search range when extrapolation is allowed: half the tested span beyond each end,
    within what can be printed (width and height >= 2.0 mm, infill 1 to 100 %)."""
    half = (f.high - f.low) / 2
    lo, hi = printable_limits(f)
    return max(f.low - half, lo), min(f.high + half, hi)


def infill_matters(params: Mapping[str, float]) -> bool:
    """Whether the infill density changes the part: more than one nozzle line fits inside the walls."""
    core = min(params["width"], params["height"]) - 2 * WALL_MM
    return core > NOZZLE_MM + 1e-9


def extrapolated(params: Mapping[str, float]) -> list[str]:
    """The continuous factors of a design outside their tested range."""
    return [f.name for f in CONTINUOUS if not f.low - 1e-9 <= params[f.name] <= f.high + 1e-9]


def check_design(params: Mapping[str, float], allow_extrapolation: bool = False) -> dict[str, float]:
    """Check a complete design (all six factors) and return it as floats in factor order."""
    unknown = [k for k in params if k not in BY_NAME]
    if unknown:
        factor(unknown[0])
    missing = [n for n in FACTOR_NAMES if n not in params or params[n] is None]
    if missing:
        raise DesignerError(
            f"missing factor(s): {', '.join(missing)}",
            "give all six: " + ", ".join(f"{f.name} ({f.describe_range()})" for f in FACTORS),
        )
    return {n: check_value(n, params[n], allow_extrapolation) for n in FACTOR_NAMES}


def round_printable(params: Mapping[str, float]) -> dict[str, float]:
    """Round continuous factors to what CAD and slicer take (1 % infill, 0.01 mm geometry)."""
    out = dict(params)
    for f in CONTINUOUS:
        if f.name in out and f.resolution:
            out[f.name] = round(round(out[f.name] / f.resolution) * f.resolution, 6)
    return out


def printability_notes(params: Mapping[str, float]) -> list[str]:
    """Plain statements about how the printer realises a design (walls against infill)."""
    notes: list[str] = []
    if not infill_matters(params):
        side = "width" if params["width"] <= params["height"] else "height"
        core = params[side] - 2 * WALL_MM
        notes.append(
            f"at {params[side]:g} mm {side} the two {WALL_MM:g} mm walls leave {core:.1f} mm inside, "
            "at most one nozzle line: the infill density has no effect and the part prints solid"
        )
    return notes
