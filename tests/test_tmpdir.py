"""Issue 37, cause 7 (the TMPDIR part), as real `python -I` processes: with TMPDIR pointing to a folder
that does not exist, `validate` died by SIGSEGV inside libcosimpy and left its staging folder; with
TMPDIR on a full disk, the message said "the disk is full" without naming TMPDIR (the outputs' disk
had room). Now TMPDIR is checked before any work, and a full temporary folder is named as such."""

from __future__ import annotations

import os

from clitools import ARM_SCENARIO, run_process, tmpfs


def test_a_missing_tmpdir_is_refused_before_any_work(tmp_path):
    env = dict(os.environ, TMPDIR=str(tmp_path / "no" / "such"), XDG_CACHE_HOME=str(tmp_path / "cache"))
    (tmp_path / "cwd").mkdir()
    r = run_process(["validate", "-o", "rep"], tmp_path / "cwd", env=env)
    assert r.returncode == 2, (r.returncode, r.stderr[-500:])
    fix = "create it, or point TMPDIR to a writable folder"
    assert r.stderr == f"error: TMPDIR={tmp_path / 'no' / 'such'} does not exist ({fix})\n"
    assert list((tmp_path / "cwd").iterdir()) == []


def test_a_full_tmpdir_is_named(tmp_path):
    (tmp_path / "cwd").mkdir()
    (tmp_path / "cwd" / "arm.toml").write_text(ARM_SCENARIO)
    with tmpfs(tmp_path / "tmp", "64k") as tmp:
        (tmp / "filler").write_bytes(b"\0" * 60_000)  # what is left cannot hold an unpacked FMU
        env = dict(os.environ, TMPDIR=str(tmp), XDG_CACHE_HOME=str(tmp_path / "cache"))
        r = run_process(["cosim", "arm.toml", "-o", "res"], tmp_path / "cwd", env=env)
        assert r.returncode == 2, (r.returncode, r.stderr[-500:])
        assert "temporary folder is full" in r.stderr and "TMPDIR" in r.stderr, r.stderr
        assert sorted(p.name for p in tmp.iterdir()) == ["filler"]
    assert sorted(p.name for p in (tmp_path / "cwd").iterdir()) == ["arm.toml"]
