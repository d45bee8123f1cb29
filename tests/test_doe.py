"""Experiment planning: the study's Box-Behnken sheet, the 1960 six-factor design, augmentation."""

import itertools
import json
import subprocess
import sys

import numpy as np
import pandas as pd

from designer.model.surrogate import Surrogate
from designer.study import space
from designer.study.doe import (
    all_continuous_plan,
    augment,
    box_behnken_6,
    near_target,
    printable_grid,
    study_plan,
)

CLI = [sys.executable, "-I", "-c", "from designer_cli.main import main; main()"]


def test_study_plan_is_bbdesign4_for_every_layer_and_raster():
    plan = study_plan(center=3, seed=1)
    assert len(plan) == 6 * (24 + 3) == 162  # about the 160 specimens the study printed
    assert plan["specimen"].is_unique and list(plan["run"]) == list(range(1, 163))
    for (layer, raster), block in plan.groupby(["layer", "raster"]):
        assert layer in (0.12, 0.16, 0.2) and raster in (0, 45)
        assert len(block) == 27
        assert (block["varied"] == 2).sum() == 24 and (block["varied"] == 0).sum() == 3
        for f in space.CONTINUOUS:  # balanced: each continuous factor 6 times low, 6 times high
            counts = block[f.name].value_counts()
            assert counts[f.low] == counts[f.high] == 6
    assert set(plan["density"]) == {20, 60, 100} and set(plan["width"]) == {2, 4.5, 7}
    # randomised, reproducibly
    assert not plan["specimen"].is_monotonic_increasing
    assert plan.equals(study_plan(center=3, seed=1))


def test_box_behnken_1960_six_factor_structure():
    d = box_behnken_6(center=6)
    assert d.shape == (54, 6)
    edge = d[:48]
    assert ((edge != 0).sum(axis=1) == 3).all() and (d[48:] == 0).all()
    assert ((edge == 1).sum(axis=0) == 12).all() and ((edge == -1).sum(axis=0) == 12).all()
    # every pair of factors varies together (a partially balanced incomplete block design)
    for i, j in itertools.combinations(range(6), 2):
        assert ((edge[:, i] != 0) & (edge[:, j] != 0)).any()
    # orthogonal main effects and a rotatable-design balance: each column sums to 0, columns orthogonal
    assert np.allclose(edge.T @ edge, 24 * np.eye(6))
    # not pyDOE3's 66-run bbdesign(6)
    from pyDOE3 import bbdesign

    assert len(bbdesign(6, center=6)) != len(d)


def test_all_continuous_plan_maps_levels():
    plan = all_continuous_plan(center=6, seed=2)
    assert len(plan) == 54
    assert set(plan["raster"]) == {0, 22.5, 45} and set(plan["layer"]) == {0.12, 0.16, 0.2}


class _Linear:
    """A first-order model over the coded continuous factors (a stand-in for one surrogate response)."""

    alpha, sigma, t95, transform = 1e-6, 1.0, 2.0, "none"

    def features(self, X):
        cols = [np.ones(len(X))] + [(X[f.name].to_numpy() - (f.low + f.high) / 2) for f in space.CONTINUOUS]
        return np.column_stack(cols)


def test_d_optimal_augmentation_picks_extremes_and_narrows():
    centre = pd.DataFrame(
        [{f.name: f.levels[1] if not f.categorical else f.levels[0] for f in space.FACTORS}] * 6
    )
    plan, narrowing = augment(8, {"k_x": _Linear()}, centre)
    cont = [f.name for f in space.CONTINUOUS]
    for f in space.CONTINUOUS:
        assert set(plan[f.name]) <= {f.low, f.high}
    assert len(plan[cont].drop_duplicates()) == 8
    nar = narrowing["k_x"]
    assert nar["half_width_after"] < nar["half_width_before"]


def test_i_optimal_augmentation_targets_its_region():
    model = _Linear()
    existing = printable_grid().sample(12, random_state=0)
    target = printable_grid().query("width == 7 and height == 14")
    _, at_target = augment(4, {"k_x": model}, existing, target=target)
    d_plan, _ = augment(4, {"k_x": model}, existing)
    _, d_at_target = augment(
        4, {"k_x": model}, pd.concat([existing, d_plan]), target=target, candidates=existing
    )
    # the targeted picks narrow the PI at the targets at least as much as the D-optimal ones
    assert at_target["k_x"]["half_width_after"] <= d_at_target["k_x"]["half_width_before"] + 1e-12


def test_near_target_selects_closest_predictions():
    grid = printable_grid()
    near = near_target(lambda X: {"k_x": X["width"].to_numpy() / 10}, {"k_x": 0.2}, grid)
    assert (near["width"] == 2).all()


def test_cli_doe_writes_plan(tmp_path):
    out = subprocess.run(
        CLI + ["doe", "--seed", "1", "-o", str(tmp_path / "plan.csv"), "--json"],
        capture_output=True,
        text=True,
    )
    assert out.returncode == 0, out.stderr
    assert len(json.loads(out.stdout)["runs"]) == 162
    assert len(pd.read_csv(tmp_path / "plan.csv")) == 162
    bad = subprocess.run(CLI + ["doe", "--k", "0.8"], capture_output=True, text=True)
    assert bad.returncode == 2 and "--augment" in bad.stderr


def test_augment_with_the_surrogate():
    sur = Surrogate.load()
    near = near_target(lambda X: {r: p.value for r, p in sur.predict(X).items()}, {"k_x": 0.8, "c_x": 2e-3})
    plan, narrowing = augment(6, sur.models, sur.table, target=near)
    assert len(plan) == 6
    space.check_design(plan.iloc[0][list(space.FACTOR_NAMES)].to_dict())
    for resp in sur.responses:
        assert narrowing[resp]["half_width_after"] < narrowing[resp]["half_width_before"]


def test_cli_augment_with_the_shipped_surrogate(tmp_path):
    out = subprocess.run(
        CLI + ["doe", "--augment", "4", "--k", "0.8", "-o", str(tmp_path / "next.csv"), "--json"],
        capture_output=True,
        text=True,
    )
    assert out.returncode == 0, out.stderr
    doc = json.loads(out.stdout)
    assert len(doc["runs"]) == 4 and len(pd.read_csv(tmp_path / "next.csv")) == 4
    for run in doc["runs"]:
        space.check_design({f: run[f] for f in space.FACTOR_NAMES})
    assert set(doc["pi_narrowing"]) == set(Surrogate.load().responses)
    k = doc["pi_narrowing"]["k_x"]
    assert k["half_width_after"] < k["half_width_before"]


def test_augment_toward_an_unreachable_target_is_refused(tmp_path):
    """`doe --augment 3 --k 50`: no printable design is predicted near 50 N/mm; say so, write nothing."""
    import subprocess

    out = tmp_path / "next.csv"
    run = subprocess.run(
        [*CLI, "doe", "--augment", "3", "--k", "50", "-o", out], capture_output=True, text=True
    )
    assert run.returncode == 2 and "outside what printable designs are predicted to reach" in run.stderr
    assert len(run.stderr.strip().splitlines()) == 1 and not out.exists()
