"""The profiler page as a design console, driven in headless Chromium through its own controls.

- maximize: a goal typed into the page, two factors locked, the button pressed: the page must land
  on the design `designer suggest` prints with the same goal and `--fix`, with the same P and D;
- the simulator's defect rate against an independent Monte Carlo written here (numpy draws of the
  print noise, the library's predictions, scipy's Student t draws of the printed response);
- layout at 1280x800 and 390x844 (no horizontal overflow, one panel row per response, touch targets);
- the browser's accessibility tree: every control named, with its unit;
- a click and a drag inside a panel; the density pinned where the part prints solid; remembered
  settings copied as a `designer export` command line and as JSON for `--from`, both run.
"""

from __future__ import annotations

import json
import shlex
import subprocess
import sys
import time
import zipfile
from pathlib import Path

import numpy as np
import pytest
from imagecheck import assert_picture
from scipy import stats
from test_profile_browser import _design

from designer.model.surrogate import Surrogate
from designer.study import space

pytest.importorskip("websocket", reason="the browser tests speak to Chromium with websocket-client")
import cdp  # noqa: E402

EXE = Path(sys.executable).with_name("designer")


@pytest.fixture(scope="module")
def sur():
    return Surrogate.load()


@pytest.fixture(scope="module")
def url(tmp_path_factory):
    """A page with no goal: the tests set goals through the page's own controls."""
    folder = tmp_path_factory.mktemp("console")
    run = subprocess.run([str(EXE), "profile", "-o", "p.html"], capture_output=True, text=True, cwd=folder)
    assert run.returncode == 0, run.stderr
    return (folder / "p.html").resolve().as_uri()


@pytest.fixture(scope="module")
def browser():
    exe = cdp.find_browser()
    if exe is None:
        pytest.skip("no headless Chromium on this machine")
    with cdp.Browser(exe, width=1280, height=800) as b:
        yield b


@pytest.fixture
def page(browser, url):
    p = browser.new_page()
    p.viewport(1280, 800)
    p.goto(url)
    p.js("localStorage.clear()")  # remembered settings of an earlier test
    p.goto(url)
    yield p
    p.call("Page.close")


def _set_goal(page, response: str, kind: str, value: float | None = None) -> None:
    """Choose the goal in the response's select and type the target into its field."""
    page.js(
        f"(() => {{ const s = document.getElementById('goal-kind-{response}'); s.focus();"
        f" s.value = '{kind}'; s.dispatchEvent(new Event('change')); }})()"
    )
    if value is not None:
        page.click(f"#goal-value-{response}")
        page.js(f"document.getElementById('goal-value-{response}').select()")
        page.type_text(repr(value))


def _suggest(*args: str) -> dict:
    run = subprocess.run([str(EXE), "suggest", *args, "--json"], capture_output=True, text=True)
    assert run.returncode in (0, 1), run.stderr
    return json.loads(run.stdout)["candidates"][0]


# (goal, target, factors moved then locked: slider fraction or level)
CASES = [
    ("target", 0.6, {"width": 0.3, "layer": 0.2}),
    ("max", None, {"height": 0.55, "raster": 45.0}),
    ("target", 1.1, {"length": 0.8, "density": 0.4}),
    ("min", None, {"layer": 0.12}),
]


@pytest.mark.parametrize(("kind", "value", "moves"), CASES)
def test_maximize_agrees_with_designer_suggest(page, sur, kind, value, moves):
    for name, v in moves.items():
        if space.BY_NAME[name].categorical:
            page.click(f'button[data-factor="{name}"][data-level="{v:g}"]')
        else:
            page.click(f"#s-{name}", v)
        page.click(f"#lock-{name}")
    _set_goal(page, "k_x", kind, value)
    held = {n: v for n, v in _design(page).items() if n in moves}
    page.click("#maximize")
    status = page.js("Object.assign({}, document.getElementById('max-status').dataset)")
    design = _design(page)
    assert {n: design[n] for n in held} == held  # the locked factors did not move
    want = _suggest(
        "--k", str(value) if kind == "target" else kind, *[f"--fix={n}={v!r}" for n, v in held.items()]
    )
    shown = json.loads(status["design"])
    assert shown == pytest.approx(want["params"], abs=1e-9)
    if "density" not in want["any"]:
        assert design == pytest.approx(want["params"], abs=1e-9)  # the controls show it
    if kind == "target":
        assert float(status["p"]) == pytest.approx(want["p_within"], rel=1e-9)
    assert float(status["d"]) == pytest.approx(want["desirability"], rel=1e-9)
    # the page's numbers at the design are still the library's
    _check_k(page, sur)
    text = page.js("document.getElementById('max-status').textContent")
    assert "designer suggest --k" in text and all(f"--fix {n}=" in text for n in held)


def test_maximize_with_a_solid_section_locked(page, sur):
    """Width locked at 2.0 mm: the walls fill the section, suggest holds density at 100 % (solid), and
    so does the page; the density control stays pinned."""
    page.js("document.getElementById('s-width').focus()")
    page.key("Home", 36)
    page.click("#lock-width")
    _set_goal(page, "k_x", "target", 1.2)
    page.click("#maximize")
    status = page.js("Object.assign({}, document.getElementById('max-status').dataset)")
    want = _suggest("--k", "1.2", "--fix", "width=2.0")
    assert want["any"] == ["density"] and want["params"]["density"] == 100
    assert json.loads(status["design"]) == pytest.approx(want["params"], abs=1e-9)
    assert float(status["p"]) == pytest.approx(want["p_within"], rel=1e-9)
    assert page.js("document.getElementById('v-density').textContent") == "100 % (solid)"
    _check_k(page, sur, ("k_x", "c_x"))


def _check_k(page, sur, responses: tuple[str, ...] = ("k_x",)) -> None:
    """The page's predictions and PIs at its setting are the library's, to 1e-9."""
    design = _design(page)
    for name in responses:
        lib = sur.predict(design, responses=[name])[name]
        got = page.js(f"Object.assign({{}}, document.getElementById('pred-{name}').dataset)")
        want = [float(lib.value[0]), float(lib.low[0]), float(lib.high[0])]
        np.testing.assert_allclose([float(got[k]) for k in ("value", "low", "high")], want, rtol=1e-9)


def test_simulator_defect_rate_matches_an_independent_monte_carlo(page, sur):
    """Page: Rao-Blackwellised over the noise draws; here: plain sampling of the printed response."""
    _set_goal(page, "k_x", "target", 0.8)
    # a sloppy printer (the defaults, 0.1 mm, change the rate by less than its Monte Carlo error:
    # the model's own uncertainty dominates); the draws stay printable (> 2 mm) in the test's draws
    sloppy = {"width": 0.4, "height": 1.2, "length": 2.5}
    for name, sd in sloppy.items():
        page.click(f"#noise-{name}")
        page.js(f"document.getElementById('noise-{name}').select()")
        page.type_text(str(sd))
    design = _design(page)
    sim = page.js("Object.assign({}, document.getElementById('sim-k_x').dataset)")
    noise = page.js("D.noise") | sloppy
    n_page = int(page.js("D.mc_draws"))
    rng = np.random.default_rng(2026)
    n = 40_000
    draws = {f: np.full(n, design[f]) for f in space.FACTOR_NAMES}
    for f in space.CONTINUOUS:
        draws[f.name] = draws[f.name] + noise[f.name] * rng.standard_normal(n)
    model = sur.model("k_x")
    pred = sur.predict(draws, responses=["k_x"], allow_extrapolation=True)["k_x"]
    mu = np.log(pred.value)
    scale = (np.log(pred.high) - mu) / stats.t.ppf(0.975, model.dof)
    k = np.exp(mu + scale * stats.t.rvs(model.dof, size=n, random_state=rng))
    defect = float(np.mean(np.abs(k / 0.8 - 1) > 0.1))
    se_here = np.sqrt(defect * (1 - defect) / n)
    page_defect, page_se = float(sim["defect"]), float(sim["se"])
    assert n_page >= 1000 and 0 < page_se < 0.01
    assert abs(page_defect - defect) <= 1.96 * np.hypot(page_se, se_here), (page_defect, defect)
    # without noise the page's rate is 1 - P(within) at the design, from scipy's t
    one = sur.predict(design, responses=["k_x"])["k_x"]
    m0, s0 = (
        np.log(one.value[0]),
        (np.log(one.high[0]) - np.log(one.value[0])) / stats.t.ppf(0.975, model.dof),
    )
    p0 = stats.t.cdf((np.log(0.88) - m0) / s0, model.dof) - stats.t.cdf((np.log(0.72) - m0) / s0, model.dof)
    assert float(sim["noiseless"]) == pytest.approx(1 - p0, abs=1e-9)
    assert abs(page_defect - float(sim["noiseless"])) > 5 * page_se  # the noise is seen at this setting
    text = page.js("document.getElementById('sim').textContent")
    assert f"({n_page} draws)" in text and "with print noise" in text


@pytest.mark.parametrize(
    ("typed", "said"),
    [
        ("0,5", "width sd: '0,5' has a comma: write the decimal point as '.' (0.5)"),
        ("-1", "width sd -1 mm must be 0 or more"),
        ("", "width sd: empty"),
        ("50", "of the draws put width at or below 0"),
    ],
)
def test_a_bad_print_noise_gives_no_defect_rate(page, typed, said):
    """The noise boxes were number inputs read with parseFloat: "0,5" became 5 mm (Chromium drops the
    comma), "-1" and an emptied box kept the old sd beside what the box said, and a noise larger than
    the part (width sd 5 or 50 mm) printed "NaN % +- NaN %". Now read as the other typed boxes, with
    the error beside the box and no rate until it is fixed; draws at or below 0 give no rate either."""
    _set_goal(page, "k_x", "target", 0.8)
    page.click("#noise-width")
    page.js("document.getElementById('noise-width').select()")
    page.type_text("0.3")
    assert float(page.js("document.getElementById('sim-k_x').dataset.defect")) > 0
    page.js("document.getElementById('noise-width').select()")
    if typed:
        page.type_text(typed)
    else:
        page.backspace()
    sim = page.js("document.getElementById('sim').textContent")
    assert sim.startswith("no defect rate: ") and said in sim and "NaN" not in sim, sim
    assert page.js("document.getElementById('sim-k_x')") is None
    if typed != "50":  # a bad box: its message beside it, the old sd not used
        assert said in page.js("document.getElementById('noise-err-width').textContent")
        assert page.js("document.getElementById('noise-width').getAttribute('aria-invalid')") == "true"


@pytest.mark.parametrize(("width", "height"), [(1280, 800), (390, 844)])
def test_layout_fits_the_screen(browser, url, tmp_path, width, height):
    page = browser.new_page()
    page.viewport(width, height, mobile=width < 600)
    page.goto(url)
    page.js("document.querySelector('details.flat').open = true")
    sizes = page.js("[document.documentElement.scrollWidth, document.documentElement.clientWidth]")
    assert sizes[0] <= sizes[1], f"horizontal overflow at {width} px: {sizes}"
    tops = page.js(
        "(() => { const o = {}; for (const s of document.querySelectorAll('svg[data-response]'))"
        " (o[s.dataset.response] = o[s.dataset.response] || [])"
        ".push(Math.round(s.getBoundingClientRect().top));"
        " return o; })()"
    )
    assert set(tops) == {"k_x", "c_x"} and all(len(v) == 6 for v in tops.values())
    if width >= 1280:
        assert all(len(set(v)) == 1 for v in tops.values()), tops  # one row of panels per response
    else:  # the summary stacks above the panels, which scale to the screen
        below = page.js(
            "document.querySelector('#panels-k_x svg').getBoundingClientRect().top >="
            " document.querySelector('.summary').getBoundingClientRect().bottom"
        )
        assert below
    small = page.js(
        "[...document.querySelectorAll('button, select, input[type=number], input[type=range], label.lock,"
        " details.flat summary')].map(e => [e.id || e.textContent.slice(0, 20), e.getBoundingClientRect()])"
        ".filter(([, r]) => r.width > 0 && (r.width < 44 || r.height < 44))"
        ".map(([n, r]) => [n, r.width, r.height])"
    )
    assert small == [], f"touch targets under 44 px: {small}"
    shot = page.screenshot(tmp_path / f"profile_{width}.png")
    assert_picture(shot, min_size=(width - 20, height))  # less a scroll bar
    page.call("Page.close")


@pytest.mark.parametrize("width", [640, 720, 900, 1024, 1140])
def test_panels_stay_readable_in_a_narrow_window(browser, url, width):
    """Between the phone layout (600 px) and a wide screen the six panels stayed in one row beside
    the summary and shrank with the window: 58 px wide at 640 px, 101 px at 900, their 11-unit labels
    drawn at 3.6 and 6.3 px. A panel is now never narrower than 140 px (labels 8.8 px or more)."""
    page = browser.new_page()
    page.viewport(width, 800)
    page.goto(url)
    page.js("document.querySelector('details.flat').open = true")
    _set_goal(page, "k_x", "target", 0.8)  # the P trace's row too
    widths = page.js(
        "[...document.querySelectorAll('svg[data-response], svg[data-trace]')]"
        ".map(s => s.getBoundingClientRect().width)"
    )
    assert len(widths) == 18 and min(widths) >= 140, (width, widths)
    sizes = page.js("[document.documentElement.scrollWidth, document.documentElement.clientWidth]")
    assert sizes[0] <= sizes[1], f"horizontal overflow at {width} px: {sizes}"
    page.call("Page.close")


CONTROL_ROLES = ("slider", "button", "checkbox", "combobox", "spinbutton", "textbox", "image", "group")


def test_accessibility_tree_names_every_control_with_its_unit(page, sur):
    _set_goal(page, "k_x", "target", 0.8)
    nodes = [n for n in page.ax_tree() if not n.get("ignored")]
    by_role: dict[str, list[dict]] = {}
    for n in nodes:
        by_role.setdefault(n.get("role", {}).get("value"), []).append(n)
    for role in CONTROL_ROLES:
        unnamed = [
            n["nodeId"] for n in by_role.get(role, []) if not n.get("name", {}).get("value", "").strip()
        ]
        assert unnamed == [], f"{role} without a name"

    def name(n):
        return n["name"]["value"]

    sliders = {name(n): n for n in by_role["slider"]}
    for f in space.CONTINUOUS:
        node = sliders[f"{f.name} ({f.unit})"]
        assert node["description"]["value"].endswith(f" {f.unit}"), node["description"]
    pressed = {
        name(n): [p["value"]["value"] for p in n["properties"] if p["name"] == "pressed"]
        for n in by_role["button"]
    }
    for f in space.CATEGORICAL:
        group = [n for n in by_role["group"] if name(n) == f"{f.name} ({f.unit})"]
        assert group, f"level buttons of {f.name} are not a named group"
        for lv in f.levels:
            assert pressed[f"{f.name} {lv:g} {f.unit}"] in (["true"], ["false"])
    checks = {name(n) for n in by_role["checkbox"]}
    assert {f"lock {f.name} (hold it when maximizing)" for f in space.FACTORS} <= checks
    typed = {name(n) for n in by_role["textbox"]}  # typed numbers are read by the page, errors shown
    assert "target k_x (N/mm)" in typed and "tolerance around a target, \u00b1 %" in typed
    assert {f"{f.name} value ({f.unit})" for f in space.CONTINUOUS} <= typed
    assert {f"print noise, standard deviation of {f.name} ({f.unit})" for f in space.CONTINUOUS} <= typed
    images = [name(n) for n in by_role["image"]]
    contour = [n for n in images if n.startswith("width against height")]
    trace = [n for n in images if n.startswith("P(every stated goal met) against ")]
    images = [n for n in images if n not in contour + trace]
    assert len(contour) == 1 and "shaded" in contour[0]  # the contour view, described in words
    assert len(trace) == 6 and all("highest" in n for n in trace)  # the P trace, one per factor
    assert len(images) == 6  # k_x's panels (c_x's are folded away: it is not predictable)
    assert all(n.startswith("k_x against ") and "N/mm" in n for n in images), images


def test_click_and_drag_inside_a_panel_set_the_factor(page, sur):
    geometry = page.js("({PW, ML, MR})")

    def at(factor: str, u: float) -> tuple[float, float]:
        b = page.box(f'svg[data-response="k_x"][data-factor="{factor}"]')
        scale = b["w"] / geometry["PW"]
        x = b["x"] + scale * (geometry["ML"] + u * (geometry["PW"] - geometry["ML"] - geometry["MR"]))
        return x, b["y"] + b["h"] / 2

    page.click_at(*at("width", 0.25))
    assert _design(page)["width"] == pytest.approx(3.25, abs=0.011)
    x0, y = at("length", 0.1)
    x1, _ = at("length", 0.75)
    page.call("Input.dispatchMouseEvent", type="mousePressed", x=x0, y=y, button="left", clickCount=1)
    for i in range(1, 6):
        page.call(
            "Input.dispatchMouseEvent",
            type="mouseMoved",
            x=x0 + (x1 - x0) * i / 5,
            y=y,
            button="left",
            buttons=1,
        )
    page.call("Input.dispatchMouseEvent", type="mouseReleased", x=x1, y=y, button="left", clickCount=1)
    assert _design(page)["length"] == pytest.approx(18 + 0.75 * 12, abs=0.011)
    page.click_at(*at("raster", 0.8))
    assert _design(page)["raster"] == 45
    _check_k(page, sur)


def test_density_pinned_where_the_part_prints_solid(page, sur):
    page.js("document.getElementById('s-width').focus()")
    page.key("Home", 36)
    assert _design(page)["width"] == 2.0
    state = page.js(
        '(() => { const svg = document.querySelector(\'svg[data-response="k_x"][data-factor="density"]\');'
        " return {disabled: document.getElementById('s-density').disabled,"
        " shown: document.getElementById('v-density').textContent, label: svg.getAttribute('aria-label'),"
        " curve: svg.querySelector('polyline').getAttribute('points'),"
        " note: document.getElementById('notes').textContent}; })()"
    )
    assert state["disabled"] and state["shown"] == "100 % (solid)"
    assert "flat" in state["label"] and "prints solid" in state["note"]
    ys = {p.split(",")[1] for p in state["curve"].split()}
    assert len(ys) == 1, "the density panel must be flat"
    _check_k(page, sur, ("k_x", "c_x"))  # the library predicts it at 100 % too


def test_remembered_settings_copy_as_command_and_json_that_run(page, sur, tmp_path):
    _set_goal(page, "k_x", "target", 0.8)
    page.click("#maximize")
    page.click("#remember")
    page.click("#s-height", 0.9)
    page.click("#remember")
    assert page.js("document.querySelectorAll('#memory tr').length") == 3
    page.click("#copy-cmd-1")
    command = page.js("document.getElementById('export-text').value")
    assert command.startswith("designer export fmu --density ")
    page.click("#copy-json")
    (tmp_path / "kept.json").write_text(page.js("document.getElementById('export-text').value"))
    run = subprocess.run(shlex.split(command), capture_output=True, text=True, cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    run = subprocess.run(
        [str(EXE), "export", "fmu", "--from", "kept.json", "--candidate", "1", "-o", "from.fmu"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert run.returncode == 0, run.stderr

    def k_start(fmu: Path) -> str:
        xml = zipfile.ZipFile(fmu).read("modelDescription.xml").decode()
        return xml.split('name="x.k"')[1].split('start="')[1].split('"')[0]

    assert float(k_start(tmp_path / "joint1.fmu")) == pytest.approx(
        float(k_start(tmp_path / "from.fmu")), rel=1e-9
    )
    assert set(page.requests()) == {page.js("location.href")}  # all that, and no request but the page
    # the table survives a reload (kept in the page's local storage). Chromium commits a page's local
    # storage to the browser process asynchronously, so a reload at once may read it before the
    # commit (seen once in a whole-suite run): reload until it shows, for at most 5 s
    deadline = time.monotonic() + 5
    rows = 0
    while rows != 3 and time.monotonic() < deadline:
        time.sleep(0.2)
        page.goto(page.js("location.href"))
        rows = page.js("document.querySelectorAll('#memory tr').length")
    assert rows == 3


def test_suggestion_buttons_name_the_factors_and_say_why_one_is_out_of_reach(browser, tmp_path, sur):
    from designer.plots import profile

    inside = dict(profile.DEFAULT_DESIGN, width=3.5)
    far = dict(profile.DEFAULT_DESIGN, width=8.0)
    sug = {"candidates": [{"params": inside, "p_within": 0.41}, {"params": far}]}
    profile.write_profiler(profile.build_profiler(sur, suggestion=sug), tmp_path / "s.html")
    page = browser.new_page()
    page.goto((tmp_path / "s.html").resolve().as_uri())
    names = {n["name"]["value"] for n in page.ax_tree() if n.get("role", {}).get("value") == "button"}
    assert (
        "#1, P 41 %: density 60 %, length 24 mm, width 3.5 mm, height 9 mm, layer 0.16 mm, raster 0 deg"
        in names
    )
    why = page.js(
        "(() => { const e = document.querySelector('#sug-2 .why');"
        " return [e.textContent, e.offsetHeight]; })()"
    )
    assert why[0] == "not shown: width 8 mm outside 2 to 7 mm (an extrapolation the sliders cannot reach)"
    assert why[1] > 0  # visible, not a tooltip
    page.click("#sug-1")
    assert _design(page)["width"] == 3.5
    page.call("Page.close")


def test_every_html_output_fits_a_phone(browser, sur, tmp_path):
    """plot space --html and the validation report: a viewport meta, no horizontal overflow at 390 px."""
    from designer.plots import html3d, space
    from designer.study.data import load_table
    from designer.validate import checks, report
    from designer.validate.study import check_dataset

    html3d.write_scene(space.surface_view(sur, "k_x", resolution=9).scene, tmp_path / "scene.html")
    figures = tmp_path / "figures"
    figures.mkdir()
    results = checks.run_checks(checks.Context(load_table(), figures), (check_dataset,))
    page_path, _ = report.write_report(results, tmp_path, 1.0)
    for path in (tmp_path / "scene.html", page_path):
        assert 'name="viewport"' in path.read_text().replace("'", '"'), path.name
        page = browser.new_page()
        page.viewport(390, 844, mobile=True)
        page.goto(path.resolve().as_uri())
        sizes = page.js("[document.documentElement.scrollWidth, document.documentElement.clientWidth]")
        assert sizes[0] <= sizes[1], (path.name, sizes)
        page.call("Page.close")
