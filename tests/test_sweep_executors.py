"""A 200-case sweep gives the same table serially, on local processes and on a Dask cluster of processes."""

import json
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest

from designer import DesignerError, cosim, sweep
from designer.sweep.executors import SerialExecutor, executor
from designer.sweep.spec import Cases, Spec, with_duration

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _start(args: list[str], cwd: Path) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-I", "-m", "dask", *args],
        cwd=cwd,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )


@pytest.fixture
def dask_scheduler(tmp_path):
    """`dask scheduler` and two `dask worker` processes, on 127.0.0.1 only; yields the address."""
    pytest.importorskip("distributed")
    info = tmp_path / "scheduler.json"
    procs = [
        _start(
            [
                "scheduler",
                "--host",
                "127.0.0.1",
                "--port",
                "0",
                "--no-dashboard",
                "--scheduler-file",
                str(info),
            ],
            tmp_path,
        )
    ]
    try:
        deadline = time.monotonic() + 60
        while not info.is_file() or not info.read_text().strip():
            assert time.monotonic() < deadline, "the Dask scheduler did not start"
            time.sleep(0.2)
        address = json.loads(info.read_text())["address"]
        for _ in range(2):
            procs.append(
                _start(
                    [
                        "worker",
                        address,
                        "--host",
                        "127.0.0.1",
                        "--nthreads",
                        "1",
                        "--no-nanny",
                        "--no-dashboard",
                    ],
                    tmp_path,
                )
            )
        yield address
    finally:
        for p in reversed(procs):  # workers first, while the scheduler still answers them
            p.terminate()
            try:
                p.wait(timeout=5)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()


def _specs() -> list[Spec]:
    """200 Monte Carlo cases of the example arm on the engine path, 8 through the joint FMUs."""
    sc = with_duration(cosim.load(EXAMPLES / "two_link_arm.toml"), 0.2)
    joints = {"j1": None, "j2": None}
    return [
        Spec(
            scenario=sc, cases=Cases(type="montecarlo", joints=joints, n=200, seed=7), path="engine", check=0
        ),
        Spec(scenario=sc, cases=Cases(type="montecarlo", joints=joints, n=8, seed=8), path="fmu", batch=2),
    ]


def test_same_table_serial_processes_and_dask(dask_scheduler):
    import distributed

    specs = _specs()
    serial = [sweep.run(spec, executor=SerialExecutor()).table for spec in specs]
    assert [len(t) for t in serial] == [200, 8] and all((t["status"] == "ok").all() for t in serial)
    with executor(workers=2) as ex:
        local = [sweep.run(spec, executor=ex).table for spec in specs]
    with distributed.Client(dask_scheduler) as client:
        client.wait_for_workers(2, timeout=60)
        with distributed.get_task_stream(client) as stream, executor(scheduler=dask_scheduler) as ex:
            on_dask = [sweep.run(spec, executor=ex).table for spec in specs]
        assert len({task["worker"] for task in stream.data}) == 2  # both worker processes took cases
    for tables in (local, on_dask):
        for mine, other in zip(serial, tables, strict=True):
            pd.testing.assert_frame_equal(mine.drop(columns="wall_s"), other.drop(columns="wall_s"))


def test_slurm_without_jobqueue_says_what_to_install(monkeypatch):
    pytest.importorskip("distributed")
    monkeypatch.setitem(sys.modules, "dask_jobqueue", None)  # as if not installed: import fails
    with pytest.raises(DesignerError, match="dask-jobqueue"):
        with executor(cluster={"slurm": {"cores": 1, "memory": "1GB"}}):
            pass
