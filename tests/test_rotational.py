"""Joint-level goals: `suggest`/`next --axis theta --k N.mm/rad` through the pseudo-rigid-body relation
K = k_x (gamma L)^2 that `export --axis theta` uses, the relation's own uncertainty (gamma 0.80-0.87)
in P: checked against a Monte Carlo of the study's predictive t and gamma drawn apart from designer."""

from __future__ import annotations

import json

import numpy as np
import pytest
from clitools import run_inprocess
from scipy import stats

import designer
from designer.model.surrogate import Surrogate


def test_suggest_theta_states_the_relation_and_p_holds_its_uncertainty(tmp_path, capsys):
    code, out, err = run_inprocess(
        ["suggest", "--axis", "theta", "--k", "800", "--top", "1", "--json"], capsys
    )
    assert code == 0, err
    sug = json.loads(out)
    best = sug["candidates"][0]
    k = best["predicted"]["k"]
    assert abs(k["value"] / 800 - 1) <= 0.1 and sug["units"]["k"] == "N.mm/rad"
    assert any("K = k_x (gamma L)^2, gamma = 0.85" in s for s in sug["statements"])
    # P by Monte Carlo: k_x from the study's predictive Student t in log space at the design, gamma
    # log-normal with its 95 % range 0.80-0.87, K = k_x (gamma L)^2
    design = best["params"]
    model = Surrogate.load().model("k_x")
    px = model.predict({n: np.array([float(v)]) for n, v in design.items()}).at(0)
    t95 = stats.t.ppf(0.975, model.dof)
    s = np.log(px.high / px.low) / (2 * t95)
    rng = np.random.default_rng(0)
    n = 400_000
    kx = px.value * np.exp(s * stats.t.rvs(model.dof, size=n, random_state=rng))
    gamma = 0.85 * np.exp(rng.normal(0.0, np.log(0.87 / 0.80) / (2 * 1.96), n))
    big_k = kx * (gamma * design["length"]) ** 2
    p = np.mean(np.abs(big_k / 800 - 1) <= 0.1)
    assert best["p_within"] == pytest.approx(p, abs=0.01)
    # without the relation's uncertainty P would be higher: it is in P
    exact = np.mean(np.abs(kx * (0.85 * design["length"]) ** 2 / 800 - 1) <= 0.1)
    assert exact > best["p_within"]

    # export --axis theta of that design gives the suggested K back, in rig units and SI
    (tmp_path / "s.json").write_text(out)
    code, out, err = run_inprocess(
        [
            "export",
            "fmu",
            "--from",
            tmp_path / "s.json",
            "--axis",
            "theta",
            "--platforms",
            "host",
            "-o",
            tmp_path / "j.fmu",
            "--json",
        ],
        capsys,
    )
    assert code == 0, err
    axis = json.loads(out)["joint"]["axes"]["theta"]
    assert axis["rig"]["k"] == pytest.approx(k["value"], rel=1e-12)
    assert axis["si"]["k"] == pytest.approx(k["value"] * 1e-3, rel=1e-12)  # N.mm/rad -> N.m/rad
    args = [f"--{n}={v}" for n, v in design.items()]
    code, out, err = run_inprocess(
        [
            "export",
            "fmu",
            *args,
            "--axis",
            "theta",
            "--platforms",
            "host",
            "-o",
            tmp_path / "d.fmu",
            "--json",
        ],
        capsys,
    )
    assert code == 0, err
    assert json.loads(out)["joint"]["axes"]["theta"]["rig"]["k"] == pytest.approx(k["value"], rel=1e-9)


def test_next_and_the_library_take_a_rotational_goal(capsys):
    code, out, err = run_inprocess(["next", "--axis", "theta", "--k", "800", "--n", "1"], capsys)
    assert code == 0, err
    assert "theta is derived, not measured" in " ".join(out.split())
    sug = designer.suggest(Surrogate.load(), k=800, axis="theta", top=1)
    assert abs(sug.candidates[0].predicted["k"].value / 800 - 1) <= 0.1


def test_one_relation_for_goals_and_exports():
    """joint.py keeps its own copy of gamma (it is imported without CasADi); they must agree."""
    from designer.joint import PRB_GAMMA
    from designer.model import rotational

    assert rotational.PRB_GAMMA == PRB_GAMMA
