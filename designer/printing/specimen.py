"""The specimen as a watertight mesh: the study's beam between two clamping blocks, its print id
engraved into one block.

The study tested a rectangular beam of length l, width b and height h (mm); it gives no figures for
the ends the rig clamps, so the blocks are the same for every specimen and are options (`Clamp`).
The beam lies on the bed (z from 0 to h, printable without supports), centred across the blocks;
x runs along the beam. Meshes are built by manifold3d, whose booleans always return a manifold
(closed, consistently oriented) solid, which a slicer needs; trimesh carries the result (STL export,
checks).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import DesignerError, number_argument
from .glyphs import check_print_id, strokes, text_width


@dataclass(frozen=True)
class Clamp:
    """The clamping blocks at both ends of the beam, mm: the same for every specimen of a study.

    The defaults hold every printable beam (width up to 9.5 mm, height up to 19 mm with
    extrapolation) with room for the print id on top: `length` along the beam, `width` across it,
    `height` from the bed. The id is engraved `depth` deep in strokes `stroke` wide, `margin` from the
    block's edges.
    """

    length: float = 12.0
    width: float = 20.0
    height: float = 20.0
    depth: float = 0.6
    stroke: float = 1.0
    margin: float = 2.0

    def checked(self) -> Clamp:
        """This clamp, every figure positive and the engraving shallower than the block."""
        for name in ("length", "width", "height", "depth", "stroke", "margin"):
            if number_argument(getattr(self, name), f"clamp.{name}", example="12") <= 0:
                raise DesignerError(f"clamp.{name}={getattr(self, name)} is not positive", "give mm > 0")
        if self.depth >= self.height / 2:
            raise DesignerError(
                f"clamp.depth={self.depth} is not under half the block's height {self.height}",
                "give an engraving depth of about 0.6 mm",
            )
        return self


@dataclass(frozen=True)
class Specimen:
    """One print: its id, the six settings and the mesh (mm, the beam along x, on the bed)."""

    print_id: str
    params: dict[str, float]
    clamp: Clamp
    mesh: Any  # trimesh.Trimesh


def beam_box(params: dict[str, float], clamp: Clamp) -> dict[str, float]:
    """Where the beam of `params` sits between the blocks of `clamp` (mm)."""
    length, b, h = params["length"], params["width"], params["height"]
    return {
        "x0": clamp.length,
        "x1": clamp.length + length,
        "y0": (clamp.width - b) / 2,
        "y1": (clamp.width + b) / 2,
        "z0": 0.0,
        "z1": h,
    }


def _box(manifold3d: Any, x0: float, x1: float, y0: float, y1: float, z0: float, z1: float) -> Any:
    return manifold3d.Manifold.cube((x1 - x0, y1 - y0, z1 - z0)).translate((x0, y0, z0))


def _label(manifold3d: Any, print_id: str, clamp: Clamp) -> Any:
    """The id's strokes as a solid to cut from the top of the first block, reading along +y with the
    glyphs' tops towards -x (seen from above, the text runs up the block's face)."""
    glyph_h = clamp.length - 2 * clamp.margin
    room = clamp.width - 2 * clamp.margin
    glyph_w = min(0.6 * glyph_h, (room - (len(print_id) - 1) * clamp.stroke) / len(print_id))
    if glyph_w < 2.5 * clamp.stroke or glyph_h < 4 * clamp.stroke:
        raise DesignerError(
            f"print id {print_id!r} does not fit on a {clamp.length:g} x {clamp.width:g} mm block face "
            f"in {clamp.stroke:g} mm strokes",
            "use a shorter id or a larger block (clamp length and width)",
        )
    y_start = clamp.margin + (room - text_width(print_id, glyph_w, clamp.stroke)) / 2
    x_top = clamp.length - clamp.margin
    top = clamp.height
    cut = None
    for u0, v0, u1, v1 in strokes(print_id, glyph_w, glyph_h, clamp.stroke):
        part = _box(
            manifold3d, x_top - v1, x_top - v0, y_start + u0, y_start + u1, top - clamp.depth, top + 1.0
        )
        cut = part if cut is None else cut + part
    return cut


def specimen(params: dict[str, float], print_id: str, clamp: Clamp | None = None) -> Specimen:
    """The specimen of a design (the six settings, rig units) with `print_id` engraved.

    Raises:
        DesignerError: a beam wider or taller than the blocks, an id that cannot be engraved or
            does not fit, or a clamp figure that is not positive.
    """
    import manifold3d
    import trimesh

    clamp = (clamp or Clamp()).checked()
    print_id = check_print_id(print_id)
    length, b, h = (float(params[n]) for n in ("length", "width", "height"))
    if min(length, b, h) <= 0:
        raise DesignerError(
            f"a beam of {length:g} x {b:g} x {h:g} mm", "give a positive length, width and height"
        )
    if b >= clamp.width or h >= clamp.height:
        raise DesignerError(
            f"the beam ({b:g} mm wide, {h:g} mm high) does not fit the {clamp.width:g} x {clamp.height:g} mm "
            "clamping blocks",
            "give larger blocks (clamp width and height)",
        )
    box = beam_box(params, clamp)
    solid = (
        _box(manifold3d, 0.0, clamp.length, 0.0, clamp.width, 0.0, clamp.height)
        + _box(manifold3d, **box)
        + _box(manifold3d, box["x1"], box["x1"] + clamp.length, 0.0, clamp.width, 0.0, clamp.height)
    )
    solid = solid - _label(manifold3d, print_id, clamp)
    mesh = solid.to_mesh()
    out = trimesh.Trimesh(
        vertices=np.asarray(mesh.vert_properties[:, :3], dtype=np.float64),
        faces=np.asarray(mesh.tri_verts, dtype=np.int64),
        process=True,
    )
    if not out.is_watertight or out.volume <= 0:  # manifold3d guarantees it; a slicer needs it
        raise DesignerError(f"the mesh of print {print_id} is not a closed solid", "report this as a bug")
    return Specimen(print_id=print_id, params=dict(params), clamp=clamp, mesh=out)
