"""The surrogate plots: design-space surface and volume (pyvista off-screen, HTML scene), leave-one-out."""

from __future__ import annotations

import re

import numpy as np
import pytest
from imagecheck import assert_picture, chromium, dump_dom

from designer.errors import DesignerError
from designer.plots import loo, space
from designer.surrogate import Surrogate


@pytest.fixture(scope="module")
def sur():
    return Surrogate.load()


def test_surface_png_and_html(sur, tmp_path):
    view = space.plot_surface(
        sur, "k_x", "width", "height", tmp_path / "s.png", target=0.8, html=tmp_path / "s.html"
    )
    assert_picture(tmp_path / "s.png", size=space.WINDOW)
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


def test_surface_follows_the_surrogate(sur, tmp_path):
    view = space.plot_surface(sur, "k_x", "width", "height", tmp_path / "s.png", fixed={"raster": 45})
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
    value = sur.model("k_x").predict(corners).value
    assert view.value_range[0] == pytest.approx(min(value), rel=1e-6)
    assert view.value_range[1] == pytest.approx(max(value), rel=1e-6)


def test_volume_png(sur, tmp_path):
    view = space.plot_volume(sur, "k_x", ["width", "height", "density"], tmp_path / "v.png", target=0.8)
    assert_picture(tmp_path / "v.png", size=space.WINDOW)
    assert set(view.held) == {"length", "layer", "raster"}


def test_space_rejects_bad_requests(sur, tmp_path):
    with pytest.raises(DesignerError, match="categorical"):
        space.plot_surface(sur, "k_x", "layer", "height", tmp_path / "s.png")
    with pytest.raises(DesignerError, match="also held fixed"):
        space.plot_surface(sur, "k_x", "width", "height", tmp_path / "s.png", fixed={"width": 3})
    with pytest.raises(DesignerError, match="outside the tested range"):
        space.plot_surface(sur, "k_x", "width", "height", tmp_path / "s.png", fixed={"density": 200})
    with pytest.raises(DesignerError, match="no response"):
        space.plot_surface(sur, "k_z", "width", "height", tmp_path / "s.png")
    with pytest.raises(DesignerError, match=".html"):
        space.plot_surface(sur, "k_x", "width", "height", tmp_path / "s.png", html=tmp_path / "s.txt")
    assert not (tmp_path / "s.png").exists()


def test_loo_table_and_png(sur, tmp_path):
    d = loo.loo_table(sur, "k_x")
    assert len(d) == len(sur.table)
    assert d.covered.mean() == pytest.approx(sur.model("k_x").loo["coverage95"])
    assert np.all(d.lo <= d.predicted) and np.all(d.predicted <= d.hi)
    assert_picture(loo.plot_loo(sur, sur.responses, tmp_path / "loo.png"), min_size=(800, 400))
