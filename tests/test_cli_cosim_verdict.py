"""`designer cosim --validate` prints a verdict with its thresholds: pass when the error falls at least
first-order with the step and agrees with MuJoCo's in-engine spring-damper to round-off, FAIL otherwise."""

from __future__ import annotations

from designer_cli.common import console
from designer_cli.cosim import _print_verdict
from designer_cli.cosim import _verdict as verdict


def _verdict(steps: list[dict]) -> str:
    with console.capture() as cap:
        _print_verdict({"reference": "test", "max_error": 1e-16, "steps": steps})
    return cap.get()


def test_first_order_convergence_passes():
    out = _verdict([{"step": 2e-3, "max_error": 0.06}, {"step": 4e-3, "max_error": 0.13}])
    assert "order 1.12 (expected >= 0.8: pass)" in out
    assert out.strip().endswith("validation: pass")


def test_stalled_convergence_fails():
    out = _verdict([{"step": 4e-3, "max_error": 0.13}, {"step": 2e-3, "max_error": 0.12}])
    assert "FAIL" in out.splitlines()[-2]
    assert out.strip().endswith("validation: FAIL")


def test_same_step_disagreement_fails():
    steps = [{"step": 4e-3, "max_error": 0.13, "max_error_same_step": 1e-3}]
    out = _verdict(steps)
    assert "same-step MuJoCo 0.001 (expected <= 1e-09: FAIL)" in out
    assert out.strip().endswith("validation: FAIL")


def test_the_verdict_decides_the_exit():
    """`cosim --validate` exits 1 on FAIL: the verdict's flag is what the command acts on."""
    good = [{"step": 2e-3, "max_error": 0.06}, {"step": 4e-3, "max_error": 0.13}]
    bad = [{"step": 4e-3, "max_error": 0.13}, {"step": 2e-3, "max_error": 0.12}]
    assert verdict({"reference": "t", "max_error": 0.0, "steps": good})[1]
    assert not verdict({"reference": "t", "max_error": 0.0, "steps": bad})[1]
