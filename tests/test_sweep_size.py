"""Issue 37, cause 8: sweeps of 1e9-1e10 cases were built in memory (+100 MB/s) with no estimate up
front, though README promises a run too large is refused with its estimate before anything is
allocated. Now the cases are counted first: beyond `max_cases` (or the memory) one line with the
count, its memory and how to go on, before any case or output folder exists."""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path

import pytest

from designer import DesignerError, sweep
from designer.sweep.cases import case_count

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _grid(tmp_path: Path, n: int) -> Path:
    """Two joints x (k, c): n^4 cases."""
    path = tmp_path / "huge.toml"
    axes = "\n".join(
        f"[cases.joints.{j}]\nk = {{from = 100, to = 400, n = {n}}}\nc = {{from = 1, to = 4, n = {n}}}"
        for j in ("j1", "j2")
    )
    path.write_text(f'scenario = "{EXAMPLES / "two_link_arm.toml"}"\n[cases]\ntype = "grid"\n{axes}\n')
    return path


def test_counting_agrees_with_the_cases_built(tmp_path):
    for spec in (sweep.load(_grid(tmp_path, 3)), sweep.load(EXAMPLES / "sweep_arm.toml")):
        assert case_count(spec) == len(sweep.make_cases(spec))


def test_a_billion_cases_are_refused_before_any_is_built(tmp_path):
    spec = sweep.load(_grid(tmp_path, 200))  # 1.6e9 cases
    start = time.perf_counter()
    with pytest.raises(DesignerError, match=r"makes 1\.6e\+09 cases \(about 6 TiB of memory") as err:
        sweep.make_cases(spec)
    assert "max_cases=1600000000" in str(err.value)
    assert time.perf_counter() - start < 5  # counted, not built (building took minutes and GBs)
    with pytest.raises(DesignerError, match="of memory"):  # allowed by the count, not by the machine
        sweep.check_size(spec, max_cases=2_000_000_000)


def test_the_cli_names_its_flag_and_writes_nothing(tmp_path):
    out = tmp_path / "res"
    code = "import sys; from designer_cli.main import main; sys.argv[0] = 'designer'; main()"
    run = subprocess.run(
        [sys.executable, "-I", "-c", code, "sweep", str(_grid(tmp_path, 200)), "-o", str(out)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 2, run.stderr
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1 and "--max-cases 1600000000" in lines[0] and "max_cases=" not in lines[0]
    assert not out.exists()
