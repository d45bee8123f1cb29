"""Issue 37, cause 7: under a small `ulimit -v`, `designer next` hung forever inside CasADi's OpenBLAS
(a failed 128 MiB mapping retried in a loop, 1 GiB), exited 3 when IPOPT's plugin failed to load
(600 MiB), or 130 with a false "stopped by SIGINT". Now: exit 2 before any work, naming the limit
and the fix; --help still works; at the limit the command runs. Real processes, real rlimits."""

from __future__ import annotations

import resource
import subprocess
import sys

import pytest

CODE = "import sys; from designer_cli.main import main; sys.argv[0] = 'designer'; main()"


def _designer(limit_bytes: int, *args: str) -> subprocess.CompletedProcess:
    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (limit_bytes, limit_bytes))

    return subprocess.run(
        [sys.executable, "-I", "-c", CODE, *args],
        capture_output=True,
        text=True,
        timeout=120,
        preexec_fn=limit,
    )


@pytest.mark.parametrize("mib", [600, 1024])
def test_a_small_address_space_limit_is_named_not_hung(mib):
    run = _designer(mib << 20, "next", "--k", "0.8")
    assert run.returncode == 2, run.stderr
    lines = run.stderr.strip().splitlines()
    assert (
        len(lines) == 1
        and f"(ulimit -v) is {mib // 1024 or mib} " in lines[0]
        and "ulimit -v 4194304" in lines[0]
    )


def test_help_and_a_sufficient_limit_run():
    assert _designer(600 << 20, "next", "--help").returncode == 0
    run = _designer(4 << 30, "next", "--k", "0.8", "--json")
    assert run.returncode == 0, run.stderr
