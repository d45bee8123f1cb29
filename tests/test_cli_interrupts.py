"""Issue 26's signal class, as real `python -I` processes: SIGTERM at a random moment of sweep, tune,
validate, a cold-cache export (the FMU binary compiled) and cosim (its kernel compiled: the cache is
cold too). Whatever the moment:

- the exit code is the command's own (0, or 1 for a negative answer) or 143 with the one line
  "stopped by SIGTERM; partial files removed", never a traceback; a signal death (-15, which a
  shell reports as 143 too) only before the command has started (nothing written);
- stopped: nothing is left in the working folder (a sweep keeps its journal of finished cases, whole
  lines, for a rerun to resume, and says so), in the temporary folder (the compiler's files
  included) or in the build cache (an entry is whole or absent);
- finished: every output is complete (also when the stop came while the outputs were written).
"""

from __future__ import annotations

import json
import os
import random
import shutil
import signal
import subprocess
import sys
import time
import zipfile
from pathlib import Path

import pandas as pd
import pytest
from clitools import CLI

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
STOPPED = "stopped by SIGTERM; partial files removed"

#: command line, the window of the random moment (s after start), the outputs of a finished run
COMMANDS = {
    "cosim": (["cosim", str(EXAMPLES / "rig.toml"), "-o", "res"], (0.3, 6.0), {"res"}),
    "sweep": (["sweep", str(EXAMPLES / "sweep_arm.toml"), "-o", "sw", "--workers", "1"], (0.3, 6.5), {"sw"}),
    # worker processes, each holding a prepared co-simulation (unpacked FMUs) between batches
    "sweep-workers": (
        ["sweep", str(EXAMPLES / "sweep_arm.toml"), "-o", "sw", "--workers", "2", "--path", "fmu"],
        (1.0, 4.0),
        {"sw"},
    ),
    "tune": (
        ["tune", str(EXAMPLES / "tune_one_link.toml"), "--robustness", "4", "--workers", "1", "-o", "t.json"],
        (0.3, 5.0),
        {"t.json"},
    ),
    "validate": (["validate", "-o", "rep"], (0.5, 14.0), {"rep"}),
    "export": (
        ["export", "fmu", "--k", "0.8", "--c", "2e-3", "--build", "--platforms", "host", "-o", "j.fmu"],
        (0.2, 1.5),
        {"j.fmu"},
    ),
}
SEEDS = {"cosim": 3, "sweep": 3, "sweep-workers": 2, "tune": 3, "validate": 2, "export": 4}
RUNS = [(name, seed) for name, n in SEEDS.items() for seed in range(n)]
# + the compiler running, a sweep resumed, a finaliser, a converted stop, a stop while writing
CASE_COUNT = len(RUNS) + 5


def _env(tmp_path: Path) -> dict[str, str]:
    for d in ("cwd", "tmp", "cache"):
        (tmp_path / d).mkdir()
    return dict(os.environ, TMPDIR=str(tmp_path / "tmp"), XDG_CACHE_HOME=str(tmp_path / "cache"))


def _start(args: list[str], cwd: Path, env: dict) -> subprocess.Popen:
    pipe = subprocess.PIPE
    return subprocess.Popen([*CLI, *args], cwd=cwd, env=env, stdout=pipe, stderr=pipe, text=True)


def _stop_at(args: list[str], cwd: Path, env: dict, after: float) -> subprocess.CompletedProcess:
    proc = _start(args, cwd, env)
    time.sleep(after)
    if proc.poll() is None:
        proc.send_signal(signal.SIGTERM)
    out, err = proc.communicate(timeout=300)
    return subprocess.CompletedProcess(args, proc.returncode, out, err)


def _check_cache(cache: Path) -> None:
    """Every build-cache entry (a folder named for its key) holds its whole library, nothing else."""
    root = cache / "flexjoint-designer"
    for kind in ("fmu", "kernel"):
        for entry in (root / kind).iterdir() if (root / kind).is_dir() else []:
            assert not entry.name.startswith("."), f"staging folder left in the cache: {entry}"
            files = list(entry.iterdir())
            assert len(files) == 1 and files[0].stat().st_size > 1000, f"incomplete cache entry {entry}"
            assert files[0].read_bytes()[:4] in (b"\x7fELF", b"\xcf\xfa\xed\xfe", b"MZ\x90\x00")


def _check_finished(name: str, cwd: Path) -> None:
    if name == "cosim":
        names = {p.name for p in (cwd / "res").iterdir()}
        assert {"timeseries.csv", "metrics.json", "rig_log.csv", "rig_log.json"} <= names, names
        assert len(pd.read_csv(cwd / "res" / "timeseries.csv")) == 20001
        json.loads((cwd / "res" / "metrics.json").read_text())
    elif name.startswith("sweep"):
        assert {p.name for p in (cwd / "sw").iterdir()} >= {"results.parquet", "summary.json", "cases.jsonl"}
        assert len(pd.read_parquet(cwd / "sw" / "results.parquet")) == 200
    elif name == "tune":
        assert "designs" in json.loads((cwd / "t.json").read_text()) or json.loads(
            (cwd / "t.json").read_text()
        )
    elif name == "validate":
        assert (cwd / "rep" / "report.html").read_text().rstrip().endswith("</html>")
    elif name == "export":
        with zipfile.ZipFile(cwd / "j.fmu") as z:
            assert z.testzip() is None


def _journal_lines(journal: Path) -> int:
    lines = journal.read_text().splitlines()
    for line in lines:
        json.loads(line)
    return len(lines)


@pytest.mark.parametrize(("name", "seed"), RUNS, ids=[f"{n}-{s}" for n, s in RUNS])
def test_sigterm_at_a_random_moment_leaves_nothing(name, seed, tmp_path):
    if name == "export" and not (os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")):
        pytest.skip("no C compiler: a cold-cache export has nothing to compile")
    args, (lo, hi), outputs = COMMANDS[name]
    env = _env(tmp_path)
    cwd = tmp_path / "cwd"
    after = random.Random(f"{name}{seed}").uniform(lo, hi)
    r = _stop_at(args, cwd, env, after)
    assert "Traceback" not in r.stderr and "Exception ignored" not in r.stderr, r.stderr
    # -15: the signal came before the command had set its handlers (Python still importing it):
    # killed as any program is (a shell reports 143 all the same), before anything was written
    assert r.returncode in (0, 1, 143, -signal.SIGTERM), (after, r.returncode, r.stderr)
    if r.returncode == -signal.SIGTERM:
        assert r.stderr == "" and not list(cwd.iterdir()), r.stderr
    assert not list((tmp_path / "tmp").iterdir()), "temporary files left"
    _check_cache(tmp_path / "cache")
    assert not [p for p in cwd.rglob(".*")], "part files left"
    if r.returncode in (143, -signal.SIGTERM):
        assert r.returncode < 0 or r.stderr.splitlines()[-1] == STOPPED, r.stderr
        left = {str(p.relative_to(cwd)) for p in cwd.rglob("*")}
        if name.startswith("sweep") and left:
            assert left == {"sw", "sw/cases.jsonl"}, left
            n = _journal_lines(cwd / "sw" / "cases.jsonl")
            assert f"{n} finished cases kept in sw/cases.jsonl" in r.stderr, r.stderr
        else:
            assert not left, f"left behind after SIGTERM at {after:.2f} s: {left}"
    else:
        assert {p.name for p in cwd.iterdir()} == outputs
        _check_finished(name, cwd)


def _children(pid: int) -> list[str]:
    try:
        return Path(f"/proc/{pid}/task/{pid}/children").read_text().split()
    except OSError:
        return []


def test_sigterm_while_the_compiler_runs_leaves_no_compiler_files(tmp_path):
    """The moment a random one rarely hits: the C compiler of a cold-cache export is running (gcc's
    cc*.s and cc*.o in the temporary folder, the cache entry half made)."""
    if not Path("/proc/self/task").is_dir() or not (shutil.which("cc") or shutil.which("gcc")):
        pytest.skip("needs Linux's /proc and a C compiler")
    env = _env(tmp_path)
    args = COMMANDS["export"][0]
    proc = _start(args, tmp_path / "cwd", env)
    deadline = time.monotonic() + 120
    while not _children(proc.pid):
        assert proc.poll() is None and time.monotonic() < deadline, proc.communicate()
        time.sleep(0.001)
    time.sleep(0.05)  # the compiler has started writing its files
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 143 and err.splitlines()[-1] == STOPPED, err
    assert not list((tmp_path / "tmp").iterdir()), "the compiler's temporary files were left"
    assert not list((tmp_path / "cwd").iterdir())
    _check_cache(tmp_path / "cache")


def test_a_stopped_sweep_resumes_from_its_journal(tmp_path):
    env = _env(tmp_path)
    cwd = tmp_path / "cwd"
    args = ["sweep", str(EXAMPLES / "sweep_arm.toml"), "-o", "sw", "--workers", "1", "--json"]
    journal = cwd / "sw" / "cases.jsonl"
    proc = _start(args, cwd, env)
    deadline = time.monotonic() + 120
    while not (journal.is_file() and journal.read_bytes().count(b"\n") >= 20):
        assert proc.poll() is None and time.monotonic() < deadline, proc.communicate()
        time.sleep(0.005)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=120)
    if proc.returncode == 0:
        pytest.skip("the sweep finished before the signal (a machine much faster than this test assumes)")
    assert proc.returncode == 143, err
    kept = _journal_lines(journal)
    r = subprocess.run([*CLI, *args], cwd=cwd, env=env, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    summary = json.loads(r.stdout)
    assert summary["resumed"] == kept and summary["cases"] == 200


def test_a_signal_landing_in_a_finaliser_still_stops_the_command():
    """A handler's exception raised while Python runs a __del__ or weakref callback is swallowed
    ("Exception ignored in ..."): validate went on to exit 0 after SIGTERM. It is delivered again."""
    code = """
import signal, sys, time
from designer_cli import main as m
m.install_signal_handlers()  # as main() does

class Finaliser:
    def __del__(self):
        m._stop(signal.SIGTERM, None)  # as if SIGTERM arrived while this finaliser ran

try:
    Finaliser()
    time.sleep(20)  # the work that follows
    sys.exit(0)
except m.Stopped as exc:
    sys.exit(128 + exc.signum)
"""
    start = time.monotonic()
    r = subprocess.run([sys.executable, "-I", "-c", code], capture_output=True, text=True, timeout=60)
    assert r.returncode == 143, r.stderr
    assert r.stderr == "" and time.monotonic() - start < 15


def test_a_stop_turned_into_another_exception_is_still_a_stop(tmp_path, monkeypatch, capsys):
    """SIGTERM landing in a C extension's import surfaced as "ImportError: initialization failed",
    reported as an internal error (exit 3, "a bug in designer"); it is the stop (143)."""
    from clitools import run_inprocess
    from designer_cli import main as m

    import designer.rig.clean as cleaning
    from designer.study.data import load_table

    monkeypatch.chdir(tmp_path)
    load_table().to_csv("t.csv", index=False)
    saved = {s: signal.getsignal(s) for s in m._signals()}

    def interrupted(*args, **kwargs):
        try:
            m._stop(signal.SIGTERM, None)  # the handler raises Stopped in the import...
        except m.Stopped:
            raise ImportError("initialization failed") from None  # ...which the import replaces

    monkeypatch.setattr(m, "RECEIVED", [])
    monkeypatch.setattr(cleaning, "clean", interrupted)
    try:
        code, out, err = run_inprocess(["clean", "t.csv"], capsys)
    finally:
        for s, handler in saved.items():
            signal.signal(s, handler)
    assert code == 143 and err.strip() == STOPPED, err


def test_a_stop_while_the_outputs_are_moved_in_lets_the_command_finish(tmp_path):
    """SIGTERM held back while a sweep's results were moved into its folder was delivered the moment
    the move ended: the command said "partial files removed" (143) of complete results (CI, seed 0 of
    sweep-workers). Once a command writes its outputs a stop lets it finish: exit 0, and it says so."""
    code = f"""
import os, signal, sys
import designer.files as files
from designer_cli import main as m

move_in = files._move_in

def interrupted(stage, target):
    os.kill(os.getpid(), signal.SIGTERM)  # arrives during the move, held back until its end
    move_in(stage, target)

files._move_in = interrupted
m.install_signal_handlers()
sys.exit(m.run(["sweep", {str(EXAMPLES / "sweep_arm.toml")!r}, "-o", "sw", "--workers", "1", "--json"]))
"""
    env = _env(tmp_path)
    cwd = tmp_path / "cwd"
    r = subprocess.run([*CLI[:-2], "-c", code], cwd=cwd, env=env, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert r.stderr.strip() == "SIGTERM came while the outputs were written: they are complete", r.stderr
    _check_finished("sweep", cwd)
    assert json.loads(r.stdout)["cases"] == 200
