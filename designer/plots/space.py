"""The design space in 3D (pyvista, off-screen): the surrogate over two or three factors, others held.

`surface_view` computes the predicted response over two continuous factors with the 95 % prediction
interval as translucent surfaces, the measured runs as points and the target as a contour line;
`volume_view` the response over three continuous factors as isosurfaces, the target's in red. Both
return a `SpaceView`: the numbers and the scene, in the unit cube (each axis scaled to its tested
range). `render` draws a view in its own off-screen pyvista plotter and returns it;
`save_screenshot` writes the picture and `html3d.write_scene` the interactive page.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..errors import DesignerError
from ..files import atomic_path
from ..study import space
from .common import check_image_path, response_label
from .html3d import Layer, Scene

#: the picture's size in pixels (width, height)
WINDOW = (1200, 900)
CMAP = "viridis"
PI_COLOR = (0.35, 0.45, 0.85)
TARGET_COLOR = (0.9, 0.05, 0.05)
#: the study's runs: black at the held values, grey elsewhere (on the floor)
BLACK_GREY = ((0.0, 0.0, 0.0), (0.55, 0.55, 0.55))
#: the user's own prints (a calibrated surrogate's): orange, as the profiler page and `plot loo` draw them
OWN_COLOR = (1.0, 0.5, 0.05)
OWN_FLOOR = (1.0, 0.72, 0.45)


@dataclass
class SpaceView:
    """What a design-space figure shows: the held factors, the response's range, and the scene."""

    response: str
    unit: str
    factors: list[str]
    held: dict[str, float]
    value_range: tuple[float, float]
    target: float | None
    #: share of the drawn grid where the target lies inside the 95 % PI
    target_in_pi: float | None
    #: what `render` and `html3d.write_scene` draw
    scene: Scene = field(repr=False, compare=False)

    def to_dict(self) -> dict[str, Any]:
        """The numbers, JSON-able (the scene left out)."""
        return {k: v for k, v in self.__dict__.items() if k != "scene"}


def held_values(table: pd.DataFrame, free: list[str], fixed: Mapping[str, float] | None) -> dict[str, float]:
    """The values of the factors not drawn: given ones checked, the rest at the level nearest the median."""
    fixed = dict(fixed or {})
    for name in fixed:
        if name in free:
            raise DesignerError(f"{name} is drawn on an axis and also held fixed", f"drop {name} from fixed=")
    held = {}
    for f in space.FACTORS:
        if f.name in free:
            continue
        if f.name in fixed:
            held[f.name] = space.check_value(f.name, fixed[f.name])
        else:
            median = float(table[f.name].median()) if f.name in table else (f.low + f.high) / 2
            held[f.name] = float(min(f.levels, key=lambda v: abs(v - median)))
    return held


def _free_factors(names: list[str]) -> list[space.Factor]:
    factors = [space.factor(n) for n in names]
    for f in factors:
        if f.categorical:
            raise DesignerError(
                f"{f.name} is categorical ({f.describe_range()})",
                "draw continuous factors (density, length, width, height) and hold it in fixed=",
            )
    if len(set(names)) != len(names):
        raise DesignerError(f"a factor is repeated in {', '.join(names)}", "draw distinct factors")
    return factors


def _unit(v: np.ndarray, lo: float, hi: float) -> np.ndarray:
    return (np.asarray(v, float) - lo) / (hi - lo)


def _runs_near(table: pd.DataFrame, held: Mapping[str, float]) -> np.ndarray:
    """Which measured runs were printed at the held values (within 1 % of each factor's range)."""
    mask = np.ones(len(table), bool)
    for name, v in held.items():
        f = space.factor(name)
        mask &= np.abs(table[name].to_numpy(float) - v) <= 0.01 * (f.high - f.low) + 1e-9
    return mask


def _rgb(values: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """Colours of the values on the colour map over [lo, hi] (mid-map when the range is empty)."""
    from matplotlib import colormaps

    v = np.asarray(values, float)
    u = np.full(v.shape, 0.5) if hi - lo <= 1e-12 * max(abs(hi), 1e-300) else (v - lo) / (hi - lo)
    return colormaps[CMAP](np.clip(u, 0, 1))[:, :3]


@contextlib.contextmanager
def _headless() -> Iterator[None]:
    """While a render window is made: ask VTK for EGL when there is no X display, then restore."""
    if os.environ.get("DISPLAY") or "VTK_DEFAULT_OPENGL_WINDOW" in os.environ:
        yield
        return
    os.environ["VTK_DEFAULT_OPENGL_WINDOW"] = "vtkEGLRenderWindow"
    try:
        yield
    finally:
        os.environ.pop("VTK_DEFAULT_OPENGL_WINDOW", None)


def round_ticks(lo: float, hi: float, n: int = 5) -> list[float]:
    """Round tick values within [lo, hi] (1, 2, 2.5 or 5 times a power of ten apart)."""
    from matplotlib.ticker import MaxNLocator

    tol = 1e-9 * (hi - lo)
    ticks = MaxNLocator(nbins=n, steps=[1, 2, 2.5, 5, 10]).tick_values(lo, hi)
    return [float(v) for v in ticks if lo - tol <= v <= hi + tol]


#: tick labels closer than this share of an axis to its ends are left out: the ends are the cube's
#: corners, where two axes' labels would print on top of each other
CORNER = 0.07
#: where each axis's tick labels stand (unit cube, for the fixed camera of `render`): along the
#: front edges of the floor for x and y, up the left vertical edge for z, each pushed off its edge
_TICK_EDGES = {
    0: lambda u: (u, -0.07, 0.0),
    1: lambda u: (1.07, u, 0.0),
    2: lambda u: (-0.06, -0.06, u),
}


def colour_limits(lo: float, hi: float) -> tuple[float, float, int]:
    """The colour scale's ends at round values just outside [lo, hi] and its number of labels, so
    every label of the scale is a round number."""
    from matplotlib.ticker import MaxNLocator

    if hi - lo <= 1e-12 * max(abs(hi), 1e-300):
        return lo, hi, 2
    ticks = MaxNLocator(nbins=5, steps=[1, 2, 2.5, 5, 10]).tick_values(lo, hi)
    ticks = ticks[(ticks >= ticks[ticks <= lo].max()) & (ticks <= ticks[ticks >= hi].min())]
    return float(ticks[0]), float(ticks[-1]), len(ticks)


def _axes(plotter, scene: Scene) -> None:
    """The cube's edges and axis titles, and tick labels at round values (not at the corners)."""
    plotter.show_bounds(
        bounds=[0, 1, 0, 1, 0, 1],
        axes_ranges=[v for r in scene.axis_ranges for v in r],
        xtitle=scene.axis_labels[0],
        ytitle=scene.axis_labels[1],
        ztitle=" ",  # written upright beside the axis by `render`, clear of the tick labels
        color="black",
        font_size=15,
        show_xlabels=False,
        show_ylabels=False,
        show_zlabels=False,
        location="outer",
    )
    for i, ticks in enumerate(axis_ticks(scene)):
        if not ticks:
            continue
        lo, hi = scene.axis_ranges[i]
        plotter.add_point_labels(
            np.array([_TICK_EDGES[i]((v - lo) / (hi - lo)) for v, _ in ticks]),
            [text for _, text in ticks],
            show_points=False,
            shape=None,
            font_size=15,
            text_color="black",
            always_visible=True,
            justification_horizontal="center",
            justification_vertical="center",
        )


def axis_ticks(scene: Scene) -> list[list[tuple[float, str]]]:
    """Per axis of the cube (x, y, z): the ticks `render` labels, (value, text), at round values and
    none within `CORNER` of a shared corner (the z axis keeps its top end)."""
    from .common import decimals_for

    out = []
    for i, (lo, hi) in enumerate(scene.axis_ranges):
        ticks = round_ticks(lo, hi, 5)
        ticks = [v for v in ticks if CORNER <= (v - lo) / (hi - lo) <= 1 - (0 if i == 2 else CORNER)]
        d = decimals_for(tuple(ticks)) if ticks else 0
        out.append([(v, f"{v:.{d}f}" if d < 7 else f"{v:.2g}") for v in ticks])
    return out


def _colorbar(plotter, response: str, lo: float, hi: float, n_labels: int) -> None:
    """The colour scale of the response (an invisible mesh carrying its range), right of the scene."""
    import pyvista as pv

    bar = pv.PolyData(np.zeros((2, 3)))
    bar.point_data[response] = [lo, hi]
    plotter.add_mesh(
        bar,
        scalars=response,
        cmap=CMAP,
        clim=[lo, hi],
        opacity=0.0,
        show_scalar_bar=True,
        scalar_bar_args={
            "title": response_label(response),
            "color": "black",
            "vertical": True,
            "fmt": "%.3g",
            "n_labels": n_labels,
            "title_font_size": 16,
            "label_font_size": 14,
            "position_x": 0.86,
            "position_y": 0.08,
            "width": 0.05,
            "height": 0.5,
        },
    )


def _add_layer(plotter, layer: Layer) -> None:
    kwargs: dict[str, Any] = {"opacity": layer.opacity}
    if layer.rgb is not None:
        kwargs |= {"scalars": (layer.rgb * 255).astype(np.uint8), "rgb": True}
    else:
        kwargs["color"] = layer.color
    if layer.mesh.n_cells and layer.mesh.verts.size == layer.mesh.n_cells * 2:
        kwargs |= {"point_size": layer.size * 4, "render_points_as_spheres": True}
    elif layer.mesh.lines.size:
        kwargs["line_width"] = layer.size * 2
    elif layer.opacity < 1:  # a translucent surface: lit mostly ambient, so it keeps its legend colour
        kwargs |= {"ambient": 0.55, "diffuse": 0.5, "specular": 0.0}
    plotter.add_mesh(layer.mesh, **kwargs)
    if layer.tag:  # written at the mesh's highest point, in its colour
        top = np.asarray(layer.mesh.points)[int(np.argmax(layer.mesh.points[:, 2]))]
        plotter.add_point_labels(
            top[None, :],
            [layer.tag],
            show_points=False,
            shape=None,
            font_size=14,
            bold=True,
            text_color=layer.color,
            always_visible=True,
        )


def render(view: SpaceView, *, window: tuple[int, int] = WINDOW):
    """Draw the view in a new off-screen pyvista plotter of `window` pixels and return the plotter.

    The legend (layer names in their colours, fixed font size) sits in the top right under the
    title, the colour scale below it on the right, both inside the picture. Close the plotter
    (`plotter.close()`) when done with it.
    """
    with _headless():
        import pyvista as pv

        plotter = pv.Plotter(off_screen=True, window_size=list(window))
    plotter.set_background("white")
    layers = view.scene.layers
    for layer in layers:
        _add_layer(plotter, layer)
    lo, hi = view.value_range
    if hi - lo <= 1e-9 * abs(hi):  # a constant response: the scale spans the plotted PI instead
        lo, hi = view.scene.axis_ranges[2]
    _colorbar(plotter, view.response, *colour_limits(lo, hi))
    # the legend: a swatch of each layer's colour and its name, top left under the title
    plotter.add_legend(
        [(layer.name, layer.color) for layer in layers],
        bcolor=None,
        border=False,
        face="rectangle",
        loc="upper left",
        size=(0.0062 * max(len(layer.name) for layer in layers), 0.032 * len(layers)),
    )
    _axes(plotter, view.scene)
    plotter.add_text(
        view.scene.axis_labels[2],
        position=(28, int(0.42 * window[1])),
        font_size=11,
        color="black",
        orientation=90,
    )
    title = view.scene.title
    plotter.add_text(title, font_size=11 if len(title) <= 90 else 9, color="black", position="upper_edge")
    plotter.camera_position = [(2.75, -2.0, 1.95), (0.62, 0.42, 0.5), (0, 0, 1)]
    return plotter


def save_screenshot(plotter, path: str | Path) -> Path:
    """Write the plotter's picture atomically (.png); returns the path.

    Raises:
        DesignerError: the suffix is not an image format, or the folder is missing.
    """
    p = check_image_path(path)
    with atomic_path(p) as tmp:
        plotter.screenshot(str(tmp))
    return p


def own_runs(surrogate, response: str) -> pd.DataFrame | None:
    """Of a calibrated surrogate (`designer.calibrate`): the user's prints that measured `response`
    (the six factors and the response); None for a surrogate not calibrated on it."""
    cal = surrogate.calibration
    if cal is None or response not in cal["table"]:
        return None
    table = cal["table"]
    mine = table[np.isfinite(table[response].to_numpy(float))]
    return mine if len(mine) else None


def _run_layers(points: np.ndarray, near: np.ndarray, *, own: bool = False, study: str = "") -> list[Layer]:
    """The measured runs (unit-cube points): those at the held values in black at their response; the
    others, measured at other held values, grey on the floor (where they lie in x and y only: drawn at
    their response they would stand in stacks that read like replicates). The user's own prints
    (`own`) in orange, larger, light orange on the floor; `study` names the study's runs beside them."""
    import pyvista as pv

    who, colors, size = ("your prints", (OWN_COLOR, OWN_FLOOR), 5) if own else (f"{study}runs", BLACK_GREY, 4)
    layers = []
    if near.any():
        layers.append(
            Layer(
                f"{who} at the held values ({int(near.sum())})",
                pv.PolyData(points[near]),
                color=colors[0],
                size=size,
            )
        )
    if (~near).any():
        floor = points[~near].copy()
        floor[:, 2] = 0.0
        layers.append(
            Layer(
                f"{'your other prints' if own else f'other {study}runs'} ({int((~near).sum())}), "
                "at other held values: on the floor",
                pv.PolyData(floor),
                color=colors[1],
                size=size - 1.5,
            )
        )
    return layers


def _plane_name(model, response: str, pred, target: float, unit: str) -> str:
    """What a target plane means, in `designer suggest`'s words: no design on this plane is predicted
    at the target, and the best chance here of landing within the default tolerance (for a response no
    form predicts, the same chance for every design)."""
    from ..design.targets import TOLERANCE, probability_within

    log = model.transform == "log"
    best = max(
        probability_within(pred.at(i), target, TOLERANCE, model.dof, log=log) for i in range(len(pred.value))
    )
    band = f"+-{100 * TOLERANCE:.0f} %"
    if not model.predictable:
        return f"target {target:g} {unit} (plane): {response} not predictable, P({band}) {best:.2f} anywhere"
    return f"target {target:g} {unit} (plane): not reached here, best P({band}) {best:.2f}"


def _target_layers(
    surface,
    values: np.ndarray,
    target: float,
    unit: str,
    zrange: tuple[float, float],
    plane_name: Callable[[], str],
) -> list[Layer]:
    """The target on a predicted surface: its contour line and that line projected on the floor, or,
    when the surface never reaches it (a flat or distant response), a plane at its level named by
    `plane_name()`."""
    import pyvista as pv

    surface.point_data["value"] = values
    line = surface.contour([target], scalars="value")
    if line.n_points:
        floor = line.copy()
        floor.points[:, 2] = 0.0
        return [
            Layer(f"target {target:g} {unit}", line, color=TARGET_COLOR, size=2.5),
            Layer("target, projected", floor, color=TARGET_COLOR, size=1.5, opacity=0.6),
        ]
    level = float(_unit(target, *zrange))
    plane = pv.Plane(center=(0.5, 0.5, level), direction=(0, 0, 1), i_size=1, j_size=1)
    return [Layer(plane_name(), plane.triangulate(), color=TARGET_COLOR, opacity=0.35)]


def surface_view(
    surrogate,
    response: str,
    *,
    x: str = "width",
    y: str = "height",
    fixed: Mapping[str, float] | None = None,
    target: float | None = None,
    resolution: int = 41,
) -> SpaceView:
    """The response over factors x and y (others held), its 95 % PI, the measured runs and the target.

    Args:
        surrogate: the fitted surrogate; response: e.g. "k_x".
        x, y: continuous factors on the two axes; fixed: values of held factors (others at the level
            nearest the runs' median); target: in rig units; resolution: grid points per axis.

    Raises:
        DesignerError: a categorical or repeated factor on an axis, a held factor out of range, a
            response the surrogate does not have.
    """
    import pyvista as pv

    model = surrogate.model(response)
    fx, fy = _free_factors([x, y])
    table = surrogate.table
    held = held_values(table, [x, y], fixed)
    gx, gy = np.meshgrid(np.linspace(fx.low, fx.high, resolution), np.linspace(fy.low, fy.high, resolution))
    X = pd.DataFrame({n: np.full(gx.size, held.get(n, 0.0)) for n in space.FACTOR_NAMES})
    X[x], X[y] = gx.ravel(), gy.ravel()
    pred = surrogate.predict(X, responses=[response])[response]  # as printed (solid at 2 mm)
    mine = own_runs(surrogate, response)
    zlo, zhi = _z_range(pred, [table, mine], response, target)

    def grid(z: np.ndarray) -> pv.PolyData:
        g = pv.StructuredGrid(
            _unit(gx, fx.low, fx.high), _unit(gy, fy.low, fy.high), _unit(z.reshape(gx.shape), zlo, zhi)
        )
        return g.extract_surface(algorithm="dataset_surface")

    mid = grid(pred.value)
    vlo, vhi = float(pred.value.min()), float(pred.value.max())
    layers = [
        Layer(
            f"{response} predicted",
            mid,
            rgb=_rgb(pred.value, *colour_limits(vlo, vhi)[:2]),
            color=tuple(_rgb(np.array([0.5]), 0, 1)[0]),
        ),
        Layer("95 % PI lower", grid(pred.low), color=PI_COLOR, opacity=0.25),
        Layer("95 % PI upper", grid(pred.high), color=PI_COLOR, opacity=0.25),
    ]
    for runs, own in ((table, False), (mine, True)):
        if runs is not None:  # the user's prints beside the study's runs: the study's named as such
            points = np.c_[_unit(runs[x], fx.low, fx.high), _unit(runs[y], fy.low, fy.high)]
            points = np.c_[points, _unit(runs[response], zlo, zhi)]
            near = _runs_near(runs, held)
            layers += _run_layers(points, near, own=own, study="" if mine is None else "study ")
    share = None
    if target is not None:
        layers += _target_layers(
            mid,
            pred.value,
            target,
            model.unit,
            (zlo, zhi),
            lambda: _plane_name(model, response, pred, target, model.unit),
        )
        share = float(np.mean((pred.low <= target) & (target <= pred.high)))
    held_txt = ", ".join(f"{k} {v:g} {space.factor(k).unit}" for k, v in held.items())
    title = f"{response_label(response)} over {x} and {y}; held: {held_txt}"
    scene = Scene(
        title,
        (f"{x} ({fx.unit})", f"{y} ({fy.unit})", response_label(response)),
        ((fx.low, fx.high), (fy.low, fy.high), (zlo, zhi)),
        layers,
    )
    scene.ticks = axis_ticks(scene)
    return SpaceView(response, model.unit, [x, y], held, (vlo, vhi), target, share, scene)


def volume_view(
    surrogate,
    response: str,
    *,
    factors: list[str],
    fixed: Mapping[str, float] | None = None,
    target: float | None = None,
    resolution: int = 25,
    levels: int = 4,
) -> SpaceView:
    """The response over three factors as isosurfaces (translucent), the target's in red, runs as points.

    Raises:
        DesignerError: not three distinct continuous factors, a held factor out of range, a response
            the surrogate does not have.
    """
    import pyvista as pv

    if len(factors) != 3:
        raise DesignerError(
            f"a volume needs three factors, got {len(factors)}", "give three factors in factors="
        )
    model = surrogate.model(response)
    fs = _free_factors(factors)
    table = surrogate.table
    held = held_values(table, factors, fixed)
    axes = [np.linspace(f.low, f.high, resolution) for f in fs]
    mesh = np.meshgrid(*axes, indexing="ij")
    X = pd.DataFrame({n: np.full(mesh[0].size, held.get(n, 0.0)) for n in space.FACTOR_NAMES})
    for f, m in zip(fs, mesh, strict=True):
        X[f.name] = m.ravel(order="F")
    pred = surrogate.predict(X, responses=[response])[response]  # as printed (solid at 2 mm)
    vol = pv.ImageData(dimensions=(resolution,) * 3, spacing=(1 / (resolution - 1),) * 3)
    vol.point_data["value"] = pred.value
    vlo, vhi = float(pred.value.min()), float(pred.value.max())
    layers = []
    for v in np.linspace(vlo, vhi, levels + 2)[1:-1]:
        iso = vol.contour([v], scalars="value")
        if iso.n_points:
            color = tuple(_rgb(np.array([v]), *colour_limits(vlo, vhi)[:2])[0])
            layers.append(
                Layer(f"{response} = {v:.3g} {model.unit}", iso, color=color, opacity=0.5, tag=f"{v:.3g}")
            )
    share = None
    if target is not None:
        iso = vol.contour([target], scalars="value")
        if iso.n_points:
            layers.append(
                Layer(
                    f"target {target:g} {model.unit}",
                    iso,
                    color=TARGET_COLOR,
                    opacity=0.85,
                    tag=f"target {target:g}",
                )
            )
        share = float(np.mean((pred.low <= target) & (target <= pred.high)))
    layers += _volume_run_layers(table, own_runs(surrogate, response), fs, response, (vlo, vhi))
    held_txt = ", ".join(f"{k} {v:g} {space.factor(k).unit}" for k, v in held.items()) or "none"
    title = f"{response_label(response)} isosurfaces over {', '.join(factors)}; held: {held_txt}"
    scene = Scene(
        title, tuple(f"{f.name} ({f.unit})" for f in fs), tuple((f.low, f.high) for f in fs), layers
    )
    scene.ticks = axis_ticks(scene)
    return SpaceView(response, model.unit, list(factors), held, (vlo, vhi), target, share, scene)


def _z_range(pred, runs: list, response: str, target: float | None) -> tuple[float, float]:
    """The z axis's range: the 95 % PI, every measured run (`runs`: tables, None skipped) and the
    target, widened by 2 % each side."""
    measured = np.concatenate([r[response].to_numpy(float) for r in runs if r is not None])
    zlo = float(min(pred.low.min(), measured.min(), target if target is not None else np.inf))
    zhi = float(max(pred.high.max(), measured.max(), target if target is not None else -np.inf))
    return zlo - 0.02 * (zhi - zlo), zhi + 0.02 * (zhi - zlo)


def _volume_run_layers(table, mine, fs: list, response: str, values: tuple[float, float]) -> list[Layer]:
    """The study's runs as points coloured by the response, and the user's prints (`mine`, or None)
    in orange, in a volume over the factors `fs`."""
    import pyvista as pv

    pts = np.c_[[_unit(table[f.name], f.low, f.high) for f in fs]].T
    layers = [
        Layer(
            f"{'measured' if mine is None else 'study'} runs ({len(table)}), coloured by {response}",
            pv.PolyData(pts),
            rgb=_rgb(table[response].to_numpy(float), *colour_limits(*values)[:2]),
            color=(0.4, 0.4, 0.4),
            size=3,
        )
    ]
    if mine is not None:
        mine_pts = np.c_[[_unit(mine[f.name], f.low, f.high) for f in fs]].T
        layers.append(
            Layer(f"your prints ({len(mine)}), orange", pv.PolyData(mine_pts), color=OWN_COLOR, size=5)
        )
    return layers
