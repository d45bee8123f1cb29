"""Inverse design: targets hit, round trip, unreachable targets, fixed factors, desirability."""

import numpy as np
import pytest

from designer import space
from designer.errors import DesignerError
from designer.suggest import Target, suggest
from designer.surrogate import Surrogate


@pytest.fixture(scope="module")
def sur():
    return Surrogate.load()


def test_flagship_target(sur):
    r = suggest(sur, k=0.8, c=2e-3)
    top = r.candidates[0]
    assert abs(top.predicted["k"].value / 0.8 - 1) <= 0.02
    lo, hi = top.predicted["k"].low, top.predicted["k"].high
    assert lo < 0.8 < hi
    assert r.reachable
    assert any("c_x is not predictable" in s for s in r.statements)
    assert r.predictability["k"]["q2"] >= 0.4
    space.check_design(top.params)  # printable and in range
    # distinct candidates, ranked by desirability
    assert len(r.candidates) == 5
    d = [c.desirability for c in r.candidates]
    assert d == sorted(d, reverse=True)


def test_round_trip_on_random_designs(sur):
    """For random in-range designs, suggesting their predicted k finds a design within 1 % of it."""
    rng = np.random.default_rng(7)
    for _ in range(20):
        design = {f.name: rng.uniform(f.low, f.high) for f in space.CONTINUOUS}
        design |= {f.name: rng.choice(f.levels) for f in space.CATEGORICAL}
        k = float(sur.predict(design, responses=["k_x"])["k_x"].value[0])
        top = suggest(sur, k=k, top=1).candidates[0]
        assert abs(top.predicted["k"].value / k - 1) <= 0.01, (design, k, top)


def test_unreachable_target_says_so_with_nearest_designs(sur):
    r = suggest(sur, k=5.0, top=3)
    assert not r.reachable
    text = " ".join(r.statements)
    assert "outside the measured range" in text and "out of reach" in text
    best = r.candidates[0].predicted["k"].value
    assert 1.0 < best < 5.0
    # the nearest design is the stiffest the tested ranges allow: the reachable maximum
    assert f"to {best:.3g} N/mm" in text


def test_extrapolation_only_when_asked(sur):
    inside = suggest(sur, k=2.5, top=1).candidates[0]
    assert not inside.extrapolated
    outside = suggest(sur, k=2.5, top=1, allow_extrapolation=True).candidates[0]
    assert outside.predicted["k"].value > inside.predicted["k"].value
    assert outside.extrapolated and any("extrapolation" in n for n in outside.notes)


def test_fixed_factors_are_held(sur):
    r = suggest(sur, k=0.7, fixed={"width": 4.5, "raster": 45}, top=3)
    for cand in r.candidates:
        assert cand.params["width"] == 4.5 and cand.params["raster"] == 45
    assert abs(r.candidates[0].rel_error["k"]) <= 0.02


def test_infill_note_when_width_is_two(sur):
    r = suggest(sur, k=1.2, fixed={"width": 2}, top=1)
    assert any("infill density has no effect" in n for n in r.candidates[0].notes)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(k=-1.0), "must be positive"),
        (dict(k=0.0), "must be positive"),
        (dict(), "no target given"),
        (dict(k=0.8, fixed={"colour": 1}), "unknown factor"),
        (dict(k=0.8, fixed={"width": 11}), "outside the tested range"),
        (dict(k=0.8, axis="y"), "no axis 'y'"),
        (dict(k=0.8, top=0), "at least 1"),
        (dict(k=float("nan")), "must be positive"),
    ],
)
def test_bad_requests(sur, kwargs, message):
    with pytest.raises(DesignerError, match=message):
        suggest(sur, **kwargs)


def test_desirability_is_derringer_suich():
    t = Target("k", 1.0, 0.5, 2.0)
    assert t.desirability(1.0) == 1.0
    assert t.desirability(0.75) == pytest.approx(0.5)
    assert t.desirability(1.5) == pytest.approx(0.5)
    assert t.desirability(0.5) == 0.0 and t.desirability(2.5) == 0.0
