"""Comparing a result with one stored before a change: nested dicts and lists alike in keys and
lengths, strings and other values equal, numbers within 1e-12 relative (floating-point order may
change), NaN where NaN was stored. Used by the tests that guard speed changes against stored outputs
(tests/test_identify_reference.py, test_loop_reference.py, test_sweep_reference.py)."""

import math

REL = 1e-12


def assert_same(got, want, where: str) -> None:
    """Fail naming the first place (`where`.key[index]...) where `got` departs from `want`."""
    if isinstance(want, dict):
        assert isinstance(got, dict) and sorted(got) == sorted(want), f"{where}: keys differ"
        for k in want:
            assert_same(got[k], want[k], f"{where}.{k}")
    elif isinstance(want, list):
        assert isinstance(got, list) and len(got) == len(want), f"{where}: lengths differ"
        for i, (g, w) in enumerate(zip(got, want, strict=True)):
            assert_same(g, w, f"{where}[{i}]")
    elif isinstance(want, float):
        assert isinstance(got, (int, float)) and not isinstance(got, bool), (
            f"{where}: {got!r} is not a number"
        )
        if math.isnan(want):
            assert math.isnan(got), f"{where}: {got!r} != nan"
        else:
            assert math.isclose(got, want, rel_tol=REL, abs_tol=1e-300), f"{where}: {got!r} != {want!r}"
    else:
        assert got == want, f"{where}: {got!r} != {want!r}"
