"""The design loop on files, as README shows it: `next` -> `print` (plate and runs table) ->
PrusaSlicer slices the plate (G-code checked) -> rig logs of those prints simulated from the physics
(tests/physics_logs.py) for a printer of tests/printers.py -> `identify --runs` fills the table ->
`calibrate` -> `next`; and the slips the table guards against (a k in N/m, a load logged in kN, a
missing column), each one line and exit 2."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from clitools import assert_clean_failure, run_inprocess
from physics_logs import make_log
from test_cli_campaign import SIX
from test_printing import SLICER, check_gcode, slice_

from designer.model.surrogate import Surrogate

sys.path.insert(0, str(Path(__file__).parent))
import printers  # noqa: E402

FACTORS = ["density", "length", "width", "height", "layer", "raster"]
HEADERS = ["density [%]", "length [mm]", "width [mm]", "height [mm]", "layer [mm]", "raster [deg]"]


def rig_log(
    folder: Path, print_id: str, design: dict, k: float, c: float, *, load_scale: float = 1.0, seed: int = 0
) -> Path:
    """The rig's log of one print (60 s at 500 Hz) and its sidecar naming the print, as a rig's
    software would write them."""
    log = make_log({"x": {"k": k, "c": c, "m": 2e-3, "amplitude": 1.0}}, duration=60.0, rate=500.0, seed=seed)
    log["Fx"] *= load_scale
    path = folder / f"{print_id.lower()}_run.csv"
    log.to_csv(path, index=False)
    path.with_suffix(".json").write_text(json.dumps({"print": print_id, "factors": design}))
    return path


@pytest.fixture(scope="module")
def printer():
    return printers.Printer(seed=7)


def test_whole_loop_on_files(tmp_path, monkeypatch, capsys, printer):
    monkeypatch.chdir(tmp_path)
    code, out, err = run_inprocess(["next", "--k", "0.8", "--n", "3", "--json"], capsys)
    assert code == 0, err
    Path("next.json").write_text(out)
    code, out, err = run_inprocess(["print", "--from", "next.json", "-o", "prints"], capsys)
    assert code == 0, err
    runs = pd.read_csv("prints/runs.csv")
    assert list(runs["print"]) == ["P1", "P2", "P3"]
    designs = [dict(zip(FACTORS, row, strict=True)) for row in runs[HEADERS].to_numpy(dtype=float)]
    proposed = [p["params"] for p in json.loads(Path("next.json").read_text())["prints"]]
    for design, asked in zip(designs, proposed, strict=True):  # as proposed; the height in whole layers
        assert all(design[n] == pytest.approx(asked[n]) for n in FACTORS if n != "height")
        assert abs(design["height"] - asked["height"]) <= design["layer"] / 2 + 1e-9
    if SLICER is not None:  # the plate as the printer gets it
        moves = slice_(["prints/plate.3mf"], tmp_path / "plate.gcode")
        for print_id, design in zip(runs["print"], designs, strict=True):
            check_gcode(moves, print_id, design)
    truth = pd.DataFrame(designs)
    k, c = printer.k(truth), printer.c(truth)
    logs = [
        rig_log(tmp_path, p, d, k[i], c[i], seed=i)
        for i, (p, d) in enumerate(zip(runs["print"], designs, strict=True))
    ]

    # two prints measured: the table fills their rows; calibrate leaves the third out and says so
    code, out, err = run_inprocess(["identify", *logs[:2], "--runs", "prints/runs.csv"], capsys)
    assert code == 0, err
    assert "filled P1, P2 in prints/runs.csv; not measured yet: P3" in " ".join(out.split())
    code, out, err = run_inprocess(["calibrate", "prints/runs.csv", "-o", "mine.json"], capsys)
    assert code == 0, err
    assert "2 run(s) of yours" in out and "not measured yet, left out: P3" in out
    # the third: every row filled, with k and c within 1 % of the printer's truth
    code, out, err = run_inprocess(["identify", logs[2], "--runs", "prints/runs.csv"], capsys)
    assert code == 0, err
    filled = pd.read_csv("prints/runs.csv")
    assert np.allclose(filled["k_x [N/mm]"], k, rtol=0.01) and np.allclose(
        filled["c_x [N.s/mm]"], c, rtol=0.03
    )
    assert list(filled["log"]) == [str(p) for p in logs]
    code, out, err = run_inprocess(["calibrate", "prints/runs.csv", "-o", "mine.json", "--json"], capsys)
    assert code == 0, err
    assert json.loads(out)["n_runs"] == 3
    mine = Surrogate.load(tmp_path / "mine.json")
    at = mine.predict(truth, responses=["k_x"])["k_x"]
    assert np.all((at.low <= k) & (k <= at.high)) and np.allclose(at.value, k, rtol=0.05)
    code, out, err = run_inprocess(["next", "--k", "0.8", "--n", "3", "--surrogate", "mine.json"], capsys)
    assert code == 0, err
    assert "Design #1 now" in out
    # one story per output: suggest says which printer it assumes, and once calibrated, c_x (now
    # pinned at the printed designs) is no longer said to be the same for every design
    code, out, err = run_inprocess(["suggest", "--k", "0.8", "--json"], capsys)
    study = said(json.loads(out))
    code, out, err = run_inprocess(["suggest", "--k", "0.8", "--surrogate", "mine.json", "--json"], capsys)
    yours = said(json.loads(out))
    assert any(s.startswith("printer: the study's own") for s in study)
    assert any(s.startswith("printer: yours, the study calibrated on 3 run(s)") for s in yours)
    assert not any("every design gets the same prediction" in s for s in yours), yours


def said(suggestion: dict) -> list[str]:
    """Every sentence a suggest --json output states."""
    return suggestion["statements"] + [p["statement"] for p in suggestion["predictability"].values()]


def _template(tmp_path: Path, capsys) -> Path:
    args = ["print", *SIX]
    code, _, err = run_inprocess([*args, "-o", tmp_path / "one"], capsys)
    assert code == 0, err
    return tmp_path / "one" / "runs.csv"


def test_a_k_in_n_per_m_is_refused_naming_the_unit(tmp_path, capsys, printer):
    runs = _template(tmp_path, capsys)
    table = pd.read_csv(runs)
    table.loc[0, "k_x [N/mm]"], table.loc[0, "c_x [N.s/mm]"] = 930.0, 2.2e-3  # 0.93 N/mm typed in N/m
    table.to_csv(runs, index=False)
    code, _, err = run_inprocess(["calibrate", runs, "-o", tmp_path / "mine.json"], capsys)
    assert_clean_failure(code, err, allowed=(2,))
    assert (
        "k_x of print P1 is 930 N/mm" in err
        and "N/m rather than N/mm" in err
        and "--accept-implausible" in err
    )
    code, _, err = run_inprocess(
        ["calibrate", runs, "--accept-implausible", "-o", tmp_path / "mine.json"], capsys
    )
    assert code == 0, err


def test_a_load_logged_in_kn_is_refused_naming_the_unit(tmp_path, capsys):
    runs = _template(tmp_path, capsys)
    design = dict(zip(FACTORS, [60.0, 24.0, 4.5, 9.0, 0.16, 0.0], strict=True))
    log = rig_log(tmp_path, "P1", design, 0.9, 2.2e-3, load_scale=1e-3)
    # identify itself fails such a log (exit 1, the reason printed) and fills nothing
    code, out, err = run_inprocess(["identify", log, "--runs", runs], capsys)
    assert_clean_failure(code, err, allowed=(1,))
    assert "in kN" in " ".join(out.split()), out
    assert pd.read_csv(runs)["k_x [N/mm]"].isna().all()
    # the same k typed into the table by hand: calibrate refuses it, naming the unit
    table = pd.read_csv(runs)
    table.loc[0, "k_x [N/mm]"], table.loc[0, "c_x [N.s/mm]"] = 0.0009, 2.2e-6
    table.to_csv(runs, index=False)
    code, _, err = run_inprocess(["calibrate", runs], capsys)
    assert_clean_failure(code, err, allowed=(2,))
    assert "k_x of print P1 is 0.0009" in err and "load logged in kN" in err, err


@pytest.mark.parametrize(
    ("drop", "words"),
    [("c_x [N.s/mm]", "k_x without c_x"), ("height [mm]", "missing factor column(s) height")],
)
def test_a_missing_column_is_named(tmp_path, capsys, drop, words):
    runs = _template(tmp_path, capsys)
    table = pd.read_csv(runs)
    table.loc[0, "k_x [N/mm]"], table.loc[0, "c_x [N.s/mm]"] = 0.9, 2.2e-3
    table.drop(columns=[drop]).to_csv(runs, index=False)
    code, _, err = run_inprocess(["calibrate", runs], capsys)
    assert_clean_failure(code, err, allowed=(2,))
    assert words in err, err


def test_mixed_up_prints_are_caught(tmp_path, capsys):
    runs = _template(tmp_path, capsys)
    other = dict(zip(FACTORS, [30.0, 24.0, 4.5, 9.0, 0.16, 0.0], strict=True))  # P1's sidecar, another design
    log = rig_log(tmp_path, "P1", other, 0.9, 2.2e-3)
    code, _, err = run_inprocess(["identify", log, "--runs", runs], capsys)
    assert_clean_failure(code, err, allowed=(2,))
    assert "density 30" in err and "mixed up" in err, err


def test_a_log_without_a_sidecar_is_named_on_the_command_line(tmp_path, capsys):
    """A rig whose software writes no sidecar: the print's id is typed (--print), as engraved."""
    runs = _template(tmp_path, capsys)
    design = dict(zip(FACTORS, [60.0, 24.0, 4.5, 9.0, 0.16, 0.0], strict=True))
    log = rig_log(tmp_path, "P1", design, 0.9, 2.2e-3)
    log.with_suffix(".json").unlink()
    code, _, err = run_inprocess(["identify", log, "--runs", runs], capsys)
    assert_clean_failure(code, err, allowed=(2,))
    assert "names no print" in err and "--print P1" in err and "print_id" not in err, err
    code, _, err = run_inprocess(["identify", log, "--print", "P1"], capsys)  # no table to fill
    assert_clean_failure(code, err, allowed=(2,))
    assert "--runs" in err, err
    assert pd.read_csv(runs)["k_x [N/mm]"].isna().all()
    code, out, err = run_inprocess(["identify", log, "--runs", runs, "--print", "p1"], capsys)
    assert code == 0, err
    assert np.isclose(pd.read_csv(runs)["k_x [N/mm]"].iloc[0], 0.9, rtol=0.02)
    # two logs cannot share one --print; a sidecar that names another print is not overridden
    code, _, err = run_inprocess(["identify", log, log, "--runs", runs, "--print", "P1"], capsys)
    assert_clean_failure(code, err, allowed=(2,))
    assert "one log" in err, err
    log.with_suffix(".json").write_text(json.dumps({"print": "P2"}))
    code, _, err = run_inprocess(["identify", log, "--runs", runs, "--print", "P1"], capsys)
    assert_clean_failure(code, err, allowed=(2,))
    assert "names print P2, --print P1" in " ".join(err.split()), err


def test_a_sidecar_with_the_designed_height_is_the_printed_print(tmp_path, capsys):
    """A rig's software that writes the design's settings (next.json's height, 9.05 mm) into the
    sidecar, where the table holds the height printed (9.0 mm: whole 0.16 mm layers over the 0.2 mm
    first): the same print, filled, not refused as "mixed up" (the old code refused it, exit 2,
    telling the user to check the engraved id)."""
    runs = _template(tmp_path, capsys)
    design = dict(zip(FACTORS, [60.0, 24.0, 4.5, 9.05, 0.16, 0.0], strict=True))
    log = rig_log(tmp_path, "P1", design, 0.9, 2.2e-3)
    code, _, err = run_inprocess(["identify", log, "--runs", runs], capsys)
    assert code == 0, err
    assert np.isclose(pd.read_csv(runs)["k_x [N/mm]"].iloc[0], 0.9, rtol=0.02)
    # a height that prints another whole layer (9.1 mm prints 9.16) is still another print
    runs = _template(tmp_path / "again", capsys)
    log = rig_log(tmp_path, "P1", design | {"height": 9.1}, 0.9, 2.2e-3)
    code, _, err = run_inprocess(["identify", log, "--runs", runs], capsys)
    assert_clean_failure(code, err, allowed=(2,))
    assert "height 9.1" in err and "mixed up" in err, err


def test_a_rotational_k_in_si_is_refused_naming_the_unit(tmp_path, capsys):
    """A runs table on theta (`print --axis theta`, k_theta [N.mm/rad]) filled from a log whose
    torque is in N.m: K 0.4 where the study's relation predicts about 400 N.mm/rad. identify --runs
    names the slip the x table's check names, exit 2 (the old code filled it: the study surrogate
    has no theta response, so nothing was compared)."""
    code, _, err = run_inprocess(["print", *SIX, "--axis", "theta", "-o", tmp_path / "one"], capsys)
    assert code == 0, err
    runs = tmp_path / "one" / "runs.csv"
    log = make_log(
        {"theta": {"k": 0.4, "c": 6e-4, "m": 1e-6, "amplitude": 0.05}}, duration=60.0, rate=500.0, seed=3
    )
    path = tmp_path / "p1_run.csv"
    log.to_csv(path, index=False)
    code, _, err = run_inprocess(["identify", path, "--runs", runs, "--print", "P1"], capsys)
    assert_clean_failure(code, err, allowed=(2,))
    words = " ".join(err.split())
    assert "k_theta of print P1 is 0.4" in words and "N.m/rad rather than N.mm/rad" in words, err
    assert "--accept-implausible" in words and pd.read_csv(runs)["k_theta [N.mm/rad]"].isna().all()
    # the same joint logged in N.mm: about 400 N.mm/rad, filled
    log["Ttheta"] *= 1000.0
    log.to_csv(path, index=False)
    code, _, err = run_inprocess(["identify", path, "--runs", runs, "--print", "P1"], capsys)
    assert code == 0, err
    assert np.isclose(pd.read_csv(runs)["k_theta [N.mm/rad]"].iloc[0], 400.0, rtol=0.02)


def test_a_measured_print_is_not_replaced_by_another_log(tmp_path, capsys):
    """P1 measured from its log; then another log named P1 (a slip of --print, meant P2): refused,
    naming the measurement it would replace, the table unchanged (the old code replaced P1's k and
    its log, exit 0). The same log again (identified anew) may refill its own row."""
    runs = _template(tmp_path, capsys)
    design = dict(zip(FACTORS, [60.0, 24.0, 4.5, 9.0, 0.16, 0.0], strict=True))
    first = rig_log(tmp_path, "P1", design, 0.9, 2.2e-3)
    code, _, err = run_inprocess(["identify", first, "--runs", runs], capsys)
    assert code == 0, err
    before = pd.read_csv(runs)
    other = tmp_path / "p2_run.csv"
    make_log({"x": {"k": 0.6, "c": 3e-3, "m": 2e-3, "amplitude": 1.0}}, duration=60.0, rate=500.0).to_csv(
        other, index=False
    )
    code, _, err = run_inprocess(["identify", other, "--runs", runs, "--print", "P1"], capsys)
    assert_clean_failure(code, err, allowed=(2,))
    words = " ".join(err.split())
    assert "print P1 is measured already" in words and str(first) in words, err
    pd.testing.assert_frame_equal(pd.read_csv(runs), before)
    code, _, err = run_inprocess(["identify", first, "--runs", runs], capsys)
    assert code == 0, err
    pd.testing.assert_frame_equal(pd.read_csv(runs), before)
