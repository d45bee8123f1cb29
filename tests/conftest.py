"""Tests run against the installed distribution (CI installs it non-editable), never the checkout."""

import os
import sys

import pytest

_root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:] = [p for p in sys.path if os.path.abspath(p or os.curdir) != _root]
# Subprocesses that start the CLI with `python -I -c ...` for the same reason: isolated mode keeps the
# current directory (often the checkout) off sys.path.


@pytest.fixture(scope="module")
def fmu_cache(tmp_path_factory):
    """Build FMU binaries into a throw-away cache, never the user's (one per test module)."""
    mp = pytest.MonkeyPatch()
    mp.setenv("XDG_CACHE_HOME", str(tmp_path_factory.mktemp("cache")))
    yield
    mp.undo()
