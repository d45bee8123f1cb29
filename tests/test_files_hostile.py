"""Issue 26's file-system classes, as real `python -I` processes of the installed package:

- two processes writing one output at once leave one writer's complete output, never a mix;
- an output path that is a symbolic link onto an existing file: the file it points to is replaced
  whole (a hard link to the old file keeps the old bytes: nothing was truncated in place), the link
  stays;
- a disk that fills up during the write (a small tmpfs mounted here as root; skipped otherwise)
  leaves the previous output intact, one line, exit 2.
"""

from __future__ import annotations

import errno
import json
import os
import shutil
import signal
import subprocess
import tempfile
import time
import zipfile
from pathlib import Path

import pytest
from clitools import CLI, assert_clean_failure, run_process, snapshot, tmpfs
from test_cli_campaign import SIX

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _rig_scenario(folder: Path, k: float, duration: float = 2.0) -> Path:
    text = (EXAMPLES / "rig.toml").read_text()
    text = text.replace("duration = 20.0", f"duration = {duration}").replace(
        "sweep = 20.0", f"sweep = {duration}"
    )
    text = text.replace("k = 330", f"k = {k}")
    path = folder / f"rig_{k:g}.toml"
    path.write_text(text)
    return path


# --- concurrent writers ---------------------------------------------------------------------------


def _simulate(k: str, c: str, seed: str) -> list[str]:
    return ["rig", "simulate", "--k", k, "--c", c, "--duration", "30", "--seed", seed, *SIX, "-o", "{out}"]


#: writers of one output file: two command lines that write different contents to `out`
CONCURRENT = {
    "rig simulate csv": (_simulate("0.8", "2e-3", "1"), _simulate("1.6", "4e-3", "1"), "log.csv"),
    "rig simulate parquet": (_simulate("0.8", "2e-3", "1"), _simulate("0.8", "2e-3", "7"), "log.parquet"),
    "doe": (["doe", "--seed", "1", "-o", "{out}"], ["doe", "--seed", "2", "-o", "{out}"], "plan.csv"),
    "export mjcf": (
        ["export", "mjcf", *SIX, "-o", "{out}"],
        ["export", "mjcf", *SIX[:4], "--width", "6", *SIX[6:], "-o", "{out}"],
        "j.xml",
    ),
    "export modelica": (
        ["export", "modelica", "--k", "0.8", "--c", "2e-3", "-o", "{out}"],
        ["export", "modelica", "--k", "1.6", "--c", "2e-3", "-o", "{out}"],
        "j.mo",
    ),
}


def _start(args: list[str], cwd: Path) -> subprocess.Popen:
    return subprocess.Popen([*CLI, *args], cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _same(name: str, a: bytes, b: bytes) -> bool:
    """Whether two outputs are the same: Parquet by its table (its bytes vary between processes)."""
    if not name.endswith(".parquet"):
        return a == b
    import io

    import pyarrow.parquet as pq

    return pq.read_table(io.BytesIO(a)).equals(pq.read_table(io.BytesIO(b)))


def _files(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.mark.parametrize("name", sorted(CONCURRENT))
def test_two_writers_of_one_file_leave_one_whole_output(name, tmp_path):
    first, second, out = CONCURRENT[name]
    solo = {}
    for i, args in enumerate((first, second)):  # each alone: the two possible outputs
        (tmp_path / f"solo{i}").mkdir()
        r = run_process([a.format(out=out) for a in args], tmp_path / f"solo{i}")
        assert r.returncode == 0, r.stderr
        solo[i] = _files(tmp_path / f"solo{i}")
    assert solo[0] != solo[1]
    both = tmp_path / "both"
    both.mkdir()
    procs = [_start([a.format(out=out) for a in args], both) for args in (first, second)]
    for p in procs:
        _, err = p.communicate(timeout=300)
        assert p.returncode == 0 and "Traceback" not in err, err
    got = _files(both)
    # every file is one writer's whole file (a log's CSV and its JSON sidecar may come from either)
    assert set(got) == set(solo[0]), (set(got), set(solo[0]))
    for f, data in got.items():
        assert _same(f, data, solo[0][f]) or _same(f, data, solo[1][f]), f"{f} is neither writer's file"
    assert not [p for p in both.rglob(".*")], "part files left"


def test_two_cosims_into_one_folder_leave_one_runs_complete_set(tmp_path):
    """A results folder: the last writer's files all, moved in under a lock (never half of each)."""
    a, b = _rig_scenario(tmp_path, 0.83), _rig_scenario(tmp_path, 1.66)
    solo = {}
    for name, sc in (("a", a), ("b", b)):
        r = run_process(["cosim", sc, "-o", f"solo_{name}", "--engine", "python"], tmp_path)
        assert r.returncode == 0, r.stderr
        solo[name] = _files(tmp_path / f"solo_{name}")
    volatile = {"plot.png"}  # drawn the same, but not byte-stable across processes: compared by name only
    procs = [_start(["cosim", sc, "-o", "res", "--engine", "python"], tmp_path) for sc in (a, b)]
    for p in procs:
        _, err = p.communicate(timeout=300)
        assert p.returncode == 0 and "Traceback" not in err, err
    got = _files(tmp_path / "res")
    assert set(got) == set(solo["a"])
    winners = {n for n in solo if all(_same(f, got[f], solo[n][f]) for f in got if f not in volatile)}
    assert len(winners) == 1, "the results folder mixes the two runs' files"
    assert not [p for p in tmp_path.rglob(".*")], "staging folders left"


def test_moving_results_in_waits_for_another_writers_lock_on_the_parent(tmp_path):
    """The protocol the folder writers share: the move-in happens under flock on the parent folder,
    so a second writer cannot interleave its files with the first's (the test holds the lock)."""
    fcntl = pytest.importorskip("fcntl")
    target = tmp_path / "res"
    target.mkdir()
    (target / "a.txt").write_text("old")
    code = (
        "import sys\nfrom designer.files import atomic_folder\n"
        "with atomic_folder(sys.argv[1]) as stage:\n    (stage / 'a.txt').write_text('new')\n"
    )
    fd = os.open(tmp_path, os.O_RDONLY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        proc = subprocess.Popen([*CLI[:2], "-c", code, str(target)], stderr=subprocess.PIPE, text=True)
        deadline = time.monotonic() + 60
        while not [p for p in tmp_path.iterdir() if p.name.startswith(".res.") and (p / "a.txt").exists()]:
            assert proc.poll() is None and time.monotonic() < deadline, proc.communicate()
            time.sleep(0.01)
        time.sleep(0.5)  # staged: it now waits for the lock
        assert proc.poll() is None and (target / "a.txt").read_text() == "old"
    finally:
        os.close(fd)  # releases the lock
    assert proc.wait(timeout=60) == 0, proc.stderr.read()
    assert (target / "a.txt").read_text() == "new"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["res"]


def test_two_cold_builds_of_one_binary_share_one_whole_cache_entry(tmp_path):
    """Two exports compiling the same FMU binary at once into an empty cache: both succeed, and the
    cache holds one entry with its one library (the second finished build is dropped, not mixed in)."""
    if not (shutil.which("cc") or shutil.which("gcc")):
        pytest.skip("no C compiler")
    env = dict(os.environ, XDG_CACHE_HOME=str(tmp_path / "cache"), TMPDIR=str(tmp_path / "tmp"))
    (tmp_path / "tmp").mkdir()
    args = ["export", "fmu", "--k", "0.8", "--c", "2e-3", "--build", "--platforms", "host"]
    procs = [
        subprocess.Popen(
            [*CLI, *args, "-o", f"j{i}.fmu"], cwd=tmp_path, env=env, stderr=subprocess.PIPE, text=True
        )
        for i in (1, 2)
    ]
    for p in procs:
        _, err = p.communicate(timeout=300)
        assert p.returncode == 0 and "Traceback" not in err, err
    for i in (1, 2):
        _complete(tmp_path / f"j{i}.fmu")
    entries = list((tmp_path / "cache" / "flexjoint-designer" / "fmu").iterdir())
    assert len(entries) == 1 and not entries[0].name.startswith("."), entries
    assert len(list(entries[0].iterdir())) == 1  # the library, nothing else
    assert not list((tmp_path / "tmp").iterdir())


# --- outputs through symbolic links ----------------------------------------------------------------

SYMLINKED = {
    "export fmu": (["export", "fmu", "--k", "0.8", "--c", "2e-3"], ".fmu"),
    "export mjcf": (["export", "mjcf", *SIX], ".xml"),
    "export urdf": (["export", "urdf", *SIX], ".urdf"),
    "export modelica": (["export", "modelica", "--k", "0.8", "--c", "2e-3"], ".mo"),
    "rig simulate": (["rig", "simulate", "--k", "0.8", "--c", "2e-3", "--duration", "5", *SIX], ".csv"),
    "doe": (["doe"], ".csv"),
    "fit": (["fit"], ".json"),
    "plot effects": (["plot", "effects"], ".png"),
}


def _complete(path: Path) -> None:
    if path.suffix == ".fmu":
        with zipfile.ZipFile(path) as z:
            assert z.testzip() is None and "modelDescription.xml" in z.namelist()
    elif path.suffix == ".json":
        json.loads(path.read_text())
    elif path.suffix == ".png":
        assert path.read_bytes().startswith(b"\x89PNG")
    else:
        assert path.stat().st_size > 100 and path.read_bytes().endswith(b"\n")


@pytest.mark.parametrize("name", sorted(SYMLINKED))
def test_output_through_a_symlink_replaces_the_target_whole(name, tmp_path):
    args, suffix = SYMLINKED[name]
    real = tmp_path / "real"
    real.mkdir()
    target = real / f"target{suffix}"
    target.write_bytes(b"OLD CONTENTS\n")
    os.link(target, tmp_path / "keep")  # a second name of the old file: truncating it in place shows here
    link = tmp_path / f"out{suffix}"
    link.symlink_to(target)
    r = run_process([*args, "-o", link.name], tmp_path)
    assert r.returncode == 0, r.stderr
    assert link.is_symlink() and os.readlink(link) == str(target), "the link itself was replaced"
    assert (tmp_path / "keep").read_bytes() == b"OLD CONTENTS\n", "the old file was rewritten in place"
    assert target.read_bytes() != b"OLD CONTENTS\n"
    _complete(target)
    assert not [p for p in tmp_path.rglob(".*")], "part files left"


def test_a_results_folder_through_a_symlink_is_filled_in_place_of_its_target(tmp_path):
    real = tmp_path / "real_results"
    real.mkdir()
    (real / "notes.txt").write_text("the user's")
    (tmp_path / "res").symlink_to(real, target_is_directory=True)
    r = run_process(["cosim", _rig_scenario(tmp_path, 0.83), "-o", "res", "--engine", "python"], tmp_path)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "res").is_symlink()
    assert (real / "notes.txt").read_text() == "the user's" and (real / "metrics.json").is_file()
    assert not [p for p in tmp_path.rglob(".*")], "staging folders left"


BAD_LINKS = {
    "dangling into a missing folder": lambda d: (d / "out.fmu").symlink_to(d / "no" / "such" / "x.fmu"),
    "onto a folder": lambda d: (d / "out.fmu").symlink_to(d, target_is_directory=True),
    "onto /proc": lambda d: (d / "out.fmu").symlink_to("/proc/x.fmu"),
}


@pytest.mark.parametrize("name", sorted(BAD_LINKS))
def test_an_unwritable_symlink_target_is_one_line(name, tmp_path):
    BAD_LINKS[name](tmp_path)
    before = snapshot(tmp_path)
    r = run_process(["export", "fmu", "--k", "0.8", "--c", "2e-3", "-o", "out.fmu"], tmp_path)
    assert_clean_failure(r.returncode, r.stderr, (2,))
    assert snapshot(tmp_path) == before


# --- a disk filling up mid-write --------------------------------------------------------------------


@pytest.fixture()
def small_disk(tmp_path):
    """A 24 MiB tmpfs mounted for the test (root only; skipped with the reason otherwise)."""
    with tmpfs(tmp_path / "disk", "24m") as mnt:
        yield mnt


def _fill(folder: Path, leave: int) -> None:
    """Fill the disk of `folder` until `leave` bytes are free."""
    free = shutil.disk_usage(folder).free - leave
    # unbuffered: a write the full disk refuses leaves nothing for close() to flush again (a buffered
    # file raised ENOSPC a second time from close when a writer beside us had taken the rest first)
    with open(folder / "filler", "wb", buffering=0) as fh:
        try:
            while free > 0:
                free -= fh.write(bytes(min(free, 1 << 20)))
        except OSError as exc:  # a writer beside us took the rest: full all the same
            assert exc.errno == errno.ENOSPC


def test_disk_full_during_a_results_folder_keeps_the_previous_results(small_disk, tmp_path):
    sc = _rig_scenario(tmp_path, 0.83, duration=4.0)  # about 1 MB of results, no size estimate up front
    r = run_process(["cosim", sc, "-o", "res", "--engine", "python"], small_disk)
    assert r.returncode == 0, r.stderr
    before = snapshot(small_disk / "res")
    _fill(small_disk, leave=256 << 10)
    r = run_process(
        ["cosim", _rig_scenario(tmp_path, 1.66, duration=4.0), "-o", "res", "--engine", "python"], small_disk
    )
    assert_clean_failure(r.returncode, r.stderr, (2,))
    assert "disk" in r.stderr, r.stderr
    assert snapshot(small_disk / "res") == before, "the previous results changed"
    assert sorted(p.name for p in small_disk.iterdir()) == ["filler", "res"]


def test_disk_filling_up_while_a_log_is_written_keeps_the_previous_log(small_disk):
    """Another program fills the disk after the size check, while the CSV is being written."""
    args = ["rig", "simulate", "--k", "0.8", "--c", "2e-3", "--duration", "120", *SIX, "-o", "log.csv"]
    previous = b"t,x,Fx\n0,0,0\n"
    (small_disk / "log.csv").write_bytes(previous)
    proc = _start(args, small_disk)
    deadline = time.monotonic() + 120
    while not [p for p in small_disk.iterdir() if p.name.startswith(".log.csv.")]:
        assert proc.poll() is None, proc.communicate()[1]
        assert time.monotonic() < deadline
        time.sleep(0.002)
    _fill(small_disk, leave=0)  # the part file has appeared: the disk fills up under it
    _, err = proc.communicate(timeout=120)
    assert_clean_failure(proc.returncode, err, (2,))
    assert "disk" in err, err
    assert (small_disk / "log.csv").read_bytes() == previous
    assert sorted(p.name for p in small_disk.iterdir()) == ["filler", "log.csv"]


def test_disk_full_before_the_work_is_refused_up_front(small_disk):
    _fill(small_disk, leave=2 << 20)
    args = ["rig", "simulate", "--k", "0.8", "--c", "2e-3", "--duration", "120", *SIX, "-o", "log.csv"]
    r = run_process(args, small_disk)
    assert_clean_failure(r.returncode, r.stderr, (2,))
    assert "not enough space for log.csv" in r.stderr
    assert sorted(p.name for p in small_disk.iterdir()) == ["filler"]


CASE_COUNT = len(CONCURRENT) + 3 + len(SYMLINKED) + 1 + len(BAD_LINKS) + 3


def test_a_stop_while_a_temporary_folder_is_removed_leaves_nothing(tmp_path, monkeypatch):
    """SIGTERM in the middle of removing a temporary folder (CI saw a cosim session's folder left in
    TMPDIR by validate): the stop is held back until the folder is gone, then delivered."""
    from designer import files

    def stop(*_):
        raise KeyboardInterrupt

    real = shutil.rmtree

    def rmtree_interrupted(path, **kwargs):
        os.kill(os.getpid(), signal.SIGTERM)  # lands inside the removal
        real(path, **kwargs)

    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    monkeypatch.setattr(shutil, "rmtree", rmtree_interrupted)
    old = signal.signal(signal.SIGTERM, stop)
    try:
        with pytest.raises(KeyboardInterrupt), files.temporary_folder("designer-test-") as folder:
            (folder / "unpacked.bin").write_bytes(b"x")
    finally:
        signal.signal(signal.SIGTERM, old)
    assert not list(tmp_path.iterdir())
