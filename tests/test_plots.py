"""The 2D plots of the data: effects boxplots and the correlation heat map, library and CLI."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from imagecheck import assert_picture

from designer.errors import DesignerError
from designer.plots import common, effects, heatmap
from designer.study import space
from designer.study.data import load_table


@pytest.fixture(scope="module")
def table():
    return load_table()


def test_main_effects_match_the_table(table):
    med = effects.main_effects(table, ["k_x"])
    width = med[med.factor == "width"].set_index("level")
    assert list(width.index) == [2.0, 4.5, 7.0]
    assert width["n"].sum() == len(table)
    assert width.loc[7.0, "median"] == pytest.approx(table.loc[table.width == 7, "k_x"].median())
    # the study: wider specimens are less stiff along x
    assert width.loc[2.0, "median"] > width.loc[7.0, "median"]
    assert set(med.factor) == set(space.FACTOR_NAMES)


def assert_inside(fig) -> None:
    """Everything drawn (texts, legends, ticks) lies inside the figure's canvas: nothing cut at an edge."""
    fig.canvas.draw()
    drawn = fig.get_tightbbox(fig.canvas.get_renderer())
    canvas = fig.bbox_inches
    assert drawn.x0 >= -0.01 and drawn.y0 >= -0.01, (drawn, canvas)
    assert drawn.x1 <= canvas.x1 + 0.01 and drawn.y1 <= canvas.y1 + 0.01, (drawn, canvas)


def tick_labels(ax) -> list[str]:
    """The y tick labels as drawn; each must read back as its tick's value (no rounding away)."""
    ax.figure.canvas.draw()
    lo, hi = ax.get_ylim()
    shown = [
        (t.get_text(), t.get_position()[1]) for t in ax.get_yticklabels() if lo <= t.get_position()[1] <= hi
    ]
    for text, value in shown:
        assert float(text.replace("\u2212", "-")) == pytest.approx(value, rel=1e-9, abs=1e-12), (text, value)
    return [text for text, _ in shown]


def test_effects_png(table, tmp_path):
    fig = effects.plot_effects(table, responses=["c_x", "k_x"])
    assert_inside(fig)
    # c in N.s/mm: tick labels distinct and readable (0.001, 0.002 ...), never all "0.0"
    labels = tick_labels(fig.axes[0])
    assert len(set(labels)) == len(labels) >= 3 and "0.0" not in labels, labels
    tick_labels(fig.axes[len(space.FACTORS)])  # k_x: 0.25 reads 0.25, not 0.2
    assert all(t.get_fontsize() >= 9 for t in fig.axes[0].get_yticklabels())
    path = common.save_figure(fig, tmp_path / "effects.png")
    rgb = assert_picture(path, min_size=(1200, 500))
    # medians are drawn in pure red
    red = (rgb[..., 0] > 0.9) & (rgb[..., 1] < 0.15) & (rgb[..., 2] < 0.15)
    assert red.sum() > 200


def test_correlations_are_pearson(table):
    from designer.study.stats import correlation

    corr = correlation(table, ["c_x", "k_x"])
    assert corr.loc["width", "k_x"] == pytest.approx(np.corrcoef(table.width, table.k_x)[0, 1])
    assert corr.loc["width", "k_x"] < -0.3  # the study's Fig 13: width lowers stiffness
    assert np.allclose(np.diag(corr), 1.0)


def test_plots_draw_into_a_given_empty_figure(table):
    from matplotlib.figure import Figure

    mine = Figure(figsize=(5, 4))
    assert heatmap.plot_heatmap(table, responses=["k_x"], fig=mine) is mine and mine.axes
    with pytest.raises(DesignerError, match="fig= already holds axes"):
        effects.plot_effects(table, responses=["k_x"], fig=mine)


def test_heatmap_png_and_svg(table, tmp_path):
    fig = heatmap.plot_heatmap(table, responses=["c_x", "k_x"])
    assert_inside(fig)
    assert_picture(common.save_figure(fig, tmp_path / "hm.png"))
    svg = common.save_figure(fig, tmp_path / "hm.svg")
    assert svg.read_text().lstrip().startswith("<?xml")


def test_bad_names_are_designer_errors(table, tmp_path):
    with pytest.raises(DesignerError, match="end the file name"):
        common.check_image_path(tmp_path / "x.jpg")
    with pytest.raises(DesignerError, match="no column m_x"):
        common.responses_for(table, ["m"], "x")
    with pytest.raises(DesignerError, match="unknown axis"):
        common.responses_for(table, None, "w")
    with pytest.raises(DesignerError, match="does not exist"):
        common.save_figure(effects.plot_effects(table, responses=["k_x"]), tmp_path / "missing" / "e.png")


def designer(*args: str, cwd) -> subprocess.CompletedProcess:
    """Run the installed `designer` command."""
    exe = Path(sys.executable).with_name("designer")
    return subprocess.run([str(exe), *args], capture_output=True, text=True, cwd=cwd)


def test_cli_effects_and_heatmap(tmp_path):
    run = designer("plot", "effects", "--response", "k", "-o", "e.png", cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    assert "e.png" in run.stdout
    assert_picture(tmp_path / "e.png")
    run = designer("plot", "heatmap", "--json", "-o", "h.png", cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    data = json.loads(run.stdout)
    assert data["correlations"]["k_x"]["k_x"] == pytest.approx(1.0)
    assert_picture(tmp_path / "h.png")


def test_cli_bad_input_is_one_line(tmp_path):
    run = designer("plot", "effects", "--axis", "q", cwd=tmp_path)
    assert run.returncode == 2
    assert run.stderr.startswith("error: unknown axis") and "Traceback" not in run.stderr
    assert not (tmp_path / "effects.png").exists()


def test_timeseries_png_with_reference(tmp_path):
    import pandas as pd

    from designer.plots.timeseries import plot_timeseries

    t = np.linspace(0, 2, 400)
    frame = pd.DataFrame({"t": t, "joint.x.s": np.exp(-t) * np.sin(9 * t), "joint.x.f": np.cos(9 * t)})
    fig = plot_timeseries(frame, reference=frame.iloc[::4])
    assert_inside(fig)
    assert_picture(common.save_figure(fig, tmp_path / "ts.png"), min_size=(800, 300))
    with pytest.raises(DesignerError, match="no column q"):
        plot_timeseries(frame, columns=["q"])
    with pytest.raises(DesignerError, match="no 'time' column"):
        plot_timeseries(frame, time="time")


def _cosim_frame() -> pd.DataFrame:
    """Columns as `designer cosim` writes them for a two-joint arm (hinges, torques in N.m)."""
    t = np.linspace(0, 2, 300)
    cols = {"t": t}
    for i, j in enumerate(("j1", "j2"), start=1):
        cols |= {
            f"robot.{j}.q": np.sin(i * t),
            f"robot.{j}.motor": 0.9 * np.sin(i * t),
            f"robot.{j}.s": 0.1 * np.sin(i * t),
            f"robot.{j}.v": 0.1 * i * np.cos(i * t),
            f"{j}.theta.f": -0.03 * np.sin(i * t),
        }
    return pd.DataFrame(cols)


def test_plot_loo_prints_the_figures_it_draws(tmp_path):
    """The terminal and the figure give the nested leave-one-out Q2 (0.31 for k_x, not the selected
    form's optimistic 0.43), and the legend sits below the data."""
    from designer.model.surrogate import Surrogate
    from designer.plots import loo

    sur = Surrogate.load()
    nested = sur.model("k_x").accuracy["q2"]
    run = designer("plot", "loo", "-o", "loo.png", cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    line = next(ln for ln in run.stdout.splitlines() if ln.startswith("k_x"))
    assert f"nested leave-one-out Q2 {nested:.2f}" in line
    fig = loo.plot_loo(sur, responses=["k_x"])
    assert f"nested Q2 {nested:.2f}" in fig.axes[0].get_title()
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    assert (
        fig.axes[0].get_legend().get_window_extent(renderer).y1 <= fig.axes[0].get_window_extent(renderer).y0
    )
    assert_inside(fig)


def test_loo_keeps_c_above_zero_and_names_the_misses():
    """c is not negative: its intervals (fitted without a log) are cut at 0 and marked, the axes start
    at 0; every run an interval misses is labelled with its run number."""
    from matplotlib.collections import LineCollection

    from designer.model.surrogate import Surrogate
    from designer.plots import loo

    sur = Surrogate.load()
    table = loo.loo_table(sur, "c_x")
    assert (table.lo < 0).any()  # the model's interval does reach below 0
    fig = loo.plot_loo(sur, responses=["c_x"])
    ax = fig.axes[0]
    assert ax.get_ylim()[0] == 0 and ax.get_xlim()[0] == 0
    bars = [seg for c in ax.collections if isinstance(c, LineCollection) for seg in c.get_segments()]
    assert bars and min(float(np.min(seg[:, 1])) for seg in bars) >= 0
    labels = {t.get_text() for t in ax.texts}
    assert labels == {f"run {r}" for r in table.run[~table.covered]}
    assert any(t.get_text().startswith("interval cut at 0") for t in ax.get_legend().get_texts())


def test_signal_units_follow_the_axis():
    from designer.plots.timeseries import signal_unit

    assert signal_unit("j1.theta.f") == "N.m" and signal_unit("joint.x.f") == "N"
    assert signal_unit("robot.j1.q") == "rad" and signal_unit("robot.j2.v") == "rad/s"
    assert signal_unit("joint.x.s") == "m" and signal_unit("joint.x.a") == "m/s²"
    assert signal_unit("hub.f", ["t", "joint.x.s", "hub.f"]) == "N"
    assert signal_unit("hub.q", ["t", "joint.theta.s", "hub.q"]) == "rad"
    assert signal_unit("analytic") == "SI"


def test_timeseries_titles_units_legend_outside_colour_per_joint(tmp_path):
    from designer.plots.timeseries import plot_timeseries

    fig = plot_timeseries(_cosim_frame())
    assert_inside(fig)
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    labels = {ax.get_ylabel(): ax.get_title(loc="left") for ax in fig.axes}
    assert labels == {
        "q (rad)": "angle q",
        "motor (rad)": "motor angle",
        "s (rad)": "deflection s",
        "v (rad/s)": "deflection rate v",
        "f (N.m)": "torque f",
    }
    for ax in fig.axes:  # the legend stands right of the data, not on it
        assert ax.get_legend().get_window_extent(renderer).x0 >= ax.get_window_extent(renderer).x1
    # the cosim plot's panels (angles of several kinds together): a colour per joint, a style per signal
    frame = _cosim_frame()
    angles = [c for c in frame.columns if c.endswith((".q", ".motor", ".s"))]
    fig = plot_timeseries(frame, panels={"angle (rad)": angles})
    lines = {ln.get_label(): ln for ln in fig.axes[0].get_lines()}
    colour = {c: lines[c].get_color() for c in angles}
    style = {c: lines[c].get_linestyle() for c in angles}
    assert colour["robot.j1.q"] == colour["robot.j1.motor"] == colour["robot.j1.s"] != colour["robot.j2.q"]
    assert style["robot.j1.q"] == style["robot.j2.q"] != style["robot.j1.motor"] != style["robot.j1.s"]
    assert style["robot.j1.q"] != style["robot.j1.s"]
    assert fig.axes[0].get_title(loc="left") == "angle q, motor angle, deflection s"
    assert_picture(common.save_figure(fig, tmp_path / "angles.png"), min_size=(800, 200))


def test_coinciding_curves_all_show():
    """Five solutions equal to 1e-9 (the report's FMU step figure): each its own colour and style,
    the first widest, so every curve is visible on top of the others."""
    from designer.plots.timeseries import plot_timeseries

    t = np.linspace(0, 1, 50)
    names = ["analytic", "FMI 2 CS", "FMI 2 ME", "FMI 3 CS", "FMI 3 ME"]
    frame = pd.DataFrame({"t": t} | {n: np.sin(t) for n in names})
    fig = plot_timeseries(frame, panels={"x.s (m)": names})
    lines = fig.axes[0].get_lines()
    assert len({(ln.get_color(), str(ln.get_linestyle())) for ln in lines}) == 5
    widths = [ln.get_linewidth() for ln in lines]
    assert widths == sorted(widths, reverse=True) and widths[0] > widths[-1]


@pytest.mark.parametrize("n", [2, 5])
def test_panel_titles_are_not_built_from_legend_labels(n):
    """A panel of curves with free names (the validation report's FMU and SSP figures) is titled by
    what it shows, from its y label or the caller's title, never by pasting the legend's labels."""
    from designer.plots.timeseries import plot_timeseries

    t = np.linspace(0, 1, 20)
    names = ["analytic", "FMI 2 CoSimulation", "FMI 2 ModelExchange", "libcosim, 2k in the SSV", "fmpy, k"][
        :n
    ]
    errors = [f"{c} error" for c in names[1:]]
    frame = pd.DataFrame({"t": t} | {c: np.sin(t) for c in names + errors})
    fig = plot_timeseries(frame, panels={"x.s (m)": names, "error (m)": errors})
    for ax in fig.axes:
        title = ax.get_title(loc="left")
        labels = [text.get_text() for text in ax.get_legend().get_texts()]
        assert title and not any(label in title for label in labels), (title, labels)
        assert "legend" not in title and " more" not in title
    assert [ax.get_title(loc="left") for ax in fig.axes] == ["deflection s", "error"]
    fig = plot_timeseries(frame, panels={"x.s (m)": names}, titles={"x.s (m)": "under a 2 N step"})
    assert fig.axes[0].get_title(loc="left") == "under a 2 N step"


def test_every_report_figure_has_its_own_caption():
    """Each figure a validation check writes has a caption saying what it shows (not its file name)."""
    from designer.validate import report

    names = set()
    for path in (Path(report.__file__).parent).glob("*.py"):
        names |= set(re.findall(r'figures / "(\w+)\.png"', path.read_text()))
    assert {"fmu_step_response", "ssp_runners", "cosim_convergence"} <= names
    assert names <= set(report.CAPTIONS), names - set(report.CAPTIONS)


def test_importing_and_plotting_leave_the_process_alone(tmp_path):
    """No backend switch, no pyplot, no environment edits: on import, on plotting, on rendering 3D.

    (Matplotlib's own boxplot reads every rcParam, which resolves the default backend as pyplot
    would for anyone; so the check plots the heat map.)
    """
    code = (
        "import os, sys, matplotlib\n"
        "backend = dict.__getitem__(matplotlib.rcParams, 'backend'); env = dict(os.environ)\n"
        "import designer.plots.common, designer.plots.effects, designer.plots.heatmap, designer.plots.loo\n"
        "import designer.plots.space, designer.plots.timeseries, designer.plots.checks\n"
        "import designer.plots.profile\n"
        "assert dict.__getitem__(matplotlib.rcParams, 'backend') is backend, 'backend set on import'\n"
        "from designer.study.data import load_table\n"
        "fig = designer.plots.heatmap.plot_heatmap(load_table(), responses=['k_x'])\n"
        "designer.plots.common.save_figure(fig, sys.argv[1])\n"
        "assert dict.__getitem__(matplotlib.rcParams, 'backend') is backend, 'backend switched'\n"
        "assert 'matplotlib.pyplot' not in sys.modules, 'pyplot imported'\n"
        "from designer.model.surrogate import Surrogate\n"
        "view = designer.plots.space.surface_view(Surrogate.load(), 'k_x', resolution=5)\n"
        "designer.plots.space.render(view, window=(200, 150)).close()\n"
        "assert dict(os.environ) == env, 'environment edited'\n"
        "print('clean')\n"
    )
    env = {k: v for k, v in os.environ.items() if k not in ("MPLBACKEND", "VTK_DEFAULT_OPENGL_WINDOW")}
    run = subprocess.run(
        [sys.executable, "-I", "-c", code, str(tmp_path / "e.png")], capture_output=True, text=True, env=env
    )
    assert run.returncode == 0 and "clean" in run.stdout, run.stderr


def test_readme_shows_one_picture_of_each_figure_command():
    """Every `designer plot` command of README's table has its picture beside it, and each exists."""
    readme = (Path(__file__).resolve().parent.parent / "README.md").read_text()
    pictures = re.findall(r"!\[[^\]]*\]\((docs/figures/[^)]+\.png)\)", readme)
    root = Path(__file__).resolve().parent.parent
    for rel in pictures:
        assert_picture(root / rel)
    commands = set(re.findall(r"`designer plot (\w+)", readme))
    assert commands == {"effects", "heatmap", "loo", "space", "timeseries"}
    for name in (
        "effects",
        "heatmap",
        "loo",
        "space",
        "volume",
        "space_c",
        "timeseries",
        "cosim_plot",
        "profiler",
    ):
        assert f"docs/figures/{name}.png" in pictures, name


def test_plot_loo_of_a_calibrated_surrogate_shows_your_own_prints(tmp_path):
    """The walk of the calibration: `plot loo --surrogate mine.json` drew the study's 44 runs only.
    It shows the user's prints first, each predicted by the calibrated surrogate from every other run
    (README's loop: the stand-in prints, then `designer calibrate`), and says which runs each row is.
    The reference: each print predicted by `designer.calibrate` on the others, recalibrated."""
    import designer as lib
    from designer.model.surrogate import Surrogate
    from designer.plots import loo

    t = load_table().iloc[[3, 12, 30]]
    t.assign(k_x=t.k_x * 0.8).to_csv(tmp_path / "my_prints.csv", index=False)
    run = designer("calibrate", "my_prints.csv", "-o", "mine.json", cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    run = designer("plot", "loo", "--surrogate", "mine.json", "-o", "loo.png", "--json", cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    mine = json.loads(run.stdout)["loo_user"]["k_x"]
    prints = pd.read_csv(tmp_path / "my_prints.csv")
    prior = Surrogate.load()
    for i, row in enumerate(mine["runs"]):
        alone = lib.calibrate(prior, prints.drop(index=i)).predict(prints.iloc[[i]], responses=["k_x"])["k_x"]
        assert row["observed"] == pytest.approx(prints.k_x[i], rel=1e-12)
        for key, want in (("predicted", alone.value), ("lo", alone.low), ("hi", alone.high)):
            assert row[key] == pytest.approx(float(want[0]), rel=1e-9), (i, key)
    # the calibration's own summary of the same leave-one-out
    run = designer("calibrate", "my_prints.csv", "-o", "again.json", "--json", cwd=tmp_path)
    user = json.loads(run.stdout)["responses"]["k_x"]["loo_user"]
    assert mine["mape"] == pytest.approx(user["mape"]) and mine["coverage95"] == user["coverage95"]
    run = designer("plot", "loo", "--surrogate", "mine.json", "-o", "loo.png", cwd=tmp_path)
    assert "k_x: your 3 prints, each predicted by the calibrated surrogate from the others" in run.stdout
    assert "k_x: the study's 44 runs, powerlaw, nested" in run.stdout
    assert_picture(tmp_path / "loo.png")
    # the figure: the user's prints as orange diamonds at those numbers, above the study's runs
    sur = Surrogate.load(tmp_path / "mine.json")
    fig = loo.plot_loo(sur, responses=["k_x"])
    top, bottom = fig.axes
    assert top.get_title().startswith("k_x: your 3 prints") and "the study's runs" in bottom.get_title()
    assert "of 44 runs" in bottom.get_title()
    drawn = [line for line in top.get_lines() if line.get_marker() == "D"]
    xy = np.vstack(
        [np.c_[np.asarray(ln.get_xdata(), float), np.asarray(ln.get_ydata(), float)] for ln in drawn]
    )
    want = np.c_[[r["observed"] for r in mine["runs"]], [r["predicted"] for r in mine["runs"]]]
    np.testing.assert_allclose(xy[np.argsort(xy[:, 0])], want[np.argsort(want[:, 0])], rtol=1e-12)
    assert {t.get_text() for t in top.texts} == {"your print 1", "your print 2", "your print 3"}
    assert_inside(fig)
    # the study's surrogate draws one row, as before
    assert len(loo.plot_loo(prior, responses=["k_x"]).axes) == 1
