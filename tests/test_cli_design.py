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
    assert d["goals"]["k"]["kind"] == "target" and d["tolerance"] == 0.1
    assert d["reachable"] is True
    cand = d["candidates"][0]
    assert set(cand["params"]) == {"density", "length", "width", "height", "layer", "raster"}
    for q in ("k", "c"):
        assert set(cand["predicted"][q]) == {"value", "low", "high"}
    assert 0 <= cand["desirability"] <= 1 and 0 < cand["p_within"] < 1
    assert set(cand["probability"]) == {"k", "c"} and cand["extrapolated"] == [] and cand["any"] == []
    assert abs(cand["predicted"]["k"]["value"] / 0.8 - 1) <= 0.02


def test_suggest_prints_units_probability_and_predictability():
    out = designer("suggest", "--k", "0.8", "--c", "2e-3", check=True).stdout
    assert "N/mm" in out and "N.s/mm" in out and "+-10 %" in out
    assert "not predictable" in out and "95 % PI" in out and "with probability" in out


def test_suggest_unreachable_exits_1_and_names_measured_runs():
    r = designer("suggest", "--k", "2.0", "--top", "2", "--json")
    assert r.returncode == 1, r.stderr
    d = json.loads(r.stdout)
    assert d["reachable"] is False and d["nearest_runs"][0]["run"] == 21
    assert d["ranges"]["k"]["measured"] == [0.246, 2.092] and d["ranges"]["k"]["predicted"][1] < 2.0
    r = designer("suggest", "--k", "2.0", "--top", "2")
    assert r.returncode == 1 and "run 21 measured 2.09 N/mm" in r.stdout


def test_suggest_min_max_goals_and_extrapolation_flags():
    r = designer("suggest", "--k", "0.5", "--c", "max", "--top", "2", check=True)
    assert "'max' cannot be acted on" in r.stdout
    d = json.loads(designer("suggest", "--k", "max", "--top", "1", "--json", check=True).stdout)
    assert d["targets"]["k"] == "max" and d["candidates"][0]["p_within"] is None
    r = designer("suggest", "--k", "2.5", "--top", "2", "--allow-extrapolation", "--json")
    for cand in json.loads(r.stdout)["candidates"]:
        assert cand["extrapolated"] and cand["params"]["height"] >= 2.0 and cand["params"]["width"] >= 2.0
    out = designer("suggest", "--k", "2.5", "--top", "1", "--allow-extrapolation").stdout
    assert "*" in out and "any" in out


def test_predict_json():
    args = ["--density", "60", "--length", "24", "--width", "4.5", "--height", "9", "--layer", "0.16"]
    d = json.loads(designer("predict", *args, "--raster", "0", "--json", check=True).stdout)
    assert d["axis"] == "x" and d["params"]["width"] == 4.5 and d["extrapolated"] == []
    k = d["predicted"]["k"]
    assert k["low"] < k["value"] < k["high"] and k["unit"] == "N/mm"
    args[-3] = "3"  # height 3 mm: below the tested 4 mm, printable
    d = json.loads(
        designer("predict", *args, "--raster", "0", "--allow-extrapolation", "--json", check=True).stdout
    )
    assert d["extrapolated"] == ["height"] and any("extrapolation" in n for n in d["notes"])


def test_fit_json_reports_nested_loo(tmp_path):
    out = tmp_path / "s.json"
    d = json.loads(designer("fit", "--json", "-o", str(out), check=True).stdout)
    k = d["responses"]["k_x"]
    assert 0.30 <= k["loo_nested"]["q2"] <= 0.34 and k["loo"]["q2"] >= 0.40
    assert set(k["loo_nested"]) == {"q2", "rmse", "mape", "coverage95"} and "selected form" in k["loo_label"]
    assert k["form"] == "powerlaw" and any(i["run"] == 21 and i["form"] == "linear" for i in k["influence"])
    assert k["lack_of_fit"]["df_pure_error"] == 1  # the study ran one design twice
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
        (["fit", "-o", "/"], "is a folder"),
        (["fit", "-o", "surrogate.txt"], "the suffix '.txt' is not .json"),
        (["suggest", "--k", "0.8", "--fix", "width=3", "--fix", "width=5"], "--fix width is given twice"),
        (["suggest", "--k", "0.8", "--fix", "colour=red"], "unknown factor 'colour'"),
        (["suggest", "--k", "stiff"], "--k 'stiff' is not a number, min or max"),
        (["suggest", "--k", "0.8", "--tolerance", "0"], "--tolerance 0 is not between"),
        (["suggest", "--k", "0.8", "--weight-k", "-1"], "--weight-k -1 must be positive"),
        (["suggest", "--k", "0.8", "--fix", "height=1", "--allow-extrapolation"], "cannot be printed"),
    ],
)
def test_bad_input_one_line_exit_2(args, message):
    r = designer(*args)
    assert r.returncode == 2, r.stderr
    assert message in r.stderr
    assert "Traceback" not in r.stderr and len(r.stderr.strip().splitlines()) == 1


def test_constant_factor_table_is_one_line(tmp_path):
    from designer.study import data

    t = data.load_table()
    t["raster"] = 0.0
    t.to_csv(tmp_path / "t.csv", index=False)
    r = designer("fit", "--data", str(tmp_path / "t.csv"))
    assert r.returncode == 2 and "raster is 0 deg in every run" in r.stderr and "Traceback" not in r.stderr


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
