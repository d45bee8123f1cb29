"""The surrogate plots: design-space surface and volume (pyvista off-screen, HTML scene), leave-one-out."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
from imagecheck import assert_picture, chromium, dump_dom, load_rgb

from designer.errors import DesignerError
from designer.model.surrogate import Surrogate
from designer.plots import common, html3d, loo, space


@pytest.fixture(scope="module")
def sur():
    return Surrogate.load()


def assert_margins_clear(rgb: np.ndarray, px: int = 4) -> None:
    """Nothing drawn in the outer `px` pixels: legends, titles and labels stay inside the picture."""
    for name, strip in (
        ("left", rgb[:, :px]),
        ("right", rgb[:, -px:]),
        ("top", rgb[:px]),
        ("bottom", rgb[-px:]),
    ):
        assert (strip > 0.9).all(), f"something is drawn at the {name} edge"


def axis_labels(view, axis: int) -> list[str]:
    """The tick labels `render` draws on an axis of the cube (0 x, 1 y, 2 z)."""
    return [text for _, text in space.axis_ticks(view.scene)[axis]]


def test_surface_png_and_html(sur, tmp_path):
    view = space.surface_view(sur, "k_x", x="width", y="height", target=0.8)
    plotter = space.render(view)
    assert all(axis_labels(view, 2))
    space.save_screenshot(plotter, tmp_path / "s.png")
    plotter.close()
    assert_margins_clear(assert_picture(tmp_path / "s.png", size=space.WINDOW))
    html3d.write_scene(view.scene, tmp_path / "s.html")
    assert view.held == {"density": 60.0, "length": 24.0, "layer": 0.16, "raster": 0.0}
    lo, hi = view.value_range
    assert lo < 0.8 < hi and 0 < view.target_in_pi <= 1
    page = (tmp_path / "s.html").read_text()
    for name in ("95 % PI lower", "95 % PI upper", "target 0.8 N/mm", "runs at the held values"):
        assert name in page
    exe = chromium()
    if exe is None:
        pytest.skip("no headless Chromium on this machine")
    dom = dump_dom(exe, tmp_path / "s.html")
    drawn = re.search(r'data-drawn="(\d+)"', dom)
    assert drawn and int(drawn.group(1)) > 1000, "the scene's script did not draw"
    # the axis titles and ticks are drawn over the scene (after it), inside the canvas
    labels = json.loads(re.search(r'data-labels="([^"]*)"', dom).group(1).replace("&quot;", '"'))
    titles = [t for t, *_ in labels]
    assert {"width (mm)", "height (mm)", "k_x (N/mm)"} <= set(titles)
    assert all(10 <= x <= 890 and 10 <= y <= 670 for _, x, y in labels), labels
    # the page labels the PNG's round ticks (it labelled five even ones: 0.21, 0.69 ...)
    for ax in space.axis_ticks(view.scene):
        assert [t for _, t in ax] and all(t in titles for _, t in ax), (ax, titles)
    assert "0.5" in titles and "1.0" in titles


def test_small_values_get_readable_ticks(sur, tmp_path):
    """c in N.s/mm: distinct z ticks with their digits (0.00172), never a column of "0.0"."""
    view = space.surface_view(sur, "c_x", resolution=9)
    plotter = space.render(view, window=(600, 450))
    z = axis_labels(view, 2)
    cube = plotter.renderer.cube_axes_actor
    sizes = [cube.GetLabelTextProperty(i).GetFontSize() for i in range(3)]
    sizes += [cube.GetTitleTextProperty(i).GetFontSize() for i in range(3)]
    plotter.close()
    assert min(sizes) >= 14, sizes  # readable ticks and titles (they were 10)
    assert len(set(z)) == len(z) >= 3 and all(float(t) > 0 for t in z[1:]), z
    fig = loo.plot_loo(sur, responses=["c_x"])
    fig.canvas.draw()
    ticks = [t.get_text() for t in fig.axes[0].get_yticklabels() if t.get_text()]
    assert len(set(ticks)) == len(ticks) >= 3, ticks


def test_surface_follows_the_surrogate(sur):
    view = space.surface_view(sur, "k_x", x="width", y="height", fixed={"raster": 45})
    assert view.held["raster"] == 45.0 and view.target is None
    import pandas as pd

    corners = pd.DataFrame(
        {
            "density": 60.0,
            "length": 24.0,
            "width": [2.0, 7.0],
            "height": [4.0, 14.0],
            "layer": 0.16,
            "raster": 45.0,
        }
    )
    value = sur.predict(corners, responses=["k_x"])["k_x"].value  # as printed: solid at 2 mm
    assert view.value_range[0] == pytest.approx(min(value), rel=1e-6)
    assert view.value_range[1] == pytest.approx(max(value), rel=1e-6)
    assert json.loads(json.dumps(view.to_dict()))["response"] == "k_x"


def test_ticks_are_round_and_clear_of_the_corners(sur):
    """Round tick values (1, 2, 2.5 or 5 times a power of ten apart), none where two axes' labels
    meet at a corner of the cube; the colour scale's ends round too."""
    for response in ("k_x", "c_x"):
        view = space.surface_view(sur, response, x="width", y="height", resolution=9)
        for i, ticks in enumerate(space.axis_ticks(view.scene)):
            lo, hi = view.scene.axis_ranges[i]
            values = [v for v, _ in ticks]
            assert len(values) >= 2, (response, i)
            step = values[1] - values[0]
            mantissa = step / 10 ** np.floor(np.log10(step))
            assert any(np.isclose(mantissa, m) for m in (1, 2, 2.5, 5)), (response, i, values)
            assert all(np.isclose(v / step, round(v / step)) for v in values)
            assert all(space.CORNER <= (v - lo) / (hi - lo) for v in values)
            if i < 2:
                assert all((v - lo) / (hi - lo) <= 1 - space.CORNER for v in values)
            assert all(float(text) == pytest.approx(v) for v, text in ticks)
    assert space.colour_limits(0.4429, 1.055) == pytest.approx((0.4, 1.2, 5))


def _any_design() -> dict[str, float]:
    """The design the c_x view holds (c_x is the same everywhere: any design in the tested box)."""
    return {"density": 60.0, "length": 24.0, "width": 4.5, "height": 9.0, "layer": 0.16, "raster": 0.0}


def test_target_plane_when_no_design_reaches_the_target(sur, tmp_path):
    """c_x is flat (not predictable): a target gets a plane at its level, and the CLI says why."""
    view = space.surface_view(sur, "c_x", target=2e-3, resolution=9)
    plane = [layer for layer in view.scene.layers if layer.name.startswith("target 0.002 N.s/mm (plane")]
    assert len(plane) == 1
    # it says what suggest says (issue 36: it said "no design reaches it"): any design meets the
    # target within +-10 % with the same probability
    from designer.design.targets import probability_within

    pred = sur.predict(_any_design(), responses=["c_x"])["c_x"].at(0)
    chance = probability_within(pred, 2e-3, 0.1, sur.model("c_x").dof, log=False)
    assert plane[0].name.endswith(f"c_x not predictable, P(+-10 %) {chance:.2f} anywhere"), plane[0].name
    assert "reaches" not in plane[0].name
    lo, hi = view.scene.axis_ranges[2]
    assert plane[0].mesh.points[:, 2] == pytest.approx((2e-3 - lo) / (hi - lo))
    # a target the surface crosses gets its contour line, no plane
    view = space.surface_view(sur, "k_x", target=0.8, resolution=9)
    names = [layer.name for layer in view.scene.layers]
    assert "target 0.8 N/mm" in names and not any("plane" in n for n in names)
    from clitools import run_process

    run = run_process(["plot", "space", "--response", "c", "--target", "2e-3", "-o", "c.png"], tmp_path)
    assert run.returncode == 0, run.stderr
    assert "c_x is not predictable from the six factors" in run.stdout
    assert_picture(tmp_path / "c.png", size=space.WINDOW)


def test_volume_png(sur, tmp_path):
    view = space.volume_view(sur, "k_x", factors=["width", "height", "density"], target=0.8)
    plotter = space.render(view)
    space.save_screenshot(plotter, tmp_path / "v.png")
    plotter.close()
    assert_margins_clear(assert_picture(tmp_path / "v.png", size=space.WINDOW))
    assert set(view.held) == {"length", "layer", "raster"}
    # each isosurface is labelled with its level in the picture, and drawn in its legend colour
    iso = [layer for layer in view.scene.layers if layer.name.startswith("k_x = ")]
    assert iso and all(layer.tag == layer.name.split(" = ")[1].split()[0] for layer in iso)
    assert len({layer.color for layer in iso}) == len(iso)


def test_space_rejects_bad_requests(sur, tmp_path):
    with pytest.raises(DesignerError, match="categorical"):
        space.surface_view(sur, "k_x", x="layer", y="height")
    with pytest.raises(DesignerError, match="also held fixed"):
        space.surface_view(sur, "k_x", fixed={"width": 3})
    with pytest.raises(DesignerError, match="outside the tested range"):
        space.surface_view(sur, "k_x", fixed={"density": 200})
    with pytest.raises(DesignerError, match="no response"):
        space.surface_view(sur, "k_z")
    view = space.surface_view(sur, "k_x", resolution=5)
    with pytest.raises(DesignerError, match=".html"):
        html3d.write_scene(view.scene, tmp_path / "s.txt")
    assert not list(tmp_path.iterdir())


def test_loo_table_and_png(sur, tmp_path):
    d = loo.loo_table(sur, "k_x")
    assert len(d) == len(sur.table)
    assert d.covered.mean() == pytest.approx(sur.model("k_x").loo["coverage95"])
    assert np.all(d.lo <= d.predicted) and np.all(d.predicted <= d.hi)
    rgb = load_rgb(common.save_figure(loo.plot_loo(sur), tmp_path / "loo.png"))
    assert_picture(tmp_path / "loo.png", min_size=(800, 400))
    assert rgb.shape[1] > rgb.shape[0]


def _orange_pixels(path) -> int:
    """Pixels of the user's prints' orange (`space.OWN_COLOR`, shaded by the light: hue kept)."""
    rgb = load_rgb(path)
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    return int(np.sum((r > 0.6) & (g > 0.35 * r) & (g < 0.7 * r) & (b < 0.25 * r)))


def test_space_of_a_calibrated_surrogate_draws_your_prints(sur, tmp_path):
    """The walk of the calibration: `plot space --surrogate mine.json` drew the study's 44 runs only.
    The user's prints (README's stand-in: three study designs at 0.8 times their k) are drawn where the
    study's runs are, in orange and named in the legend: at the held values at their measured k, the
    others on the floor; in the volume too."""
    import subprocess
    import sys
    from pathlib import Path

    import designer as lib

    t = lib.load_table().iloc[[3, 12, 30]]
    t = t.assign(k_x=t.k_x * 0.8)
    t.to_csv(tmp_path / "my_prints.csv", index=False)
    cal = lib.calibrate(sur, t)
    first = t.iloc[0]
    fix = {n: float(first[n]) for n in ("density", "length", "layer", "raster")}
    view = space.surface_view(cal, "k_x", x="width", y="height", fixed=fix)
    layers = {layer.name: layer for layer in view.scene.layers}
    here = layers["your prints at the held values (1)"]
    assert (
        here.color == space.OWN_COLOR
        and "your other prints (2), at other held values: on the floor" in layers
    )
    zlo, zhi = view.scene.axis_ranges[2]
    want = [(first.width - 2) / 5, (first.height - 4) / 10, (first.k_x - zlo) / (zhi - zlo)]
    np.testing.assert_allclose(np.asarray(here.mesh.points)[0], want, atol=1e-6)
    assert any(name.startswith("study runs at the held values") for name in layers)
    # the study's surrogate: as before, no print of yours
    assert not any("your" in layer.name for layer in space.surface_view(sur, "k_x", fixed=fix).scene.layers)
    names = [
        layer.name
        for layer in space.volume_view(cal, "k_x", factors=["width", "height", "density"]).scene.layers
    ]
    assert "your prints (3), orange" in names
    # the command line, as typed: the PNG shows orange where the study's picture has none
    exe = str(Path(sys.executable).with_name("designer"))
    run = subprocess.run(
        [exe, "calibrate", "my_prints.csv", "-o", "mine.json"], capture_output=True, cwd=tmp_path
    )
    assert run.returncode == 0, run.stderr
    args = [a for n, v in fix.items() for a in ("--fix", f"{n}={v:g}")]
    for name, extra in (("mine.png", ["--surrogate", "mine.json"]), ("study.png", [])):
        run = subprocess.run(
            [exe, "plot", "space", *args, *extra, "-o", name], capture_output=True, text=True, cwd=tmp_path
        )
        assert run.returncode == 0, run.stderr
    assert _orange_pixels(tmp_path / "mine.png") > 100 and _orange_pixels(tmp_path / "study.png") == 0
