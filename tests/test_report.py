"""`designer validate`: the checks, the HTML and Markdown report, the exit code."""

from __future__ import annotations

import base64
import re
import subprocess
import sys
from pathlib import Path

import pytest
from imagecheck import assert_picture, chromium, dump_dom

import designer
from designer.model.surrogate import Surrogate
from designer.study.data import load_table, table_hash
from designer.validate import checks, report
from designer.validate.stats import check_main_effects
from designer.validate.study import check_dataset


def test_validate_writes_a_passing_report(tmp_path):
    exe = Path(sys.executable).with_name("designer")
    run = subprocess.run([str(exe), "validate", "-o", "rep"], capture_output=True, text=True, cwd=tmp_path)
    assert run.returncode == 0, run.stdout + run.stderr
    out = tmp_path / "rep"
    md = (out / "report.md").read_text()
    names = [check_dataset(checks.Context(load_table(), tmp_path)).name]
    assert names[0] in md and "FAIL" not in md
    for png in sorted((out / "figures").glob("*.png")):
        assert_picture(png)
    assert len(list((out / "figures").glob("*.png"))) >= len(checks.CHECKS)
    for name in ("table4", "fmu_step_response", "identification", "cosim_convergence", "cosim_arm"):
        assert (out / "figures" / f"{name}.png").is_file()
    for title in ("Table 4", "validate_fmu", "libcosimpy", "Identification closed loop", "convergence"):
        assert title in md
    # who, when, on what: the header a colleague needs to trust the report
    about = dict(line[2:].split(": ", 1) for line in md.splitlines() if line.startswith("- "))
    assert set(about) == {"date", "tool", "code", "platform", "surrogate", "data"}
    assert re.fullmatch(r"\d{4}-\d\d-\d\d \d\d:\d\d UTC", about["date"])
    assert about["tool"] == f"flexjoint designer {designer.__version__}"
    assert re.fullmatch(
        r"(commit [0-9a-f]{12}( with uncommitted changes)?|package sha256 [0-9a-f]{12})", about["code"]
    )
    assert about["surrogate"] == Surrogate.load().id
    assert about["data"] == f"bundled study table, 44 runs, sha256 {table_hash(load_table())[:12]}"
    # human column names with units, no raw names or 'nan' cells
    page = (out / "report.html").read_text()
    for raw in ("F_paper", "max_error_same_step", "| nan |", ">nan<"):
        assert raw not in md + page, raw
    assert "macro step (s)" in md and "F, paper" in page
    # one file travels: every figure inside the page as a data URI, with a caption; a phone viewport
    assert "name='viewport'" in page
    sources = re.findall(r"<img src='([^']*)'", page)
    pngs = sorted((out / "figures").glob("*.png"))
    assert len(sources) == len(pngs) and all(s.startswith("data:image/png;base64,") for s in sources)
    embedded = {base64.b64decode(s.split(",", 1)[1]) for s in sources}
    assert embedded == {p.read_bytes() for p in pngs}
    assert page.count("<figcaption>") == len(pngs) and "fmu_step_response.png)</figcaption>" in page
    exe = chromium()
    if exe is None:
        pytest.skip("no headless Chromium on this machine")
    dom = dump_dom(exe, out / "report.html")
    assert f'data-checks="{len(checks.CHECKS)}"' in dom
    assert f'data-passed="{len(checks.CHECKS)}"' in dom
    assert dom.count('class="check"') == len(checks.CHECKS)


def test_a_failing_check_fails_the_report(tmp_path):
    table = load_table()
    # triple the stiffness of the widest runs: k_x now rises with width, against the study
    wide = table.width == 7
    table.loc[wide, "k_x"] *= 3
    ctx = checks.Context(table, tmp_path)
    result = check_main_effects(ctx)
    assert not result.passed
    rows = result.table.set_index(["response", "factor"])
    assert not rows.loc[("k_x", "width"), "agrees"]
    assert rows.loc[("k_x", "height"), "agrees"]
    results = checks.run_checks(ctx, (check_dataset, check_main_effects))
    page, md = report.write_report(results, tmp_path, 1.0)
    assert "1 of 2 checks pass" in md.read_text() and "FAIL" in page.read_text()


def test_bad_table_fails_in_one_line(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("density,length\n1,2\n")
    exe = Path(sys.executable).with_name("designer")
    run = subprocess.run(
        [str(exe), "validate", "--data", str(bad), "-o", "rep"], capture_output=True, text=True, cwd=tmp_path
    )
    assert run.returncode == 2 and run.stderr.startswith("error:") and "Traceback" not in run.stderr


def test_a_crashing_check_is_a_failed_check_not_an_aborted_report(tmp_path):
    def check_that_crashes(ctx):
        raise ZeroDivisionError("a fault inside a library")

    ctx = checks.Context(load_table(), tmp_path)
    results = checks.run_checks(ctx, (check_that_crashes, check_dataset))
    assert [r.passed for r in results] == [False, True]
    assert results[0].summary == "could not run: ZeroDivisionError: a fault inside a library"


def test_an_interrupted_report_leaves_the_old_one_whole(tmp_path, monkeypatch):
    out = tmp_path / "rep"
    out.mkdir()
    (out / "report.html").write_text("old report")

    def interrupt(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(report, "run_checks", lambda ctx, progress=None: [])
    monkeypatch.setattr(report, "write_report", interrupt)
    with pytest.raises(KeyboardInterrupt):
        report.validate(out)
    assert [p.name for p in tmp_path.iterdir()] == ["rep"]
    assert [p.name for p in out.iterdir()] == ["report.html"] and (
        out / "report.html"
    ).read_text() == "old report"
