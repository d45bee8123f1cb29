"""The `designer` command for fit, predict and suggest: JSON schema, help, bad input without traceback."""

import json
import subprocess
import sys

import pytest


def designer(*args, check=False):
    cmd = [sys.executable, "-I", "-c", "from designer_cli.main import main; main()", *args]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=300, check=check)


def test_suggest_json_schema():
    r = designer("suggest", "--k", "0.8", "--c", "2e-3", "--json", check=True)
    d = json.loads(r.stdout)
    assert d["axis"] == "x" and d["targets"] == {"k": 0.8, "c": 0.002}
    assert isinstance(d["reachable"], bool)
    cand = d["candidates"][0]
    assert set(cand["params"]) == {"density", "length", "width", "height", "layer", "raster"}
    for q in ("k", "c"):
        assert set(cand["predicted"][q]) == {"value", "low", "high"}
    assert 0 <= cand["desirability"] <= 1
    assert abs(cand["predicted"]["k"]["value"] / 0.8 - 1) <= 0.02


def test_suggest_prints_units_and_predictability():
    out = designer("suggest", "--k", "0.8", "--c", "2e-3", check=True).stdout
    assert "N/mm" in out and "N.s/mm" in out
    assert "not predictable" in out and "95 % PI" in out


def test_predict_json():
    args = ["--density", "60", "--length", "24", "--width", "4.5", "--height", "9", "--layer", "0.16"]
    d = json.loads(designer("predict", *args, "--raster", "0", "--json", check=True).stdout)
    assert d["axis"] == "x" and d["params"]["width"] == 4.5
    k = d["predicted"]["k"]
    assert k["low"] < k["value"] < k["high"] and k["unit"] == "N/mm"


def test_fit_json_reports_loo(tmp_path):
    out = tmp_path / "s.json"
    d = json.loads(designer("fit", "--json", "-o", str(out), check=True).stdout)
    assert d["responses"]["k_x"]["loo"]["q2"] >= 0.40
    assert d["responses"]["k_x"]["form"] == "powerlaw"
    assert set(d["responses"]["c_x"]["loo"]) >= {"rmse", "mape", "q2"}
    assert out.exists()
    r = designer("suggest", "--k", "0.8", "--surrogate", str(out), "--json", check=True)
    assert json.loads(r.stdout)["surrogate_id"] == d["surrogate_id"]


@pytest.mark.parametrize(
    "args, message",
    [
        (["suggest", "--k", "0.8", "--fix", "colour=3"], "unknown factor 'colour'"),
        (["suggest", "--k", "0.8", "--fix", "width"], "is not NAME=VALUE"),
        (["suggest", "--k", "0.8", "--fix", "width=20"], "outside the tested range"),
        (["suggest", "--k", "-1"], "must be positive"),
        (["suggest", "--c", "0"], "must be positive"),
        (["predict", "--density", "60"], "missing factor"),
        (
            [
                "predict",
                "--density",
                "nan",
                "--length",
                "24",
                "--width",
                "4.5",
                "--height",
                "9",
                "--layer",
                "0.16",
                "--raster",
                "0",
            ],
            "not a finite number",
        ),
        (["fit", "--data", "/nonexistent.csv"], "no such table"),
    ],
)
def test_bad_input_one_line_exit_2(args, message):
    r = designer(*args)
    assert r.returncode == 2, r.stderr
    assert message in r.stderr
    assert "Traceback" not in r.stderr and len(r.stderr.strip().splitlines()) == 1


def test_malformed_table_and_unwritable_output(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("density,length\n1,2\n")
    r = designer("fit", "--data", str(bad))
    assert r.returncode == 2 and "missing factor column" in r.stderr
    r = designer("fit", "-o", str(tmp_path / "no" / "dir" / "s.json"))
    assert r.returncode == 2 and "does not exist" in r.stderr
    assert not list(tmp_path.glob("**/*.part"))


@pytest.mark.parametrize("command", ["fit", "predict", "suggest"])
def test_help_has_an_example(command):
    out = designer(command, "--help", check=True).stdout
    assert "Example: designer " + command in out
