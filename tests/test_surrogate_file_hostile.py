"""Issue 37, cause 1: a hand-edited surrogate file. Each edit below is one a user can make in a text
editor (a NaN or huge coefficient, a negative sigma, a covariance of the wrong shape, swapped forms,
the JSON literals NaN and Infinity, deep nesting, a huge integer); each must end as exit 2 in one line
naming the key and "refit it", in every command that reads a surrogate, never as a NaN or infinite
stiffness with exit 0, a reversed interval, or exit 3."""

from __future__ import annotations

import copy
import json
from collections.abc import Callable
from pathlib import Path

import pytest
from clitools import assert_clean_failure, run_inprocess
from test_cli_campaign import SIX

from designer.model.surrogate import Surrogate, default_path

SHIPPED = json.loads(default_path().read_text())


def k_x(d: dict) -> dict:
    return d["responses"]["k_x"]


def edit(change: Callable[[dict], None]) -> Callable[[], str]:
    def make() -> str:
        d = copy.deepcopy(SHIPPED)
        change(d)
        return json.dumps(d)

    return make


def text_edit(old: str, new: str) -> Callable[[], str]:
    """An edit made on the text, for what json.dumps cannot write (literals, huge integers)."""

    def make() -> str:
        text = json.dumps(SHIPPED)
        assert old in text
        return text.replace(old, new, 1)

    return make


def sigma_text() -> str:
    return f'"sigma": {json.dumps(k_x(SHIPPED)["sigma"])}'


# name: (the file's text, words the message must hold)
EDITS: dict[str, tuple[Callable[[], str], str]] = {
    "coef NaN": (edit(lambda d: k_x(d)["coef"].__setitem__(1, float("nan"))), "coef"),
    "coef 1e308": (edit(lambda d: k_x(d)["coef"].__setitem__(1, 1e308)), "coef"),
    "coef 1e30 (finite, absurd)": (edit(lambda d: k_x(d)["coef"].__setitem__(0, 1e30)), "k_x"),
    "coef short": (edit(lambda d: k_x(d)["coef"].pop()), "coef"),
    "coef text": (edit(lambda d: k_x(d)["coef"].__setitem__(0, "0.1")), "coef"),
    "t95 NaN literal": (text_edit('"t95": 2.0255476624403013', '"t95": NaN'), "t95"),
    "t95 zero": (edit(lambda d: k_x(d).__setitem__("t95", 0.0)), "t95"),
    "sigma Infinity literal": (lambda: text_edit(sigma_text(), '"sigma": Infinity')(), "sigma"),
    "sigma negative": (edit(lambda d: k_x(d).__setitem__("sigma", -k_x(d)["sigma"])), "sigma"),
    "vcov 1x1": (edit(lambda d: k_x(d).__setitem__("vcov", [[1.0]])), "vcov"),
    "vcov ragged": (edit(lambda d: k_x(d)["vcov"][2].pop()), "vcov"),
    "vcov negative definite": (
        edit(lambda d: k_x(d).__setitem__("vcov", [[-v for v in row] for row in k_x(d)["vcov"]])),
        "vcov",
    ),
    "forms swapped": (
        edit(
            lambda d: (
                k_x(d).__setitem__("form", "mean"),
                d["responses"]["c_x"].__setitem__("form", "powerlaw"),
            )
        ),
        "shape",
    ),
    "unknown form": (edit(lambda d: k_x(d).__setitem__("form", "cubic")), "form"),
    "dof zero": (edit(lambda d: k_x(d).__setitem__("dof", 0)), "dof"),
    "huge integer": (text_edit(sigma_text(), '"sigma": ' + "9" * 400), "sigma"),
    "deep nesting": (
        lambda: json.dumps(SHIPPED)[:-1] + ', "x": ' + "[" * 100_000 + "]" * 100_000 + "}",
        "nested",
    ),
    "training short column": (edit(lambda d: d["training"]["width"].pop()), "training width"),
    "training empty": (edit(lambda d: d.__setitem__("training", {k: [] for k in d["training"]})), "training"),
    "training NaN width": (text_edit('"width": [', '"width": [NaN, '), "training width"),
    "no responses": (edit(lambda d: d.__setitem__("responses", {})), "responses"),
    "response not a coefficient": (
        edit(lambda d: d["responses"].__setitem__("k_w", d["responses"].pop("k_x"))),
        "k_w",
    ),
    "influence row out of range": (
        edit(lambda d: k_x(d)["influence"][0].__setitem__("row", 999)),
        "influence",
    ),
    "loo predictions short": (edit(lambda d: k_x(d)["loo_predictions"]["value"].pop()), "loo_predictions"),
    "observed range reversed": (
        edit(lambda d: k_x(d).__setitem__("observed_range", [2.0, 0.2])),
        "observed_range",
    ),
}


@pytest.fixture(scope="module")
def files(tmp_path_factory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("edited")
    out = {}
    for i, (name, (make, _)) in enumerate(EDITS.items()):
        out[name] = folder / f"s{i}.json"
        out[name].write_text(make())
    return out


@pytest.mark.parametrize("name", list(EDITS))
def test_predict_refuses_an_edited_surrogate_naming_the_value(name, files, capsys):
    code, out, err = run_inprocess(["predict", *SIX, "--json", "--surrogate", files[name]], capsys)
    assert_clean_failure(code, err, allowed=(2,))
    assert "refit it" in err and EDITS[name][1] in err, err
    assert out == ""


@pytest.mark.parametrize(
    "command",
    [
        ["suggest", "--k", "0.8", "--json"],
        ["profile", "--json"],
        ["next", "--k", "0.8", "--json"],
        ["calibrate", "RUNS", "-o", "OUT", "--json"],
    ],
    ids=lambda c: c[0],
)
@pytest.mark.parametrize("name", ["coef 1e308", "sigma negative", "vcov 1x1"])
def test_every_command_reading_a_surrogate_refuses_it(command, name, files, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    runs = tmp_path / "runs.csv"
    runs.write_text("density,length,width,height,layer,raster,k_x,c_x\n60,24,4.5,9,0.16,0,0.8,0.002\n")
    args = [{"RUNS": runs, "OUT": tmp_path / "o.json"}.get(a, a) for a in command]
    code, _, err = run_inprocess([*args, "--surrogate", files[name]], capsys)
    assert_clean_failure(code, err, allowed=(2,))
    assert "refit it" in err and EDITS[name][1] in err, err
    assert [p.name for p in tmp_path.iterdir()] == ["runs.csv"]


def test_the_shipped_and_a_refitted_surrogate_still_load(tmp_path):
    """The checks pass what fit writes: the shipped file, and a fit with c and k of two axes saved."""
    shipped = Surrogate.load()
    assert shipped.id == SHIPPED["id"]
    again = Surrogate.load(shipped.save(tmp_path / "again.json"))
    assert again.id == shipped.id
    p = again.predict({"density": 60, "length": 24, "width": 4.5, "height": 9, "layer": 0.16, "raster": 0})
    assert 0 < p["k_x"].low < p["k_x"].value < p["k_x"].high


RUN_EDITS: dict[str, tuple[Callable[[dict], object], str]] = {
    "a huge width": (lambda r: r["width"].__setitem__(0, 1e308), "width"),
    "a null k": (lambda r: r["k_x"].__setitem__(0, None), "k_x[0]"),
    "a text c": (lambda r: r["c_x"].__setitem__(0, "abc"), "c_x[0]"),
    "a negative k": (lambda r: r["k_x"].__setitem__(0, -1.0), "k_x[0]"),
    "an untested layer": (lambda r: r["layer"].__setitem__(0, 0.3), "layer"),
    "a short column": (lambda r: r["height"].pop(), "height"),
    "no raster": (lambda r: r.pop("raster"), "raster"),
    "no run": (lambda r: [v.clear() for v in r.values()], "density"),
    "no response": (lambda r: [r.pop("k_x"), r.pop("c_x")], "responses"),
}


@pytest.mark.parametrize("name", RUN_EDITS)
def test_a_calibrated_surrogate_with_an_edited_run_is_refused(tmp_path, capsys, name):
    """The saved runs are checked without pandas (`stored.calibration_runs`, issue 38) as strictly as
    load_table checked them: each edit ends as exit 2 naming the column and the fix (a file with its
    runs emptied loaded as the uncalibrated study before)."""
    runs = tmp_path / "runs.csv"
    runs.write_text("density,length,width,height,layer,raster,k_x,c_x\n60,24,4.5,9,0.16,0,0.8,0.002\n")
    out = tmp_path / "cal.json"
    code, _, err = run_inprocess(["calibrate", runs, "-o", out], capsys)
    assert code == 0, err
    d = json.loads(out.read_text())
    change, named = RUN_EDITS[name]
    change(d["calibration"]["runs"])
    out.write_text(json.dumps(d))
    code, _, err = run_inprocess(["predict", *SIX, "--surrogate", out], capsys)
    assert_clean_failure(code, err, allowed=(2,))
    assert named in err and "recalibrate it" in err, err


def test_a_calibrated_file_loads_without_pandas(tmp_path):
    """Its runs are read as arrays: next --surrogate imports no pandas (0.4 s, issue 38)."""
    import subprocess
    import sys

    import designer

    runs = designer.load_table().iloc[[0, 7]]
    cal = designer.calibrate(Surrogate.load(), runs)
    path = cal.save(tmp_path / "cal.json")
    code = (
        f"import sys; from designer.model.surrogate import Surrogate; s = Surrogate.load({str(path)!r});"
        "print(s.calibration.n_runs, 'pandas' in sys.modules)"
    )
    done = subprocess.run([sys.executable, "-I", "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.split() == ["2", "False"]
