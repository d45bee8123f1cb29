"""Inverse design: goals (target, min, max), ranking by P(within tolerance), reachability, printability."""

import itertools

import numpy as np
import pytest
from scipy import stats

from designer.design.candidates import Suggestion
from designer.design.suggestions import suggest
from designer.design.targets import Target, probability_within
from designer.errors import DesignerError
from designer.model.prediction import Prediction
from designer.model.surrogate import Surrogate
from designer.study import space


@pytest.fixture(scope="module")
def sur():
    return Surrogate.load()


def test_flagship_target(sur):
    r = suggest(sur, k=0.8, c=2e-3)
    top = r.candidates[0]
    assert abs(top.predicted["k"].value / 0.8 - 1) <= 0.02
    assert top.predicted["k"].low < 0.8 < top.predicted["k"].high
    assert r.reachable
    assert any("c_x is not predictable" in s and "probability" in s for s in r.statements)
    assert any("reached within +-10 %" in s and "probability" in s for s in r.statements)
    assert 0.30 <= r.predictability["k"]["q2"] <= 0.34  # nested
    space.check_design(top.params)  # printable and in range
    assert len(r.candidates) == 5
    p = [c.p_within for c in r.candidates]
    assert p == sorted(p, reverse=True) and top.p_within == max(p)
    # D over the predictable response only: c's constant desirability is not in it
    assert top.desirability == pytest.approx(r.targets["k"].desirability(top.predicted["k"].value))


def test_round_trip_on_random_designs(sur):
    """For random in-range designs, suggesting their predicted k finds a design within 1 % of it."""
    rng = np.random.default_rng(7)
    for _ in range(10):
        design = {f.name: rng.uniform(f.low, f.high) for f in space.CONTINUOUS}
        design |= {f.name: rng.choice(f.levels) for f in space.CATEGORICAL}
        design["width"] = max(design["width"], 2.5)  # where infill matters, so the design is as given
        k = float(sur.predict(design, responses=["k_x"])["k_x"].value[0])
        top = suggest(sur, k=k, top=1).candidates[0]
        assert abs(top.predicted["k"].value / k - 1) <= 0.01, (design, k, top)


def _grid(fixed):
    """A dense grid over the tested box (9 levels per continuous factor), the solid rule applied."""
    axes = [
        [fixed[f.name]]
        if f.name in fixed
        else (np.linspace(f.low, f.high, 9) if not f.categorical else f.levels)
        for f in space.FACTORS
    ]
    designs = [dict(zip(space.FACTOR_NAMES, p, strict=True)) for p in itertools.product(*axes)]
    designs = [d if space.infill_matters(d) else d | {"density": 100.0} for d in designs]
    return {n: np.array([d[n] for d in designs]) for n in space.FACTOR_NAMES}


def _grid_probability(sur, cols, target, tol=0.1):
    """P(within tolerance) on the grid from scipy's t distribution (independent of the tool's CDF)."""
    m = sur.model("k_x")
    p = sur.predict(cols, responses=["k_x"])["k_x"]
    t95 = stats.t.ppf(0.975, m.dof)
    mu, sd = np.log(p.value), (np.log(p.high) - np.log(p.low)) / (2 * t95)
    edges = [(np.log(target * (1 + s * tol)) - mu) / sd for s in (1, -1)]
    return p.value, stats.t.cdf(edges[0], m.dof) - stats.t.cdf(edges[1], m.dof)


@pytest.mark.parametrize("fixed", [{}, {"width": 4.5, "raster": 45}, {"height": 9, "layer": 0.2}])
def test_suggest_beats_a_dense_grid(sur, fixed):
    """Target, min and max goals: the top candidate is at least as good as the best of a dense grid."""
    cols = _grid(fixed)
    for target in (0.5, 0.9):
        _, prob = _grid_probability(sur, cols, target)
        r = suggest(sur, k=target, fixed=fixed, top=3)
        assert r.candidates[0].p_within >= prob.max() - 1e-3, (target, fixed)
        assert r.candidates[0].p_within == max(c.p_within for c in r.candidates)
    value, _ = _grid_probability(sur, cols, 1.0)
    for goal, best in (("min", value.min()), ("max", value.max())):
        top = suggest(sur, k=goal, fixed=fixed, top=2).candidates[0]
        got = top.predicted["k"].value
        assert (got <= best * 1.001) if goal == "min" else (got >= best * 0.999), (goal, fixed, got, best)
        for name, v in fixed.items():
            assert top.params[name] == v


def test_unreachable_target_says_so_with_ranges(sur):
    r = suggest(sur, k=5.0, top=3)
    assert not r.reachable
    text = " ".join(r.statements)
    assert "outside the measured range" in text and "out of reach within +-10 %" in text
    lo, hi = r.ranges["k"]["predicted"]
    assert r.ranges["k"]["measured"] == [pytest.approx(0.246), pytest.approx(2.092)]
    assert r.candidates[0].predicted["k"].value == pytest.approx(hi, rel=1e-6)
    assert lo < hi < 2.092


def test_measured_but_not_predicted_target_names_the_runs(sur):
    """k = 2.0: the surrogate cannot reach it, but run 21 measured 2.09 N/mm: say so, with its design."""
    r = suggest(sur, k=2.0, top=2)
    assert not r.reachable
    run21 = r.nearest_runs[0]
    assert run21["run"] == 21 and run21["measured"] == pytest.approx(2.092)
    assert run21["params"]["width"] == 2 and run21["params"]["height"] == 4
    at = sur.predict(run21["params"], responses=["k_x"])["k_x"].at(0)
    assert run21["predicted"]["value"] == pytest.approx(at.value)
    assert any(
        s.startswith("run 21 measured 2.09 N/mm at") and "the surrogate predicts 1.26" in s
        for s in r.statements
    )


def test_extrapolation_stays_printable_and_is_flagged(sur):
    inside = suggest(sur, k=2.5, top=1).candidates[0]
    assert not inside.extrapolated
    r = suggest(sur, k=2.5, top=5, allow_extrapolation=True)
    assert r.candidates[0].predicted["k"].value > inside.predicted["k"].value
    for cand in r.candidates:
        assert cand.params["width"] >= 2.0 and cand.params["height"] >= 2.0
        assert 1 <= cand.params["density"] <= 100
        assert cand.extrapolated == space.extrapolated(cand.params) and cand.extrapolated
        assert any("extrapolation" in n for n in cand.notes)
    with pytest.raises(DesignerError, match="cannot be printed"):
        space.check_value("height", 1.5, allow_extrapolation=True)


def test_fixed_factors_are_held_and_shortfall_is_explained(sur):
    r = suggest(sur, k=0.7, fixed={"width": 4.5, "raster": 45}, top=5)
    for cand in r.candidates:
        assert cand.params["width"] == 4.5 and cand.params["raster"] == 45
    assert abs(r.candidates[0].rel_error["k"]) <= 0.02
    if len(r.candidates) < 5:
        assert any(f"{len(r.candidates)} distinct design(s) instead of the 5" in s for s in r.statements)


def test_density_is_any_where_the_walls_fill_the_section(sur):
    r = suggest(sur, k=1.2, fixed={"width": 2}, top=3)
    for cand in r.candidates:
        assert cand.any == ["density"] and cand.params["density"] == 100
        assert any("infill density has no effect" in n for n in cand.notes)


def test_min_max_goals_and_unpredictable_c(sur):
    r = suggest(sur, k=0.5, c="max", top=2)
    assert r.reachable and abs(r.candidates[0].rel_error["k"]) <= 0.1
    assert r.targets["c"].kind == "max" and "c" not in r.candidates[0].probability
    assert any("'max' cannot be acted on" in s and "not predictable" in s for s in r.statements)
    stiff = suggest(sur, k="max", top=1)
    assert stiff.candidates[0].p_within is None and stiff.candidates[0].desirability > 0
    assert (
        stiff.candidates[0].predicted["k"].value
        > suggest(sur, k="min", top=1).candidates[0].predicted["k"].value
    )


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(k=-1.0), "must be positive"),
        (dict(k=0.0), "must be positive"),
        (dict(), "no target given"),
        (dict(k="most"), "not a number, 'min' or 'max'"),
        (dict(k=0.8, fixed={"colour": 1}), "unknown factor"),
        (dict(k=0.8, fixed={"width": 11}), "outside the tested range"),
        (dict(k=0.8, fixed={"width": 1.5}, allow_extrapolation=True), "cannot be printed"),
        (dict(k=0.8, axis="y"), "no axis 'y'"),
        (dict(k=0.8, top=0), "at least 1"),
        (dict(k=0.8, tolerance=0), "tolerance"),
        (dict(k=0.8, weight={"k": -1}), "weight of k"),
        (dict(k=float("nan")), "k = nan is not a finite number"),
        (dict(k=float("inf")), "k = inf is not a finite number"),
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
    assert Target("k", 1.0, 0.5, 2.0, weight=2).desirability(0.75) == pytest.approx(0.25)
    up = Target("k", None, 1.0, 3.0, kind="max")
    assert (up.desirability(0.5), up.desirability(2.0), up.desirability(4.0)) == (0.0, 0.5, 1.0)
    down = Target("k", None, 1.0, 3.0, kind="min")
    assert (down.desirability(0.5), down.desirability(2.0), down.desirability(4.0)) == (1.0, 0.5, 0.0)


def test_probability_within_is_the_predictive_t_mass():
    """From the PI back to the t distribution: equals scipy's mass, and a Monte Carlo of it."""
    dof, mu, s = 12.5, np.log(0.8), 0.21
    t95 = stats.t.ppf(0.975, dof)
    pred = Prediction(np.exp(mu), np.exp(mu - t95 * s), np.exp(mu + t95 * s))
    ref = stats.t.cdf((np.log(0.9 * 1.1) - mu) / s, dof) - stats.t.cdf((np.log(0.9 * 0.9) - mu) / s, dof)
    assert probability_within(pred, 0.9, 0.1, dof) == pytest.approx(ref, abs=1e-12)
    draws = np.exp(mu + s * np.random.default_rng(1).standard_t(dof, 400_000))
    assert probability_within(pred, 0.9, 0.1, dof) == pytest.approx(
        np.mean(np.abs(draws / 0.9 - 1) <= 0.1), abs=3e-3
    )
    raw = Prediction(2.0, 2.0 - t95 * 0.5, 2.0 + t95 * 0.5)
    ref = stats.t.cdf((2.2 - 2.0) / 0.5, dof) - stats.t.cdf((1.8 - 2.0) / 0.5, dof)
    assert probability_within(raw, 2.0, 0.1, dof, log=False) == pytest.approx(ref, abs=1e-12)


def test_suggestion_json_round_trip(sur):
    r = suggest(sur, k=0.8, c="max", top=2)
    back = Suggestion.from_dict(r.to_dict())
    assert back.to_dict() == r.to_dict()


@pytest.mark.parametrize(
    ("value", "low", "high", "text"),
    [
        (0.7994, 0.4123, 1.567, "0.799 [0.41, 1.6] N/mm"),
        (300.4, 214.0, 433.0, "300 [210, 430] N/mm"),  # written out, not 2.1e+02
        (1234.0, 987.0, 15678.0, "1230 [990, 16000] N/mm"),
        (0.002234, 0.000351, 0.0042, "0.00223 [0.00035, 0.0042] N/mm"),
        (2e-05, 1.04e-05, 3.9e-05, "2e-05 [1e-05, 3.9e-05] N/mm"),
    ],
)
def test_a_prediction_reads_with_its_digits_and_unit(value, low, high, text):
    assert Prediction(value, low, high).text("N/mm") == text
    assert Prediction(value, low, high).text() == text.removesuffix(" N/mm")
