"""A sweep on a real SLURM cluster through dask-jobqueue gives the local table.

The fixture starts a one-node SLURM on this machine (Debian's slurm-wlm and munge: munged,
slurmctld and slurmd, on 127.0.0.1 and free ports, every file in a temporary folder) and stops it
after; the sweep's `[cluster] slurm` table reaches `dask_jobqueue.SLURMCluster`, whose workers run
as SLURM batch jobs. Skips with the reason where the packages are missing or the daemons cannot
start (.ci/run installs them with apt where it can).
"""

from __future__ import annotations

import os
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest

from designer import cosim, sweep
from designer.sweep.executors import SerialExecutor, executor
from designer.sweep.spec import Cases, Spec, with_duration

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
DAEMONS = ("munged", "slurmctld", "slurmd", "sbatch", "sinfo", "scancel")


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _conf(d: Path) -> str:
    cpus = os.cpu_count() or 1
    return f"""ClusterName=designer
SlurmctldHost=localhost(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket={d}/munge.sock
CredType=cred/munge
StateSaveLocation={d}/state
SlurmdSpoolDir={d}/spool
SlurmctldPidFile={d}/slurmctld.pid
SlurmdPidFile={d}/slurmd.pid
SlurmctldPort={_free_port()}
SlurmdPort={_free_port()}
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
MpiDefault=none
ReturnToService=2
SlurmctldLogFile={d}/slurmctld.log
SlurmdLogFile={d}/slurmd.log
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
NodeName=localhost NodeAddr=127.0.0.1 CPUs={cpus} RealMemory=2000 State=UNKNOWN
PartitionName=debug Nodes=localhost Default=YES MaxTime=INFINITE State=UP
"""


def _stop(pid_file: Path) -> None:
    try:
        pid = int(pid_file.read_text().split()[0])
    except (OSError, ValueError, IndexError):
        return
    try:
        os.kill(pid, signal.SIGTERM)
    except ProcessLookupError:
        return
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline:
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return
        time.sleep(0.1)
    os.kill(pid, signal.SIGKILL)


def _log_tail(d: Path) -> str:
    logs = [d / n for n in ("munged.log", "slurmctld.log", "slurmd.log")]
    return " | ".join(p.read_text().strip().splitlines()[-1] for p in logs if p.exists() and p.read_text())


@pytest.fixture(scope="module")
def slurm(tmp_path_factory):
    """A running one-node SLURM; yields the environment its clients need (SLURM_CONF)."""
    missing = [name for name in DAEMONS if shutil.which(name) is None]
    if missing:
        pytest.skip(f"SLURM is not installed ({', '.join(missing)} missing): apt-get install slurm-wlm munge")
    pytest.importorskip("dask_jobqueue", reason="dask-jobqueue is not installed (the cluster extra has it)")
    if os.geteuid() != 0:
        pytest.skip("the test's SLURM runs its daemons as root")
    d = Path(tmp_path_factory.mktemp("slurm"))
    for sub in ("state", "spool", "jobs"):
        (d / sub).mkdir()
    key = d / "munge.key"
    key.write_bytes(os.urandom(1024))
    key.chmod(0o400)
    conf = d / "slurm.conf"
    conf.write_text(_conf(d))
    env = {**os.environ, "SLURM_CONF": str(conf)}
    munge = [
        "munged", "--force", f"--socket={d}/munge.sock", f"--key-file={key}",
        f"--pid-file={d}/munged.pid", f"--log-file={d}/munged.log", f"--seed-file={d}/munge.seed",
    ]  # fmt: skip
    try:
        subprocess.run(munge, check=True, capture_output=True, env=env, timeout=30)
        for command in (["slurmctld", "-f", str(conf)], ["slurmd", "-f", str(conf), "-N", "localhost"]):
            subprocess.run(command, check=True, capture_output=True, env=env, timeout=30)
        deadline = time.monotonic() + 60
        while True:
            state = subprocess.run(
                ["sinfo", "-h", "-o", "%T"], capture_output=True, text=True, env=env, timeout=30
            ).stdout.strip()
            if state == "idle":
                break
            if time.monotonic() > deadline:
                raise RuntimeError(f"the node stays '{state}'")
            time.sleep(0.5)
    except (subprocess.SubprocessError, RuntimeError, OSError) as exc:
        for name in ("slurmd", "slurmctld", "munged"):
            _stop(d / f"{name}.pid")
        pytest.skip(f"the SLURM daemons do not start here ({exc}; {_log_tail(d)})")
    old = os.environ.get("SLURM_CONF")
    os.environ["SLURM_CONF"] = str(conf)  # dask-jobqueue runs sbatch, squeue and scancel from here
    yield d
    subprocess.run(["scancel", "--user=root"], capture_output=True, env=env, timeout=30)
    for name in ("slurmd", "slurmctld", "munged"):
        _stop(d / f"{name}.pid")
    if old is None:
        os.environ.pop("SLURM_CONF", None)
    else:
        os.environ["SLURM_CONF"] = old


def test_a_twenty_case_sweep_on_slurm_equals_the_local_one(slurm):
    sc = with_duration(cosim.load(EXAMPLES / "two_link_arm.toml"), 0.2)
    cases = Cases(type="montecarlo", joints={"j1": None, "j2": None}, n=20, seed=11)
    spec = Spec(scenario=sc, cases=cases, path="fmu", batch=5)
    local = sweep.run(spec, executor=SerialExecutor()).table
    jobs = slurm / "jobs"
    settings = {
        "jobs": 2,
        "cores": 1,
        "processes": 1,
        "memory": "900MB",
        "walltime": "00:10:00",
        "interface": "lo",  # scheduler and workers on 127.0.0.1 only
        "log_directory": str(jobs),
        "local_directory": str(jobs),
        "python": sys.executable,
    }
    with executor(cluster={"slurm": settings}) as ex:
        on_slurm = sweep.run(spec, executor=ex).table
    assert len(local) == 20 and (local["status"] == "ok").all()
    pd.testing.assert_frame_equal(local.drop(columns="wall_s"), on_slurm.drop(columns="wall_s"))
    # the cases ran in dask workers that SLURM started as batch jobs
    logs = [p.read_text() for p in jobs.glob("*.err")] + [p.read_text() for p in jobs.glob("*.out")]
    assert any("Start worker" in text or "Starting Worker" in text for text in logs), logs
