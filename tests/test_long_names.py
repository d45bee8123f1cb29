"""Issue 37, cause 3: legal long names. A 250 to 255-byte output name was refused by every writer
("File name too long") because the hidden temporary name beside it (`.<name>.XXXXXXXX.part.xml`)
added 16 to 20 bytes; now such a name gets a short temporary name in the same folder. A name whose
companion cannot exist (a rig log's .json sidecar one byte over 255) is refused before any work.
Real `python -I` processes, each with its own TMPDIR that must stay empty."""

from __future__ import annotations

import os

import pytest
from clitools import ARM_SCENARIO, SIX_FLAGS, run_process


def name(size: int, suffix: str) -> str:
    """A name of exactly `size` bytes ending in `suffix`."""
    return "n" * (size - len(suffix)) + suffix


# command, output name (bytes), the files it writes (name -> the command's output)
CASES = {
    "export fmu 255": (lambda o: ["export", "fmu", "--k", "0.8", "--c", "2e-3", "-o", o], name(255, ".fmu")),
    "export mjcf 255": (
        lambda o: ["export", "mjcf", "--k", "0.8", "--c", "2e-3", "--m", "0.001", "-o", o],
        name(255, ".xml"),
    ),
    "doe 255": (lambda o: ["doe", "-o", o], name(255, ".csv")),
    "plot effects 250": (lambda o: ["plot", "effects", "-o", o], name(250, ".png")),
    "rig simulate + sidecar 254": (
        lambda o: ["rig", "simulate", "--k", "0.8", "--c", "2e-3", "--duration", "1", *SIX_FLAGS, "-o", o],
        name(254, ".csv"),
    ),
    "cosim folder 255": (lambda o: ["cosim", "arm.toml", "-o", o], name(255, "")),
}


@pytest.mark.parametrize("case", list(CASES))
def test_a_legal_long_output_name_is_written(case, tmp_path):
    args, out = CASES[case]
    (tmp_path / "tmp").mkdir()
    (tmp_path / "arm.toml").write_text(ARM_SCENARIO)
    env = dict(os.environ, TMPDIR=str(tmp_path / "tmp"), XDG_CACHE_HOME=str(tmp_path / "cache"))
    r = run_process(args(out), tmp_path, env=env)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / out).exists()
    hidden = [p.name for p in tmp_path.iterdir() if p.name.startswith(".")]
    assert hidden == [] and list((tmp_path / "tmp").iterdir()) == []


def test_a_log_whose_sidecar_name_cannot_exist_is_refused_before_work(tmp_path):
    out = name(255, ".csv")  # the sidecar, .json, would be 256 bytes
    r = run_process(
        ["rig", "simulate", "--k", "0.8", "--c", "2e-3", "--duration", "1", *SIX_FLAGS, "-o", out], tmp_path
    )
    assert r.returncode == 2, r.stderr
    assert "256 bytes" in r.stderr and r.stderr.count("\n") == 1, r.stderr
    assert list(tmp_path.iterdir()) == []
