"""Sweep workers run their cases through one prepared Session and leave nothing in the temporary
folder, in this process and in local worker processes, also after a failing case."""

import tempfile
from pathlib import Path

import numpy as np
import pytest

from designer import cosim, sweep
from designer.sweep import evaluate
from designer.sweep.executors import SerialExecutor
from designer.sweep.spec import Cases, Spec, with_duration

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "two_link_arm.toml"
#: N.mm/rad: 1e7 makes the arm's explicit Euler step diverge at 1 ms, the others run
KS = [250.0, 330.0, 1e7, 400.0]


@pytest.fixture
def scratch(tmp_path, monkeypatch):
    """An empty temporary folder for this process and the processes it starts."""
    folder = tmp_path / "tmp"
    folder.mkdir()
    monkeypatch.setenv("TMPDIR", str(folder))
    monkeypatch.setattr(tempfile, "tempdir", None)
    return folder


def spec(**kwargs) -> Spec:
    sc = with_duration(cosim.load(EXAMPLE), 0.2)
    return Spec(
        scenario=sc, cases=Cases(type="grid", joints={"j1": {"k": KS}}), path="fmu", check=0, **kwargs
    )


def test_one_session_per_worker_until_a_case_fails(scratch, monkeypatch):
    """Serially, batches of one case: one prepare for the sweep, one more after the diverging case."""
    real, prepared = cosim.prepare, []

    def counting(sc):
        prepared.append(sc)
        return real(sc)

    monkeypatch.setattr(cosim, "prepare", counting)
    result = sweep.run(spec(batch=1), executor=SerialExecutor())
    assert list(result.table["status"]) == ["ok", "ok", "failed", "ok"]
    assert "diverged" in result.table["message"][2]
    assert len(prepared) == 2
    assert list(scratch.iterdir()) == [] and not evaluate._HELD


@pytest.mark.parametrize("start", ["spawn", "fork"])
def test_local_worker_processes_leave_nothing_behind(scratch, start):
    """Worker processes hold a Session between batches and close it when they end: spawned ones
    (the default executor's) and forked ones (a user's ProcessPoolExecutor), which skip atexit."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    serial = sweep.run(spec(), executor=SerialExecutor()).table
    if start == "spawn":
        processes = sweep.run(spec(workers=2, batch=1)).table  # the default executor, a batch per case
    else:
        with ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("fork")) as pool:
            processes = sweep.run(spec(workers=2, batch=1), executor=pool).table
    assert list(processes["status"]) == ["ok", "ok", "failed", "ok"]
    assert list(scratch.iterdir()) == []  # the workers closed their sessions when they exited
    numbers = [c for c in serial.columns if c.startswith("j") and serial[c].dtype.kind == "f"]
    np.testing.assert_array_equal(serial[numbers].to_numpy(), processes[numbers].to_numpy())


def test_a_held_session_is_for_its_exact_scenario(scratch):
    """Scenarios differing in one sample of a long motor trajectory (numpy elides it in a plain
    repr) get their own Session."""
    from dataclasses import replace

    t = np.linspace(0.0, 0.2, 2001)
    q = 0.1 * np.sin(5 * t)
    sc = with_duration(cosim.load(EXAMPLE), 0.2)
    first = replace(sc, motors=sc.motors | {"j1": cosim.Trajectory(t, q)}).check()
    q2 = q.copy()
    q2[1000] += 1e-3
    second = replace(first, motors=first.motors | {"j1": cosim.Trajectory(t, q2)}).check()
    try:
        one = evaluate.held(first)
        assert evaluate.held(first) is one
        two = evaluate.held(second)
        assert two is not one and one.closed and not two.closed
    finally:
        evaluate.release()
    assert list(scratch.iterdir()) == []
