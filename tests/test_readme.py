"""Every command in README's code blocks (and its table of plot commands) runs verbatim, in order, in a
fresh folder holding only the repository's `examples/`: the files a command names exist or are made
by an earlier command. Only `pip install` lines are skipped: CI has installed the package already,
and the Quick start's second line would run this very suite again."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"


def readme_commands(text: str) -> list[str]:
    """Shell commands in README order: lines of ```bash blocks (continuations joined) and the
    `designer ...` commands that open a table row."""
    found = []
    for block in re.finditer(r"```bash\n(.*?)```", text, flags=re.S):
        for line in block.group(1).replace("\\\n", " ").splitlines():
            if line.strip():
                found.append((block.start(), line.strip()))
    for row in re.finditer(r"^\| `(designer [^`]+)` \|", text, flags=re.M):
        found.append((row.start(), row.group(1)))
    return [cmd for _, cmd in sorted(found, key=lambda f: f[0]) if not cmd.startswith("pip install")]


def test_readme_names_its_commands():
    commands = readme_commands(README.read_text())
    assert len(commands) >= 25
    assert not [c for c in commands if "|mjcf" in c or "[--" in c], "shell notation instead of commands"


def test_readme_commands_run_verbatim(tmp_path):
    shutil.copytree(ROOT / "examples", tmp_path / "examples")
    env = dict(os.environ, PATH=f"{Path(sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}")
    env.pop("PYTHONPATH", None)
    timings = []
    for cmd in readme_commands(README.read_text()):
        start = time.perf_counter()
        r = subprocess.run(["bash", "-c", cmd], cwd=tmp_path, env=env, capture_output=True, text=True)
        timings.append((time.perf_counter() - start, cmd))
        assert r.returncode == 0, f"{cmd}\n{r.stderr[-2000:]}"
        assert "Traceback" not in r.stderr, cmd
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists(), "MuJoCo's log left in the current folder"
    print("\n".join(f"{s:6.1f} s  {c}" for s, c in sorted(timings, reverse=True)))
