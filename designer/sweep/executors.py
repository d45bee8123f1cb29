"""Executors a sweep runs on, all `concurrent.futures` executors: serial, local processes, Dask.

Dask (`dask.distributed`, and `dask-jobqueue` for SLURM) is the optional `cluster` extra and is
imported only here, only when a cluster is asked for.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
from collections.abc import Iterator, Mapping
from concurrent.futures import Executor, Future, ProcessPoolExecutor
from typing import Any

from ..errors import DesignerError


class SerialExecutor(Executor):
    """Runs each task at submission, in this process: for tests, debugging and one-core machines."""

    def submit(self, fn, /, *args, **kwargs) -> Future:
        future: Future = Future()
        try:
            future.set_result(fn(*args, **kwargs))
        except BaseException as exc:  # handed to the caller through the future, as other executors do
            future.set_exception(exc)
        return future


def local_workers(workers: int | None) -> int:
    """Worker processes for the local executor: as asked, else one per available core."""
    if workers is not None:
        return workers
    try:
        return max(len(os.sched_getaffinity(0)), 1)
    except AttributeError:  # not on Linux
        return max(os.cpu_count() or 1, 1)


def _dask() -> Any:
    try:
        import distributed
    except ImportError:
        raise DesignerError(
            "running on a Dask cluster needs dask.distributed",
            'install the extra: pip install "flexjoint-designer[cluster]"',
        ) from None
    return distributed


def _cluster(cluster: Mapping[str, Any]) -> Any:
    """A Dask cluster object for a [cluster] table with `workers` (local) or `slurm` (dask-jobqueue)."""
    distributed = _dask()
    if "workers" in cluster:
        return distributed.LocalCluster(
            n_workers=int(cluster["workers"]), threads_per_worker=1, processes=True, dashboard_address=None
        )
    try:
        from dask_jobqueue import SLURMCluster
    except ImportError:
        raise DesignerError(
            "a SLURM cluster needs dask-jobqueue",
            'install it: pip install "flexjoint-designer[cluster]" dask-jobqueue',
        ) from None
    settings = dict(cluster["slurm"])
    jobs = int(settings.pop("jobs", 1))
    slurm = SLURMCluster(**settings)
    slurm.scale(jobs=jobs)
    return slurm


@contextlib.contextmanager
def executor(
    *, workers: int | None = None, scheduler: str | None = None, cluster: Mapping[str, Any] | None = None
) -> Iterator[Executor]:
    """The executor a sweep asks for, closed (with any cluster it started) when the block ends.

    Precedence: a `scheduler` address (an existing Dask scheduler), then a `cluster` table
    (`scheduler`, `workers` for a local Dask cluster, `slurm` for dask-jobqueue), then local
    processes (`workers` of them; 1 means serial in this process).

    Raises:
        DesignerError: Dask (or dask-jobqueue) is asked for but not installed, or the scheduler
            cannot be reached.
    """
    cluster = dict(cluster or {})
    address = scheduler or cluster.get("scheduler")
    if address is None and not cluster:
        n = local_workers(workers)
        if n == 1:
            yield SerialExecutor()
            return
        # spawn, not fork: the parent may hold MuJoCo, CasADi or BLAS threads
        with ProcessPoolExecutor(max_workers=n, mp_context=multiprocessing.get_context("spawn")) as pool:
            yield pool
        return
    distributed = _dask()
    with contextlib.ExitStack() as stack:
        if address is None:
            address = stack.enter_context(_cluster(cluster))
        try:
            client = stack.enter_context(distributed.Client(address, timeout="20s"))
        except OSError as exc:
            raise DesignerError(
                f"cannot reach the Dask scheduler at {address}: {exc}", "check the address"
            ) from None
        yield client.get_executor(pure=False)
