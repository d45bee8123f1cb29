"""Tests run against the installed distribution (CI installs it non-editable), never the checkout."""

import os
import sys

import pytest

_root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:] = [p for p in sys.path if os.path.abspath(p or os.curdir) != _root]
# Subprocesses that start the CLI with `python -I -c ...` for the same reason: isolated mode keeps the
# current directory (often the checkout) off sys.path.


_START = os.getcwd()


@pytest.fixture(autouse=True)
def _start_in_the_starting_folder():
    """Every test starts in the folder pytest started in. A test (or a library it drives) that leaves
    the process in another folder, or in one since removed, must not break the tests after it: on the
    whole suite the in-process commands after one such test failed with 'getcwd failed' and
    FileNotFoundError (sbatch, Drake and fmpy likewise), while every file passed on its own."""
    os.chdir(_START)
    yield


@pytest.fixture(scope="module")
def fmu_cache(tmp_path_factory):
    """Build FMU binaries into a throw-away cache, never the user's (one per test module)."""
    mp = pytest.MonkeyPatch()
    mp.setenv("XDG_CACHE_HOME", str(tmp_path_factory.mktemp("cache")))
    yield
    mp.undo()
