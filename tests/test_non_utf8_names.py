"""Issue 37, cause 4: names with bytes that are not UTF-8 (`l\\xff.csv`, legal on Linux, common from old
archives). `rig simulate -o l\\xff.csv`, `cosim -o res\\xff` and `export fmu|ssp|modelica --from
sug\\xff.json` ended as exit 3 (UnicodeEncodeError: pyarrow refused the path, the path was written raw
into provenance); `identify` refused a valid log so named. Real `python -I` processes, the names
passed as bytes, each with its own TMPDIR that must stay empty."""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pytest
from clitools import ARM_SCENARIO, SIX_FLAGS, run_process

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def raw(name: bytes) -> str:
    """A file name from bytes, as Python holds a command-line argument (surrogate escapes)."""
    return os.fsdecode(name)


def run(args: list[str], cwd: Path):
    (cwd / "tmp").mkdir(exist_ok=True)
    env = dict(os.environ, TMPDIR=str(cwd / "tmp"), XDG_CACHE_HOME=str(cwd.parent / "cache"))
    r = run_process(args, cwd, env=env, errors="surrogateescape")
    assert r.returncode == 0, r.stderr
    assert list((cwd / "tmp").iterdir()) == []
    assert [p.name for p in cwd.iterdir() if p.name.startswith(".")] == []
    return r


def test_a_rig_log_so_named_is_written_and_identified(tmp_path):
    log = raw(b"log\xff.csv")
    chirp = ["--duration", "20", "--f0", "1", "--f1", "3"]
    run(["rig", "simulate", "--k", "0.8", "--c", "2e-3", *chirp, *SIX_FLAGS, "-o", log], tmp_path)
    assert (tmp_path / log).stat().st_size > 0
    assert json.loads((tmp_path / raw(b"log\xff.json")).read_text())["factors"]["width"] == 4.5
    r = run(["identify", log, "-o", raw(b"table\xff.csv"), "--json"], tmp_path)
    assert json.loads(r.stdout)["failed"] == []
    assert (tmp_path / raw(b"table\xff.csv")).read_text().count("\n") == 2  # header and one run


def test_cosim_writes_into_a_folder_so_named(tmp_path):
    (tmp_path / "arm.toml").write_text(ARM_SCENARIO)
    run(["cosim", "arm.toml", "-o", raw(b"res\xff")], tmp_path)
    assert json.loads((tmp_path / raw(b"res\xff") / "metrics.json").read_text())


@pytest.mark.parametrize("kind, suffix", [("fmu", ".fmu"), ("ssp", ".ssp"), ("modelica", ".mo")])
def test_export_from_a_suggestion_so_named(kind, suffix, tmp_path):
    source = raw(b"sug\xff.json")
    shutil.copy(EXAMPLES / "suggestion.json", tmp_path / source)
    run(["export", kind, "--from", source, "-o", "out" + suffix], tmp_path)
    assert (tmp_path / ("out" + suffix)).stat().st_size > 0
