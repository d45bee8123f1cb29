"""A self-contained interactive HTML view of a 3D scene: no server, no network, no WebGL needed.

The page embeds the triangles, lines and points of the scene's pyvista meshes (in the unit cube the
scene is drawn in) and a small canvas renderer: drag to rotate, wheel to zoom, click a layer's name
to hide or show it. Translucent layers are drawn back to front, so the 95 % PI surfaces stay readable.
"""

from __future__ import annotations

import html
import json
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import DesignerError
from ..files import atomic_write

#: above this many triangles a layer is decimated before embedding (keeps the page fast)
MAX_TRIANGLES = 12000


@dataclass
class Layer:
    """One mesh of the scene with how to draw it: uniform colour or per-point RGB (0..1)."""

    name: str
    mesh: Any  # pyvista.PolyData in scene (unit cube) coordinates
    color: tuple[float, float, float] = (0.5, 0.5, 0.5)
    rgb: np.ndarray | None = None
    opacity: float = 1.0
    size: float = 2.0  # point size or line width, pixels
    tag: str | None = None  # a label written on the mesh in the PNG (an isosurface's level)


@dataclass
class Scene:
    """Layers in the unit cube plus what the cube's axes stand for."""

    title: str
    axis_labels: tuple[str, str, str]
    axis_ranges: tuple[tuple[float, float], tuple[float, float], tuple[float, float]]
    layers: list[Layer] = field(default_factory=list)
    #: per axis, the (value, text) ticks to label (round values clear of the corners); None: five even ones
    ticks: list[list[tuple[float, str]]] | None = None


def _payload(layer: Layer) -> dict[str, Any]:
    """The layer as flat arrays: positions, per-point colours (0..255), triangles, segments, points."""
    mesh, rgb = layer.mesh, layer.rgb
    if mesh.faces.size:
        mesh = mesh.triangulate()
        if rgb is None and mesh.n_cells > MAX_TRIANGLES:
            mesh = mesh.decimate(1 - MAX_TRIANGLES / mesh.n_cells)
    tris = mesh.faces.reshape(-1, 4)[:, 1:] if mesh.faces.size else np.empty((0, 3), int)
    segs = []
    if mesh.lines.size:
        cells, i = mesh.lines, 0
        while i < cells.size:
            n = cells[i]
            ids = cells[i + 1 : i + 1 + n]
            segs.extend(zip(ids[:-1], ids[1:], strict=True))
            i += n + 1
    verts = mesh.verts.reshape(-1, 2)[:, 1] if mesh.verts.size else np.empty(0, int)
    colors = np.tile(layer.color, (mesh.n_points, 1)) if rgb is None else np.asarray(rgb)
    return {
        "name": layer.name,
        "opacity": float(layer.opacity),
        "size": float(layer.size),
        "pos": np.round(np.asarray(mesh.points, float), 4).ravel().tolist(),
        "col": np.clip(np.round(colors * 255), 0, 255).astype(int).ravel().tolist(),
        "tri": np.asarray(tris, int).ravel().tolist(),
        "seg": np.asarray(segs, int).ravel().tolist(),
        "pts": np.asarray(verts, int).ravel().tolist(),
    }


def write_scene(scene: Scene, path: str | Path) -> Path:
    """Write the scene as one HTML file that opens in any browser (no server, no network).

    Raises:
        DesignerError: the path does not end in .html or .htm, or its folder is missing.
    """
    if Path(path).suffix.lower() not in (".html", ".htm"):
        raise DesignerError(
            f"cannot write an HTML scene to '{Path(path).name}'", "end the file name in .html"
        )
    data = {
        "title": scene.title,
        "labels": list(scene.axis_labels),
        "ranges": [list(map(float, r)) for r in scene.axis_ranges],
        "layers": [_payload(layer) for layer in scene.layers],
        "ticks": None if scene.ticks is None else [[[float(v), str(t)] for v, t in ax] for ax in scene.ticks],
    }
    template = (resources.files("designer.plots") / "scene.html").read_text(encoding="utf-8")
    page = template.replace("__TITLE__", html.escape(scene.title)).replace(
        "__DATA__", json.dumps(data, separators=(",", ":")).replace("</", "<\\/")
    )
    path = Path(path)
    with atomic_write(path, "w", encoding="utf-8") as fh:
        fh.write(page)
    return path
