"""Mass of a printed specimen from its geometry, walls, infill and the TPU density."""

from __future__ import annotations

from collections.abc import Mapping

from .study.space import NOZZLE_MM, WALL_MM
from .units import MM, TPU_DENSITY


def specimen_mass(params: Mapping[str, float], material_density: float = TPU_DENSITY) -> float:
    """Mass in kg of the flexing section (l x b x h): solid 0.8 mm walls around an infilled core.

    A core no wider than one nozzle line prints solid, as the slicer fills it with one line.
    The clamped ends are not counted: they do not move with the joint.
    """
    b, h, length = params["width"], params["height"], params["length"]
    core_b, core_h = b - 2 * WALL_MM, h - 2 * WALL_MM
    core = max(core_b, 0.0) * max(core_h, 0.0)
    fill = 1.0 if min(core_b, core_h) <= NOZZLE_MM else params["density"] / 100.0
    area_mm2 = (b * h - core) + core * fill
    return material_density * area_mm2 * length * MM**3
