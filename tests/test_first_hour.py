"""A new user's first hour, scripted: README's install line and first-hour block, verbatim, in a fresh
virtual environment, on a copy of the checkout.

The fresh environment sees this environment's third-party packages through a .pth file (numpy,
MuJoCo, casadi ... are 2 GB: downloading them again would add minutes and test the package index, not
this project); the project itself is built and installed into it by README's own `pip install .`,
from the copied checkout, and every command then runs from that install.
"""

from __future__ import annotations

import os
import re
import shutil
import site
import subprocess
import sys
from pathlib import Path

import pytest

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
    venv_line = _block_after(readme, "## Install")[0]
    install_line = _block_after(readme, "## Quick start")[0]
    first_hour = _block_after(readme, "## The first hour")
    assert venv_line.startswith("python3 -m venv .venv") and install_line.startswith("pip install .")

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

    script = "\n".join(["set -e", venv_line, install_line, *first_hour, "command -v designer"])
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
