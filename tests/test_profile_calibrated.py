"""The profiler page of a calibrated surrogate (designer calibrate) in a real browser: the page
evaluates the calibration itself and must print what the library predicts, to 1e-9."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from test_profile_browser import _check
from test_profile_console import _check_k

import designer
from designer.model.surrogate import Surrogate
from designer.study import space

pytest.importorskip("websocket", reason="the browser tests speak to Chromium with websocket-client")
import cdp  # noqa: E402


@pytest.fixture(scope="module")
def calibrated(tmp_path_factory):
    folder = tmp_path_factory.mktemp("calibrated")
    table = designer.load_table()
    runs = table.iloc[[3, 10, 27, 30]][list(space.FACTOR_NAMES) + ["k_x", "c_x"]]
    runs.assign(k_x=runs["k_x"] * 0.7, c_x=runs["c_x"] * 1.4).to_csv(folder / "mine.csv", index=False)
    exe = Path(sys.executable).with_name("designer")
    for cmd in (
        ["calibrate", "mine.csv", "-o", "mine.json"],
        ["profile", "--surrogate", "mine.json", "--target", "k=0.8", "--target", "c=2e-3", "-o", "p.html"],
    ):
        run = subprocess.run([str(exe), *cmd], capture_output=True, text=True, cwd=folder)
        assert run.returncode == 0, run.stderr
    return folder


def test_page_of_a_calibrated_surrogate_matches_the_library(calibrated):
    exe = cdp.find_browser()
    if exe is None:
        pytest.skip("no headless Chromium on this machine")
    sur = Surrogate.load(calibrated / "mine.json")
    assert sur.calibration is not None
    with cdp.Browser(exe) as browser:
        page = browser.new_page()
        page.goto((calibrated / "p.html").resolve().as_uri())
        _check(page, sur)
        for f in space.CONTINUOUS:
            page.click(f"#s-{f.name}", 0.2)
            _check(page, sur)
        for level in (0.12, 0.2):
            page.click(f'button[data-factor="layer"][data-level="{level:g}"]')
            _check(page, sur)


def test_maximize_on_a_calibrated_page_agrees_with_suggest(calibrated):
    """The page's maximize searches the calibrated model as `designer suggest --surrogate` does."""
    import json

    from test_profile_browser import _design

    exe = cdp.find_browser()
    if exe is None:
        pytest.skip("no headless Chromium on this machine")
    with cdp.Browser(exe) as browser:
        page = browser.new_page()
        page.goto((calibrated / "p.html").resolve().as_uri())
        page.click("#lock-height")
        held = _design(page)["height"]
        page.click("#maximize")
        status = page.js("Object.assign({}, document.getElementById('max-status').dataset)")
    cli = Path(sys.executable).with_name("designer")
    args = ["suggest", "--surrogate", "mine.json", "--k", "0.8", "--fix", f"height={held!r}", "--json"]
    run = subprocess.run([str(cli), *args], capture_output=True, text=True, cwd=calibrated)
    assert run.returncode in (0, 1), run.stderr
    want = json.loads(run.stdout)["candidates"][0]
    assert json.loads(status["design"]) == pytest.approx(want["params"], abs=1e-9)
    assert float(status["p"]) == pytest.approx(want["p_within"], rel=1e-9)


def test_calibrated_page_shows_your_prints_and_the_calibrated_figures(calibrated, tmp_path):
    """Issue 36: the calibrated page said "44 measured runs", showed the study's accuracy and folded
    c away as flat; it shows the user's prints, the calibration's own figures and c's panels."""
    from designer.model.calibration import report
    from designer.plots import profile

    exe = cdp.find_browser()
    if exe is None:
        pytest.skip("no headless Chromium on this machine")
    sur = Surrogate.load(calibrated / "mine.json")
    mine = sur.calibration["table"]
    first = {n: float(mine[n].iloc[0]) for n in space.FACTOR_NAMES}
    page_path = profile.write_profiler(
        profile.build_profiler(sur, targets={"k": 0.8}, design=first), tmp_path / "at_mine.html"
    )
    figures = report(sur)["responses"]
    with cdp.Browser(exe) as browser:
        page = browser.new_page()
        page.goto(page_path.resolve().as_uri())
        source = page.js("document.getElementById('source').textContent")
        assert f"{len(mine)} of your prints" in source
        rows = page.js("document.getElementById('rows').textContent")
        for name in ("k_x", "c_x"):
            loo = figures[name]["loo_user"]
            assert (
                f"your {loo['n']} prints, each predicted from the others: median error {loo['mape']:.0f} %"
                in rows
            )
        assert page.js("document.querySelectorAll('details.flat').length") == 0  # c's panels shown
        assert page.js("document.querySelectorAll('#panels-c_x svg').length") == 6
        # at the design of the first print, that print is drawn in every panel of k
        assert page.js("document.querySelectorAll('#panels-k_x path.mine').length") >= 6
        _check_k(page, sur, ("k_x", "c_x"))


def test_command_lines_of_a_calibrated_page_answer_from_its_surrogate(calibrated):
    """The remembered design's export command and maximize's suggest command name the page's
    surrogate: without `--surrogate mine.json` they answered from the study's (export gave k 0.633
    N/mm at the opening design where the page showed 0.494, and had no such flag)."""
    import json
    import shlex

    exe = cdp.find_browser()
    if exe is None:
        pytest.skip("no headless Chromium on this machine")
    cli = str(Path(sys.executable).with_name("designer"))
    with cdp.Browser(exe) as browser:
        page = browser.new_page()
        page.goto((calibrated / "p.html").resolve().as_uri())
        shown = float(page.js("document.getElementById('pred-k_x').dataset.value"))
        page.click("#remember")
        page.click("#copy-cmd-1")
        export = shlex.split(page.js("document.getElementById('export-text').value"))
        page.click("#lock-height")
        page.click("#maximize")
        status = page.js("Object.assign({}, document.getElementById('max-status').dataset)")
        said = page.js("document.getElementById('max-status').textContent")
    assert export[:3] == ["designer", "export", "fmu"] and "--surrogate" in export
    run = subprocess.run([cli, *export[1:], "--json"], capture_output=True, text=True, cwd=calibrated)
    assert run.returncode == 0, run.stderr
    assert json.loads(run.stdout)["joint"]["axes"]["x"]["rig"]["k"] == pytest.approx(shown, rel=1e-9)
    suggest = shlex.split(said.split("the same search as: ")[1])
    assert suggest[:2] == ["designer", "suggest"] and "--surrogate" in suggest
    run = subprocess.run([cli, *suggest[1:], "--json"], capture_output=True, text=True, cwd=calibrated)
    assert run.returncode in (0, 1), run.stderr
    best = json.loads(run.stdout)["candidates"][0]
    assert best["params"] == pytest.approx(json.loads(status["design"]), abs=1e-9)
    assert best["p_within"] == pytest.approx(float(status["p"]), rel=1e-9)


def test_suggestion_of_another_surrogate_is_greyed(calibrated):
    """A calibrated page opened with the study's suggestion showed its buttons live ("#1, P 37 %")
    while the page, at that very design, computed P for the calibrated model; they are greyed and
    say which surrogate found them."""
    exe = cdp.find_browser()
    if exe is None:
        pytest.skip("no headless Chromium on this machine")
    cli = str(Path(sys.executable).with_name("designer"))
    run = subprocess.run(
        [cli, "suggest", "--k", "0.8", "--json"], capture_output=True, text=True, cwd=calibrated
    )
    assert run.returncode == 0, run.stderr
    (calibrated / "study.json").write_text(run.stdout)
    args = ["profile", "--surrogate", "mine.json", "--suggestion", "study.json", "-o", "mixed.html"]
    run = subprocess.run([cli, *args], capture_output=True, text=True, cwd=calibrated)
    assert run.returncode == 0, run.stderr
    study, mine = Surrogate.load().id, Surrogate.load(calibrated / "mine.json").id
    with cdp.Browser(exe) as browser:
        page = browser.new_page()
        page.goto((calibrated / "mixed.html").resolve().as_uri())
        buttons = page.js(
            "[...document.querySelectorAll('#suggestions button')].map(b => [b.dataset.stale,"
            " b.querySelector('.stale-why').textContent])"
        )
        p_page = float(page.js("document.getElementById('tgt-k_x').dataset.probability"))
    assert buttons and all(
        s == "true" and f"found with surrogate {study}, not this page's {mine}" in t for s, t in buttons
    )
    p_button = json.loads((calibrated / "study.json").read_text())["candidates"][0]["p_within"]
    assert abs(p_page - p_button) > 0.01  # the button's P was never this page's


def test_calibrated_page_does_not_say_no_setting_changes_c(calibrated):
    """The summary said "c_x not predictable: no setting changes its chance" on a calibrated page,
    where c's P moved from 22 % to 8.1 % and 1.4 % between the user's prints (they pin c down)."""
    exe = cdp.find_browser()
    if exe is None:
        pytest.skip("no headless Chromium on this machine")
    mine = Surrogate.load(calibrated / "mine.json").calibration["table"]
    with cdp.Browser(exe) as browser:
        page = browser.new_page()
        page.goto((calibrated / "p.html").resolve().as_uri())
        seen = set()
        for i in range(len(mine)):
            design = {n: float(mine[n].iloc[i]) for n in space.FACTOR_NAMES}
            page.js(f"applyDesign({json.dumps(design)})")
            seen.add(round(float(page.js("document.getElementById('tgt-c_x').dataset.probability")), 6))
            said = page.js("document.getElementById('overall').textContent")
            assert "no setting changes" not in said, said
            assert "c_x not predictable from the six factors: its chance varies with the setting only" in said
    assert len(seen) > 1  # it does vary
