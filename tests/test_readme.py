"""Every command in README's code blocks (and its table of plot commands) runs verbatim, in order, in a
fresh folder holding only the repository's `examples/`: the files a command names exist or are made
by an earlier command. Only lines with a `pip install` are skipped: CI has installed the package
already, and the Quick start's second line would run this very suite again."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

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
    return [cmd for _, cmd in sorted(found, key=lambda f: f[0]) if "pip install " not in cmd]


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


def _figure(pattern: str) -> tuple[str, ...]:
    text = " ".join(README.read_text().split())  # the README wraps sentences anywhere
    m = re.search(pattern, text)
    assert m, f"README no longer states: {pattern}"
    return m.groups()


def test_readme_accuracy_figures_are_the_shipped_surrogates():
    """The figures README states for k_x are what `designer fit --json` reports of the shipped file."""
    from designer.model.surrogate import Surrogate

    q2, rmse, mape, inside = _figure(
        r"k_x is moderately predictable: nested Q2 = ([\d.]+), RMSE ([\d.]+) N/mm, "
        r"MAPE (\d+) %, (\d+) % of runs"
    )
    nested = Surrogate.load().model("k_x").loo_nested
    assert (float(q2), float(rmse)) == (round(nested["q2"], 2), round(nested["rmse"], 2))
    assert (int(mape), int(inside)) == (round(nested["mape"]), round(100 * nested["coverage95"]))


def test_readme_sweep_figures_are_what_the_example_sweep_prints(tmp_path):
    """README's example-sweep sentence (percentiles, settle count, share meeting both limits), rerun."""
    import json

    p5, p50, p95 = map(int, _figure(r"j2's overshoot after its step is (\d+) / (\d+) / (\d+) %"))
    (settled,) = map(int, _figure(r"only (\d+) of the 200 draws settle"))
    (share,) = map(float, _figure(r"and ([\d.]+) % of the prints meet both limits"))
    out = tmp_path / "sweep"
    example = ROOT / "examples" / "sweep_arm.toml"
    run = subprocess.run(
        [
            sys.executable,
            "-I",
            "-c",
            "from designer_cli.main import main; main()",
            "sweep",
            str(example),
            "-o",
            str(out),
        ],
        capture_output=True,
        text=True,
    )
    assert run.returncode == 0, run.stderr
    summary = json.loads((out / "summary.json").read_text())
    over = summary["percentiles"]["j2.overshoot_pct"]
    assert (p5, p50, p95) == (round(over["p5"]), round(over["p50"]), round(over["p95"]))
    assert settled == summary["percentiles"]["j2.settling_time_s"]["n"]
    assert share == pytest.approx(100 * summary["share_meeting_all"], abs=0.05)
