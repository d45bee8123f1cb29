"""The response-surface surrogate: LOO selection, intervals, CasADi function, shipped file."""

import json

import numpy as np
import pytest

from designer import data, space
from designer.errors import DesignerError
from designer.surrogate import FORMAT, Surrogate, _ridge_fit, design_matrix, leave_one_out


@pytest.fixture(scope="module")
def refit():
    return Surrogate().fit(data.load_table())


def test_shipped_surrogate_equals_a_refit_of_the_bundled_table(refit):
    shipped = Surrogate.load()
    assert shipped.table_hash == data.table_hash(data.load_table())
    assert shipped.responses == refit.responses
    for r in refit.responses:
        a, b = shipped.models[r], refit.models[r]
        assert a.form == b.form and a.alpha == b.alpha
        np.testing.assert_allclose(a.coef, b.coef, rtol=1e-9, atol=1e-15)
        np.testing.assert_allclose(a.vcov, b.vcov, rtol=1e-9, atol=1e-15)
        assert a.loo == pytest.approx(b.loo, rel=1e-9)
    assert shipped.id == refit.id


def test_loo_figures_on_the_bundled_table(refit):
    k, c = refit.models["k_x"], refit.models["c_x"]
    assert k.form == "powerlaw" and k.loo["q2"] >= 0.40
    assert k.predictable
    # c_x: nothing beats the mean by more than the noise of the comparison
    assert c.form == "mean" and not c.predictable
    assert max(m["q2"] for m in c.candidates.values()) < 0.06
    for m in (k, c):
        assert 0.85 <= m.loo["coverage95"] <= 1.0


def test_leave_one_out_is_an_honest_refit():
    """One LOO prediction equals a fit without that run, predicted at that run."""
    t = data.load_table()
    X = {n: t[n].to_numpy(float) for n in space.FACTOR_NAMES}
    y = t["k_x"].to_numpy(float)
    loo = leave_one_out("linear", X, y, "k_x")
    from designer.surrogate import ResponseSurface

    keep = np.arange(len(y)) != 7
    m = ResponseSurface("k_x", "linear").fit({k: v[keep] for k, v in X.items()}, y[keep])
    assert loo.value[7] == pytest.approx(m.predict({k: v[7:8] for k, v in X.items()}).value[0], rel=1e-12)


def test_prediction_intervals_and_casadi_function_agree(refit):
    design = dict(density=60, length=24, width=4.5, height=9, layer=0.16, raster=0)
    for r in refit.responses:
        p = refit.predict(design, responses=[r])[r]
        assert p.low[0] < p.value[0] < p.high[0]
        f = refit.models[r].casadi_function()
        out = f([design[n] for n in space.FACTOR_NAMES])
        assert [float(v) for v in out] == pytest.approx([p.value[0], p.low[0], p.high[0]], rel=1e-12)


def test_vectorised_prediction_matches_single(refit):
    t = data.load_table()
    many = refit.predict(t)["k_x"].value
    one = [refit.predict(t.iloc[i])["k_x"].value[0] for i in (0, 20, 43)]
    assert many[[0, 20, 43]] == pytest.approx(one, rel=1e-12)


def test_positivity_is_enforced_on_the_tested_grid():
    """A table whose least-squares fit dips below zero on the grid comes back clipped at the floor."""
    from designer.surrogate import _grid

    rng = np.random.default_rng(1)
    t = data.load_table()
    Z = design_matrix("quadratic", t)
    y = 0.01 + np.abs(rng.normal(0, 1, len(t))) * (t["height"].to_numpy() < 6)
    Zg = design_matrix("quadratic", _grid())
    free = np.linalg.lstsq(Z, y, rcond=None)[0]
    assert (Zg @ free).min() < 0
    beta = _ridge_fit(Z, y, 0.0, Zg, 1e-3)
    assert (Zg @ beta).min() >= 1e-3 * (1 - 1e-6)


def test_save_load_round_trip_and_bad_files(tmp_path, refit):
    p = refit.save(tmp_path / "s.json")
    back = Surrogate.load(p)
    assert back.id == refit.id
    assert json.loads(p.read_text())["format"] == FORMAT
    (tmp_path / "bad.json").write_text("{")
    with pytest.raises(DesignerError, match="cannot read surrogate"):
        Surrogate.load(tmp_path / "bad.json")
    (tmp_path / "other.json").write_text("{}")
    with pytest.raises(DesignerError, match="is not a"):
        Surrogate.load(tmp_path / "other.json")
    with pytest.raises(DesignerError, match="no response 'k_y'"):
        refit.model("k_y")
