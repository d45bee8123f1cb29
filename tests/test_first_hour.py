"""A new user's first hour, scripted: Quick start's first line (venv, install, a first answer) and
README's first-hour block, verbatim, in a fresh virtual environment, on a copy of the checkout; then
the block must be one story: the FMU the arm co-simulated is the file `export fmu` wrote, on the
hinge axis theta, with the stiffness and damping of the design `suggest` ranked first.

The fresh environment sees this environment's third-party packages through a .pth file (numpy,
MuJoCo, casadi ... are 2 GB: downloading them again would add minutes and test the package index, not
this project); the project itself is built and installed into it by README's own `pip install .`,
from the copied checkout, and every command then runs from that install.
"""

from __future__ import annotations

import json
import os
import re
import shlex
import shutil
import site
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from fmpy import read_model_description

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[1]


def _block_after(text: str, heading: str) -> list[str]:
    """The lines of the first ```bash block after `heading`."""
    after = text[text.index(heading) :]
    block = re.search(r"```bash\n(.*?)```", after, flags=re.S).group(1)
    return [line for line in block.splitlines() if line.strip()]


def test_first_hour_in_a_fresh_venv(tmp_path):
    if shutil.which("git") is None or not (ROOT / ".git").exists():
        pytest.skip("needs the git checkout to copy its tracked files")
    readme = (ROOT / "README.md").read_text()
    setup_line = _block_after(readme, "## Quick start")[0]
    first_hour = _block_after(readme, "## The first hour")
    assert setup_line.startswith("python3 -m venv .venv && . .venv/bin/activate && pip install . && ")

    checkout = tmp_path / "checkout"
    files = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True, check=True)
    for name in files.stdout.splitlines():
        if (ROOT / name).is_file():
            (checkout / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(ROOT / name, checkout / name)
    venv = checkout / ".venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    inner = next(venv.glob("lib/python*/site-packages"))
    (inner / "_third_party.pth").write_text("\n".join(site.getsitepackages()) + "\n")

    script = "\n".join(["set -e", setup_line, *first_hour, "command -v designer"])
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    env["PATH"] = f"{Path(sys.executable).parent}{os.pathsep}{env.get('PATH', '')}"
    run = subprocess.run(["bash", "-c", script], cwd=checkout, env=env, capture_output=True, text=True)
    assert run.returncode == 0, run.stdout[-2000:] + run.stderr[-3000:]
    assert run.stdout.strip().splitlines()[-1] == str(venv / "bin" / "designer")
    assert "validation: pass" in run.stdout
    for made in (
        "suggestion.json",
        "joint.fmu",
        "results/arm/timeseries.csv",
        "results/arm.png",
        "profile.html",
        "prints/plate.3mf",
        "prints/P1.stl",
        "prints/runs.csv",
    ):
        assert (checkout / made).stat().st_size > 0, made
    where = subprocess.run(
        [str(venv / "bin" / "python"), "-I", "-c", "import designer; print(designer.__file__)"],
        capture_output=True,
        text=True,
        check=True,
    )
    assert where.stdout.startswith(str(inner)), "the project runs from the fresh install, not elsewhere"
    _check_one_story(checkout, first_hour)


def _command(lines: list[str], start: str) -> list[str]:
    """The words of the one line that starts with `start`, its comment dropped."""
    (line,) = [x for x in lines if x.startswith(start)]
    return shlex.split(line, comments=True)


def _option(words: list[str], name: str) -> str:
    return words[words.index(name) + 1]


def _check_one_story(checkout: Path, first_hour: list[str]) -> None:
    """The suggestion's best design is the FMU exported on theta, and that file is what the arm ran."""
    export = _command(first_hour, "designer export fmu")
    cosim = _command(first_hour, "designer cosim")
    fmu = (checkout / _option(export, "-o")).resolve()
    assert _option(export, "--axis") == "theta", "a robot's hinge needs the rotational axis"

    scenario_path = checkout / cosim[2]
    scenario = tomllib.loads(scenario_path.read_text())
    joints = scenario["joints"]
    ran = {
        name: (scenario_path.parent / j["fmu"]).resolve() if "fmu" in j else j for name, j in joints.items()
    }
    assert joints and all(path == fmu for path in ran.values()), f"exported {fmu}, the arm ran {ran}"
    assert {j.get("axis", "theta") for j in joints.values()} == {"theta"}

    variables = {v.name: v for v in read_model_description(str(fmu)).modelVariables}
    assert {n.split(".")[0] for n in variables if n.endswith(".k")} == {"theta"}
    k_fmu, c_fmu = float(variables["theta.k"].start), float(variables["theta.c"].start)

    # the suggestion's best design taken to theta by the pseudo-rigid-body model, N.mm/rad -> N.m/rad
    best = json.loads((checkout / _option(export, "--from")).read_text())["candidates"][0]
    arm = (0.85 * best["params"]["length"]) ** 2 / 1000
    assert k_fmu == pytest.approx(best["predicted"]["k"]["value"] * arm, rel=1e-9)
    assert c_fmu == pytest.approx(best["predicted"]["c"]["value"] * arm, rel=1e-9)

    # the torque the arm felt is that FMU's law, f = -(k s + c v), at every step of every joint
    series = pd.read_csv(checkout / _option(cosim, "-o") / "timeseries.csv")
    for name in joints:
        s, v = series[f"robot.{name}.s"].to_numpy(), series[f"robot.{name}.v"].to_numpy()
        (k, c), *_ = np.linalg.lstsq(np.c_[s, v], -series[f"{name}.theta.f"].to_numpy(), rcond=None)
        assert (k, c) == (pytest.approx(k_fmu, rel=1e-9), pytest.approx(c_fmu, rel=1e-6)), name
        assert np.ptp(s) > 0.01, f"{name} barely moved: the check would say nothing"
