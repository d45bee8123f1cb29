"""`designer export`: joint sources, bad-input messages, and the Modelica, MJCF and URDF outputs."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from designer.export import build
from designer.export.modelica import modelica_text
from designer.joint import PRB_GAMMA, Joint

DESIGN = {"density": 60, "length": 24, "width": 4.5, "height": 9, "layer": 0.16, "raster": 0}


def run(*args, env=None):
    import os

    e = dict(os.environ, **(env or {}))
    if args[:2] == ("export", "fmu") and "--platforms" not in args:
        args = (
            *args,
            "--platforms",
            "host",
        )  # the default, all platforms, is tested below and in test_fmu_platforms
    return subprocess.run(
        [sys.executable, "-I", "-c", "from designer_cli.main import main; main()", *args],
        capture_output=True,
        text=True,
        env=e,
    )


@pytest.fixture()
def cache_env(tmp_path):
    return {"XDG_CACHE_HOME": str(tmp_path / "cache")}


class FakeSurrogate:
    """A surrogate with the documented interface and known numbers."""

    id = "fake-1"
    responses = ["c_x", "k_x"]
    axes = ["x"]

    def predict(self, X, *, allow_extrapolation=False):
        from designer import Prediction

        def one(v):
            return Prediction(np.array([v]), np.array([v / 2]), np.array([v * 2]))

        return {"k_x": one(0.8), "c_x": one(2e-3)}


def test_joint_from_design_carries_pis_settings_mass_and_prb():
    j = Joint.from_design(DESIGN, axes=["x", "theta"], surrogate=FakeSurrogate())
    assert j.axes["x"].k == 0.8 and (j.axes["x"].predicted["k"].low, j.axes["x"].predicted["k"].high) == (
        0.4,
        1.6,
    )
    assert j.provenance["params"]["width"] == 4.5 and j.provenance["surrogate"] == "fake-1"
    assert j.axes["x"].m > 0
    arm = PRB_GAMMA * 24
    assert j.axes["theta"].k == pytest.approx(0.8 * arm**2)
    assert "derived, not measured" in j.axes["theta"].origin


def test_joint_from_suggestion(tmp_path):
    s = {
        "axis": "x",
        "targets": {"k": 0.8},
        "reachable": True,
        "candidates": [
            {
                "params": DESIGN,
                "predicted": {
                    "k": {"value": 0.7, "low": 0.5, "high": 0.9},
                    "c": {"value": 1e-3, "low": 0, "high": 3e-3},
                },
                "desirability": 0.9,
            },
            {
                "params": DESIGN,
                "predicted": {
                    "k": {"value": 0.6, "low": 0.3, "high": 1.2},
                    "c": {"value": 1e-3, "low": 0, "high": 3e-3},
                },
                "desirability": 0.5,
            },
        ],
    }
    p = tmp_path / "s.json"
    p.write_text(json.dumps(s))
    j = Joint.from_suggestion(p, candidate=2)
    assert j.axes["x"].k == 0.6 and j.provenance["desirability"] == 0.5 and j.axes["x"].m > 0
    r = run("export", "fmu", "--from", str(p), "--candidate", "3", "-o", str(tmp_path / "j.fmu"))
    assert r.returncode == 2 and "candidate 3 does not exist" in r.stderr and "Traceback" not in r.stderr


def test_cli_exports_fmu_with_json(tmp_path, cache_env):
    out = tmp_path / "j.fmu"
    r = run(
        "export",
        "fmu",
        "--k",
        "0.8",
        "--c",
        "2e-3",
        "--m",
        "0.01",
        "--interface",
        "body",
        "--fmi",
        "3",
        "-o",
        str(out),
        "--json",
        env=cache_env,
    )
    assert r.returncode == 0, r.stderr
    data = json.loads(r.stdout)
    assert data["path"] == str(out) and data["joint"]["axes"]["x"]["si"]["k"] == 800.0
    assert out.is_file()


@pytest.mark.parametrize(
    "args, message",
    [
        ([], "give the joint one way"),
        (["--k", "0.8", "--c", "2e-3", "--density", "60"], "give the joint one way"),
        (["--k", "0.8", "--c", "2e-3", "--interface", "body"], "needs a mass"),
        (["--k", "0.8"], "one --k and one --c per --axis"),
        (["--k", "-1", "--c", "2e-3"], "not a valid value"),
        (["--k", "0.8", "--c", "2e-3", "--axis", "w"], "unknown axis"),
        (["--k", "0.8", "--c", "2e-3", "--fmi", "4"], "--fmi 4 is not supported"),
        (["--k", "0.8", "--c", "2e-3", "--interface", "spring"], "--interface 'spring' is not an interface"),
        (["--density", "60"], "missing factor"),
        (
            ["--k", "0.8", "--c", "2e-3", "--surrogate", "mine.json"],
            "--surrogate predicts a joint from a design",
        ),
    ],
)
def test_cli_bad_input_is_one_line(tmp_path, cache_env, args, message):
    r = run("export", "fmu", *args, "-o", str(tmp_path / "j.fmu"), env=cache_env)
    assert r.returncode == 2
    assert r.stderr.startswith("error: ") and message in r.stderr and "Traceback" not in r.stderr
    assert not (tmp_path / "j.fmu").exists()


def test_cli_without_compiler_says_how_and_source_only_works(tmp_path, cache_env):
    env = dict(cache_env, CC="no-such-cc-xyz")
    out = str(tmp_path / "j.fmu")
    r = run(
        "export", "fmu", "--k", "0.8", "--c", "2e-3", "--build", "--platforms", "host", "-o", out, env=env
    )
    assert r.returncode == 2 and "no-such-cc-xyz" in r.stderr and "--source-only" in r.stderr
    assert "compiling the FMU binary for x86_64-linux (--build)" in r.stderr
    r = run("export", "fmu", "--k", "0.8", "--c", "2e-3", "--platforms", "all", "--json", "-o", out, env=env)
    assert r.returncode == 0 and "compiling" not in r.stderr, r.stderr
    assert json.loads(r.stdout)["platforms"] == list(build.PLATFORMS)
    r = run(
        "export", "fmu", "--k", "0.8", "--c", "2e-3", "--source-only", "-o", str(tmp_path / "j.fmu"), env=env
    )
    assert r.returncode == 0 and "build it from sources/" in r.stdout


def test_modelica_package_uses_msl_with_si_values():
    j = Joint.from_coefficients({"x": {"k": 0.8, "c": 2e-3, "m": 0.01}, "theta": {"k": 50.0, "c": 0.1}})
    text = modelica_text(j)
    assert "Modelica.Mechanics.Translational.Components.SpringDamper springDamper_x(c = k_x, d = c_x)" in text
    assert "TranslationalSpringConstant k_x = 800.0" in text and "Mass m_x = 0.01" in text
    assert "Rotational.Components.SpringDamper" in text and "RotationalSpringConstant k_theta = 0.05" in text
    assert "Inertia" not in text.split("k_theta")[1].split("end Joint")[0].replace("Documentation", "")
    assert 'uses(Modelica(version = "4.0.0"))' in text and "entered by hand" in text
    assert text.count("package FlexJoint") == 1 and text.rstrip().endswith("end FlexJoint;")


@pytest.mark.parametrize("fmt, suffix", [("modelica", ".mo"), ("mjcf", ".xml"), ("urdf", ".urdf")])
def test_cli_writes_snippets(tmp_path, fmt, suffix):
    out = tmp_path / f"j{suffix}"
    r = run("export", fmt, "--k", "0.8", "--c", "2e-3", "--m", "0.01", "-o", str(out))
    assert r.returncode == 0, r.stderr
    assert "800" in out.read_text() and "N/m" in r.stdout


def _starts(fmu) -> dict[str, float]:
    from fmpy import read_model_description

    md = read_model_description(str(fmu))
    return {
        v.name: float(v.start)
        for v in md.modelVariables
        if v.causality == "parameter" and not v.name.endswith(".enabled")
    }


def test_cli_exports_a_design_through_the_shipped_surrogate(tmp_path, cache_env):
    import pandas as pd

    from designer.model.surrogate import Surrogate

    flags = [x for f, v in DESIGN.items() for x in (f"--{f}", str(v))]
    out = tmp_path / "design.fmu"
    args = ["export", "fmu", *flags, "--axis", "x", "--axis", "theta", "--interface", "body", "-o", str(out)]
    r = run(*args, "--json", env=cache_env)
    assert r.returncode == 0, r.stderr
    axes = json.loads(r.stdout)["joint"]["axes"]
    pred = Surrogate.load().predict(pd.DataFrame([DESIGN]))
    k, c = float(pred["k_x"].value[0]), float(pred["c_x"].value[0])
    assert axes["x"]["rig"]["k"] == pytest.approx(k) and axes["x"]["rig"]["c"] == pytest.approx(c)
    assert axes["theta"]["rig"]["k"] == pytest.approx(k * (PRB_GAMMA * 24) ** 2)
    starts = _starts(out)
    assert starts["x.k"] == pytest.approx(k * 1e3) and starts["x.c"] == pytest.approx(c * 1e3)  # N/m, N.s/m
    assert starts["theta.k"] == pytest.approx(axes["theta"]["si"]["k"]) and starts["x.m"] > 0


def test_cli_exports_a_suggestion_from_designer_suggest(tmp_path, cache_env):
    r = run("suggest", "--k", "0.8", "--fix", "length=24", "--top", "2", "--json", env=cache_env)
    assert r.returncode == 0, r.stderr
    (tmp_path / "s.json").write_text(r.stdout)
    cand = json.loads(r.stdout)["candidates"][1]
    out = tmp_path / "s.fmu"
    r = run(
        "export", "fmu", "--from", str(tmp_path / "s.json"), "--candidate", "2", "--axis", "theta",
        "--fmi", "3", "-o", str(out), "--json", env=cache_env,
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    theta = json.loads(r.stdout)["joint"]["axes"]["theta"]
    k = cand["predicted"]["k"]["value"] * (PRB_GAMMA * 24) ** 2  # N.mm/rad
    assert theta["rig"]["k"] == pytest.approx(k) and _starts(out)["theta.k"] == pytest.approx(k * 1e-3)
