"""The build is silent: `pip wheel . --no-deps` with this pip and the newest setuptools its build
isolation installs prints no warning. A setuptools warning today is a failed build tomorrow: the
license as a TOML table is deprecated with a removal date, and folders the wheel ships but
`packages` leaves out are warned about once each."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SHIPPED = ("designer", "cli", "fmus", "surrogates")

# a warning as Python prints it ("...: SetuptoolsDeprecationWarning: ...") or as pip does ("WARNING: ...")
WARNING = re.compile(r"\b[A-Z]\w*Warning\b|^\s*WARNING:", flags=re.M)


def test_pip_wheel_prints_no_warning(tmp_path):
    source = tmp_path / "source"
    source.mkdir()
    for name in ("pyproject.toml", "README.md"):
        shutil.copy2(ROOT / name, source / name)
    junk = shutil.ignore_patterns("__pycache__", "*.egg-info", "build", "*.pyc")
    for folder in SHIPPED:
        shutil.copytree(ROOT / folder, source / folder, ignore=junk)
    # -v: pip shows the build backend's own output (older pips hide it without -v)
    run = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", ".", "--no-deps", "-v", "-w", str(tmp_path / "wheel")],
        cwd=source,
        capture_output=True,
        text=True,
    )
    out = run.stdout + run.stderr
    assert run.returncode == 0, out[-3000:]
    warned = sorted({line.strip() for line in out.splitlines() if WARNING.search(line)})
    assert not warned, "\n".join(warned)
    assert len(list((tmp_path / "wheel").glob("flexjoint_designer-*.whl"))) == 1
