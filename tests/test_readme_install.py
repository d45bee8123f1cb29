"""README's install figures are what `scripts/measure_install.py` measures: the sizes of the install
and its extras (within the rounding README uses, so a new dependency or a grown one shows), and the
compiler statement (an export and a co-simulation run with no C compiler on PATH). The suite's time
(`--suite`, minutes) is not rerun here."""

from __future__ import annotations

import importlib.util
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"


def _script():
    spec = importlib.util.spec_from_file_location("measure_install", ROOT / "scripts" / "measure_install.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _text() -> str:
    return " ".join(README.read_text().split())  # the README wraps sentences anywhere


def _stated(pattern: str) -> tuple[float, dict[str, float]]:
    """The total README states after `pattern` and its '(name N MB, name N, ...)' list."""
    m = re.search(pattern + r" about ([\d.]+) [GM]B \(([^)]*)\)", _text())
    assert m, f"README no longer states: {pattern}"
    items = dict(
        re.fullmatch(r"(\S+) (\d+)(?: MB)?", item.strip()).groups() for item in m.group(2).split(",")
    )
    return float(m.group(1)), {name: float(mb) for name, mb in items.items()}


def test_install_sizes_are_measured():
    measured = _script().sizes()
    if measured["missing"]:
        pytest.skip(f"not installed here, so not measurable: {', '.join(measured['missing'])}")
    for pattern, key, scale, tolerance in (
        (r"the tool with its dependencies", "base_mb", 1000, 0.1),  # GB
        (r"`\[test\]` adds", "test_adds_mb", 1000, 0.1),
        (r"`\[cluster\]`", "cluster_adds_mb", 1, 5),  # MB
    ):
        total, largest = _stated(pattern)
        assert abs(measured[key] / scale - total) <= tolerance, (pattern, measured[key], total)
        group = {"base_mb": "base", "test_adds_mb": "test", "cluster_adds_mb": "cluster"}[key]
        biggest = measured["largest"][group]
        assert list(largest) == list(biggest), f"{pattern}: README names {list(largest)}, largest {biggest}"
        for name, mb in largest.items():
            assert abs(biggest[name] - mb) <= 0.1 * mb + 5, (name, biggest[name], mb)
    (everything,) = re.search(r"all three about ([\d.]+) GB", _text()).groups()
    assert abs(measured["all_mb"] / 1000 - float(everything)) <= 0.1


def test_exports_need_no_compiler_and_cosim_falls_back():
    assert "Exports need no C compiler" in _text()
    assert "without one `designer cosim` runs its Python master" in _text()
    checked = _script().compiler()
    assert checked["export_without_compiler"], checked["export_error"]
    assert checked["cosim_without_compiler_engine"] == "python", checked["cosim_error"]


def test_suite_time_is_read_from_pytests_summary():
    log = "...\n===== 1347 passed, 12 skipped in 563.20s (0:09:23) =====\n"
    assert _script().suite_from_log(log) == pytest.approx(
        {"tests_min": 563.2 / 60, "summary": "1347 passed, 12 skipped"}
    )
    quiet = "....\n1797 passed, 1 skipped, 1 warning in 686.47s (0:11:26)\n"  # pytest -q: no rule
    assert _script().suite_from_log(quiet) == pytest.approx(
        {"tests_min": 686.47 / 60, "summary": "1797 passed, 1 skipped, 1 warning"}
    )
