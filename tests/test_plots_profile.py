"""The profiler page's data (library) and `designer profile` (CLI); test_profile_browser drives the page."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from designer.errors import DesignerError
from designer.model.forms import FORMS, design_matrix
from designer.model.surrogate import Surrogate
from designer.plots import profile
from designer.study import space


@pytest.fixture(scope="module")
def sur():
    return Surrogate.load()


def _evaluate(node, x):
    """A reading of the exported expression trees, to check them against the surrogate's features."""
    op = node[0]
    if op == "x":
        return x[node[1]]
    if op == "c":
        return node[1]
    if op == "log":
        return math.log(_evaluate(node[1], x))
    if op == "level":
        return float(abs(_evaluate(node[1], x) - node[2]) <= 1e-8 + 1e-5 * abs(node[2]))
    a, b = _evaluate(node[1], x), _evaluate(node[2], x)
    return {"+": a + b, "-": a - b, "*": a * b, "/": a / b}[op]


@pytest.mark.parametrize("form", FORMS)
def test_feature_programs_are_the_surrogates_features(form):
    rng = np.random.default_rng(3)
    program = profile.feature_program(form)
    for _ in range(20):
        x = {f.name: float(rng.uniform(f.low, f.high)) for f in space.CONTINUOUS}
        x |= {f.name: float(rng.choice(f.levels)) for f in space.CATEGORICAL}
        want = design_matrix(form, x)[0]
        got = [1.0] + [_evaluate(n, x) for n in program]
        np.testing.assert_allclose(got, want, rtol=1e-13, atol=1e-13)


def test_profiler_data(sur, tmp_path):
    page = profile.build_profiler(sur, targets={"k": 0.8}, design={"width": 3.5})
    d = page.data
    assert d["design"] == profile.DEFAULT_DESIGN | {"width": 3.5}
    k, c = d["responses"]
    assert (k["name"], c["name"]) == ("k_x", "c_x")
    assert k["coef"] == list(sur.model("k_x").coef) and k["transform"] == "log"
    assert k["target"]["value"] == 0.8 and c["target"] is None
    assert not c["predictable"] and "not predictable" in c["statement"]
    assert (
        "leave-one-out" in k["accuracy"]["kind"] and k["accuracy"]["q2"] == sur.model("k_x").loo_nested["q2"]
    )
    # the panels' y range holds every run and the PI at the design
    lo, hi = k["range"]
    assert lo <= min(sur.training["k_x"]) and hi >= max(sur.training["k_x"])
    html = profile.write_profiler(page, tmp_path / "p.html").read_text()
    assert "Content-Security-Policy" in html and "default-src 'none'" in html
    assert "http://" not in html and "https://" not in html
    embedded = json.loads(html.split('type="application/json">')[1].split("</script>")[0])
    assert embedded["responses"][0]["vcov"] == np.asarray(sur.model("k_x").vcov).tolist()


def test_command_lines_name_the_surrogate_they_need(sur):
    """The page's suggest and export command lines carry --surrogate for any surrogate but the
    shipped one: its file quoted for a shell, or, with no file known, its id in a form no shell
    runs unchanged (never a line that silently answers from the study's surrogate)."""
    from dataclasses import replace

    assert profile.build_profiler(sur).data["surrogate_flag"] == ""
    flag = profile.build_profiler(sur, surrogate_file=Path("my prints") / "mine.json").data["surrogate_flag"]
    assert flag == "--surrogate 'my prints/mine.json'"
    other = replace(sur, models={**sur.models, "k_x": replace(sur.models["k_x"], sigma=0.5)})
    assert other.id != sur.id
    assert (
        profile.build_profiler(other).data["surrogate_flag"]
        == f"--surrogate <the file of surrogate {other.id}>"
    )


def test_nested_figures_are_preferred(sur, monkeypatch):
    model = sur.model("k_x")
    monkeypatch.setattr(
        model, "loo_nested", {"q2": 0.32, "rmse": 0.22, "mape": 19.0, "coverage95": 0.9}, raising=False
    )
    acc = profile.build_profiler(sur).data["responses"][0]["accuracy"]
    assert acc["nested"] and acc["q2"] == 0.32 and acc["kind"].startswith("nested")


def test_bad_requests_name_the_argument(sur, tmp_path):
    with pytest.raises(DesignerError, match="targets has unknown quantity 'm'"):
        profile.build_profiler(sur, targets={"m": 1.0})
    with pytest.raises(DesignerError, match="tolerance=1.5"):
        profile.build_profiler(sur, tolerance=1.5)
    with pytest.raises(DesignerError, match="outside the tested range"):
        profile.build_profiler(sur, design={"width": 9})
    with pytest.raises(DesignerError, match="unknown axis"):
        profile.build_profiler(sur, axis="w")
    with pytest.raises(DesignerError, match="no list of candidates"):
        profile.build_profiler(sur, suggestion={"rows": []})
    with pytest.raises(DesignerError, match="candidate 1 does not give all six"):
        profile.build_profiler(sur, suggestion={"candidates": [{"params": {"width": 3}}]})
    with pytest.raises(DesignerError, match="no such suggestion file"):
        profile.build_profiler(sur, suggestion=tmp_path / "none.json")
    with pytest.raises(DesignerError, match=".html"):
        profile.write_profiler(profile.build_profiler(sur), tmp_path / "p.png")
    far = dict(profile.DEFAULT_DESIGN, width=9.0)
    strip = profile.build_profiler(sur, suggestion={"candidates": [{"params": far}]}).data["suggestions"]
    assert strip == [
        {
            "rank": 1,
            "params": far,
            "inside": False,
            "outside": ["width 9 mm outside 2 to 7 mm"],  # the page shows this reason in visible text
            "any": [],
            "p_within": None,
        }
    ]
    any_density = {"candidates": [{"params": profile.DEFAULT_DESIGN, "any": ["density"]}]}
    assert profile.build_profiler(sur, suggestion=any_density).data["suggestions"][0]["any"] == ["density"]


def designer(*args: str, cwd) -> subprocess.CompletedProcess:
    exe = Path(sys.executable).with_name("designer")
    return subprocess.run([str(exe), *args], capture_output=True, text=True, cwd=cwd)


def test_cli_profile(sur, tmp_path):
    run = designer(
        "profile", "--design", "raster=45", "--target", "k=0.8", "--json", "-o", "p.html", cwd=tmp_path
    )
    assert run.returncode == 0, run.stderr
    out = json.loads(run.stdout)
    assert out["design"]["raster"] == 45.0 and (tmp_path / "p.html").is_file()
    want = sur.predict(out["design"], responses=["k_x"])["k_x"]
    assert out["predicted"]["k_x"]["value"] == pytest.approx(float(want.value[0]), rel=1e-12)
    for bad, message in (
        (["--design", "width=3", "--design", "width=4"], "twice"),
        (["--target", "k"], "is not NAME=VALUE"),
        # suggest and export take --axis theta (derived from x); the page said "the surrogate has no
        # response 'k_theta' ... fit one on a table with that axis: Surrogate().fit(table)", a Python
        # call and a fit the study's table cannot give
        (["--axis", "theta"], "the profiler shows the axes the surrogate has (x), and theta is not one"),
    ):
        run = designer("profile", *bad, cwd=tmp_path)
        assert run.returncode == 2 and message in run.stderr and "Traceback" not in run.stderr, (
            bad,
            run.stderr,
        )


def test_a_next_output_as_suggestion_is_refused_naming_suggest(sur, tmp_path):
    """The walk of the profiler page: `profile --suggestion next.json` (a `designer next` output) was
    refused in Python's words ("pass a Suggestion, its to_dict() or such a JSON file"). next's prints
    are chosen for what measuring them teaches, not ranked by P as the page's buttons are, so it stays
    refused, in one line naming the suggest command line with next's own goals."""
    run = designer("next", "--k", "0.8", "--n", "2", "--tolerance", "15", "--json", cwd=tmp_path)
    assert run.returncode in (0, 1), run.stderr
    (tmp_path / "next.json").write_text(run.stdout)
    run = designer("profile", "--suggestion", "next.json", "-o", "p.html", cwd=tmp_path)
    assert run.returncode == 2 and "Traceback" not in run.stderr and not (tmp_path / "p.html").exists()
    line = run.stderr.strip()
    assert "\n" not in line and "to_dict" not in line and "an output of designer next" in line, line
    fix = "designer suggest --k 0.8 --tolerance 15 --json > s.json"
    assert fix in line, line
    # the command it names makes a file the page takes
    run = designer(*fix.split(" > ")[0].split()[1:], cwd=tmp_path)
    (tmp_path / "s.json").write_text(run.stdout)
    run = designer("profile", "--suggestion", "s.json", "-o", "p.html", cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    # the library refuses it naming its own arguments
    with pytest.raises(DesignerError, match="suggestion is a next_prints result"):
        profile.build_profiler(sur, suggestion=tmp_path / "next.json")
    # a file that is neither names the command whose output it takes, not a Python call
    (tmp_path / "rows.json").write_text('{"rows": []}')
    run = designer("profile", "--suggestion", "rows.json", "-o", "p.html", cwd=tmp_path)
    assert run.returncode == 2 and "`designer suggest ... --json`" in run.stderr, run.stderr
    assert "to_dict" not in run.stderr
