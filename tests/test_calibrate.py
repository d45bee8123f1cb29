"""Calibration to a user's printer and the next prints: tiny exact cases, invariants, bad input,
and simulated printers from tests/printers.py (written independently of designer)."""

import json
import math
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from clitools import assert_clean_failure, run_inprocess
from test_cli_campaign import SIX

import designer
from designer.model.calibration import report
from designer.model.correction import CalibratedSurface, noise_of
from designer.model.surrogate import Surrogate
from designer.study.space import check_design

sys.path.insert(0, str(Path(__file__).parent))
import printers  # noqa: E402

FACTORS = ["density", "length", "width", "height", "layer", "raster"]


@pytest.fixture(scope="module")
def study():
    return Surrogate.load()


@pytest.fixture(scope="module")
def table():
    return designer.load_table()


def _rows(table, idx, scale=1.0):
    runs = table.iloc[idx][FACTORS + ["k_x", "c_x"]].reset_index(drop=True)
    return runs.assign(k_x=runs["k_x"] * scale)


def test_zero_runs_return_the_study_surrogate(study, table):
    same = designer.calibrate(study, pd.DataFrame())
    assert same is study
    X = table[FACTORS]
    for r in study.responses:
        a, b = same.predict(X)[r], study.predict(X)[r]
        np.testing.assert_allclose(a.value, b.value, rtol=1e-12)


def _log_sd(pred, t95):
    return (np.log(pred.high) - np.log(pred.value)) / t95


def test_one_run_at_a_study_design_moves_the_prediction_by_the_models_amount(study, table):
    """The model of correction.py's docstring, written out here with numpy: log y = mu0 + u h'b + g + u d + e.
    On the user's printer only (u = 1): b ~ N(0, diag(sb)) the mechanism terms, with h(x) = [1, the
    study's d mu0/d width and d mu0/d height (central differences here), d mu0/d density x density x
    ln(density / 100), coded layer, raster sign, their product], and d a Matern 5/2 field of sd
    LOCAL_SD; g a Gaussian process of size sg(x) = amplitude * sqrt(max(s0^2 - sn^2, s0^2 / 4)) and
    Matern 5/2 correlation (scikit-learn's) over the coded settings, shared by both printers; e ~ N(0,
    sn^2). Observed at the study's 44 runs (u = 0) and the user's one run. The prediction at the run
    moves by the conditional mean of h'b + g + d there, its scale is the conditional sd."""
    run = _rows(table, [12], scale=0.7)
    assert run["width"][0] > 2  # a hollow section: the design is predicted as given
    base, tau = study.model("k_x"), 0.3
    sb = np.array([tau, 0.15, 0.15, 0.3, 0.1, 0.05, 0.05]) ** 2
    local = 0.06
    cal = designer.calibrate(study, run)
    length, amplitude, noise = cal.model("k_x").length, cal.model("k_x").amplitude, noise_of(base)
    X = pd.concat([table[FACTORS], run[FACTORS]], ignore_index=True)
    X.loc[X[["width", "height"]].min(axis=1) <= 2.0, "density"] = 100.0  # as printed: walls fill 2 mm
    from sklearn.gaussian_process.kernels import Matern

    from designer.model.correction import coded

    def mu0(D):
        return np.log(base.predict(D).value)

    def slope(name, step):
        up, down = X.copy(), X.copy()
        up[name] += step
        down[name] -= step
        return (mu0(up) - mu0(down)) / (2 * step)

    rho_d = X["density"].to_numpy()
    lc, rs = (X["layer"].to_numpy() - 0.16) / 0.04, (X["raster"].to_numpy() - 22.5) / 22.5
    H = np.column_stack(
        [
            np.ones(len(X)),
            slope("width", 1e-5),
            slope("height", 1e-5),
            slope("density", 1e-4) * rho_d * np.log(rho_d / 100),
            lc,
            rs,
            lc * rs,
        ]
    )
    p = base.predict(X)
    s0 = _log_sd(p, base.t95)
    sg0 = np.sqrt(np.maximum(s0**2 - noise**2, 0.25 * s0**2))
    sg = amplitude * sg0
    u = np.r_[np.zeros(len(table)), 1.0]
    Hu = H * u[:, None]
    Z = coded(X)
    rho = Matern(length_scale=length, nu=2.5)(Z)
    K = (
        (Hu * sb) @ Hu.T
        + local**2 * np.outer(u, u) * rho
        + np.outer(sg, sg) * rho
        + noise**2 * np.eye(len(u))
    )
    r = np.log(np.r_[table["k_x"], run["k_x"]]) - np.log(p.value)
    c = K[-1] - noise**2 * (np.arange(len(u)) == len(u) - 1)
    shift = c @ np.linalg.solve(K, r)
    prior = s0[-1] ** 2 + (amplitude**2 - 1) * sg0[-1] ** 2 + H[-1] ** 2 @ sb + local**2
    scale = math.sqrt(prior - c @ np.linalg.solve(K, c))
    p1 = cal.predict(run[FACTORS])["k_x"].at(0)
    # central differences of a smooth surface: the derivatives agree to about 1e-9, the rest exactly
    assert math.log(p1.value) - math.log(p.value[-1]) == pytest.approx(shift, rel=1e-7)
    assert _log_sd(p1, base.t95) == pytest.approx(scale, rel=1e-7)
    # the run sits on a study design measured at 1/0.7 of it: the factor comes out near 0.7 (one run
    # cannot tell the factor from the other mechanisms, so its interval stays wide) and the interval
    # at the run itself shrinks to about the print scatter
    factor = cal.model("k_x").printer_factor()
    assert factor.low < 0.7 < factor.high
    assert scale < 2 * noise


@pytest.mark.parametrize("response", ["k_x", "c_x"])
def test_the_correction_predicts_each_study_run_from_the_others_with_calibrated_intervals(study, response):
    """Leave-one-out over the study's own runs, by brute force: each run's log value predicted by the
    correction conditioned on the other 43, at the settings calibrate chose; the standardized errors
    have sd about 1 (44 runs: the sample sd itself scatters by about 0.11) and the 95 % intervals cover
    (measured: k sd 0.94, 91 % inside; c sd 1.07, 95 % inside)."""
    from scipy import stats

    from designer.model.correction import _correlation, _local_sd, _log_moments, coded, settings_of
    from designer.model.forms import as_printed

    base = study.model(response)
    length, amplitude, noise = settings_of(study, response)
    X = as_printed({n: np.asarray(study.training[n], dtype=float) for n in FACTORS})
    y = np.asarray(study.training[response], dtype=float)
    mu0, s0 = _log_moments(base, X)
    sg = amplitude * _local_sd(s0, noise)
    K = np.outer(sg, sg) * _correlation(coded(X), coded(X), length) + noise**2 * np.eye(len(y))
    r = np.log(y) - mu0
    z = []
    for i in range(len(y)):
        o = np.arange(len(y)) != i
        mean = K[i, o] @ np.linalg.solve(K[np.ix_(o, o)], r[o])
        var = K[i, i] - K[i, o] @ np.linalg.solve(K[np.ix_(o, o)], K[i, o])
        z.append((r[i] - mean) / math.sqrt(var))
    z = np.array(z)
    assert 0.8 <= np.std(z) <= 1.15, np.std(z)
    assert np.mean(np.abs(z) <= stats.norm.ppf(0.975)) >= 0.88  # 44 runs: 0.95 within its scatter


def test_printer_factor_of_one_half_is_recovered_within_its_interval(study, table):
    runs = _rows(table, list(range(0, 40, 4)), scale=0.5)  # ten study designs, measured at half
    factor = designer.calibrate(study, runs).model("k_x").printer_factor()
    assert factor.low <= 0.5 <= factor.high
    assert factor.high / factor.low < 2.0  # ten runs say something


def test_interval_narrows_near_measured_designs_and_stays_wide_elsewhere(study, table):
    from designer.model.correction import coded

    runs = _rows(table, [3, 10, 20, 30])
    cal = designer.calibrate(study, runs)
    # near: a design the user printed; far: of the printable grid, the design farthest from every run
    # the study or the user printed (so no run observes the local correction there)
    grid = printers.grid(points=5)
    gap = np.min(np.linalg.norm(coded(grid)[:, None, :] - coded(table)[None, :, :], axis=2), axis=1)
    near, far = table.iloc[[3]][FACTORS], grid.iloc[[int(np.argmax(gap))]][FACTORS]
    width = {
        n: {
            s: float(np.log(p.high / p.low)[0])
            for s, p in (("study", study.predict(X)["k_x"]), ("cal", cal.predict(X)["k_x"]))
        }
        for n, X in (("near", near), ("far", far))
    }
    assert width["near"]["cal"] < 0.5 * width["near"]["study"]
    assert width["far"]["cal"] > 0.9 * width["far"]["study"]


def test_save_load_and_recalibration_are_the_same_surrogate(study, table, tmp_path):
    runs = _rows(table, [1, 2, 3, 4])
    cal = designer.calibrate(study, runs)
    cal.save(tmp_path / "mine.json")
    back = Surrogate.load(tmp_path / "mine.json")
    assert back.id == cal.id and isinstance(back.model("k_x"), CalibratedSurface)
    twice = designer.calibrate(designer.calibrate(study, runs.iloc[:2]), runs.iloc[2:])
    X = table[FACTORS]
    for r in ("k_x", "c_x"):
        np.testing.assert_allclose(back.predict(X)[r].high, cal.predict(X)[r].high, rtol=1e-12)
        np.testing.assert_allclose(twice.predict(X)[r].value, cal.predict(X)[r].value, rtol=1e-12)


def test_casadi_function_equals_predict(study, table):
    cal = designer.calibrate(study, _rows(table, [5, 6], scale=1.3))
    f = cal.model("k_x").casadi_function()
    hollow = np.flatnonzero(table["width"].to_numpy() > 2)  # predicted as given (thin: as solid)
    for i in hollow[[0, 7, 20]]:
        p = cal.predict(table.iloc[[i]][FACTORS])["k_x"].at(0)
        v, lo, hi = (float(x) for x in f(table.iloc[i][FACTORS].to_numpy(dtype=float)))
        assert (v, lo, hi) == pytest.approx((p.value, p.low, p.high), rel=1e-12)


def test_simulated_printer_three_prints_pin_the_neighbourhood(study):
    printer = printers.Printer(3)
    rng = np.random.default_rng(0)
    sug = designer.suggest(study, k=0.8, top=3)
    designs = pd.DataFrame([c.params for c in sug.candidates])
    runs = printer.prints(designs, rng)
    cal = designer.calibrate(study, runs)
    truth = printer.k(designs)
    pred = cal.predict(designs[FACTORS])["k_x"]
    assert np.all(np.abs(pred.value / truth - 1) < 0.08)
    assert np.all((pred.low <= truth) & (truth <= pred.high))
    factor = cal.model("k_x").printer_factor()
    assert factor.low <= printer.factor_k <= factor.high


def test_calibrated_intervals_hold_on_drawn_printers(study):
    """Against printers whose k departs from the study's spline between the runs as much as the study
    surrogate's nested cross-validation says it errs there (tests/printers.py, DEPARTURE_SCALE): after
    1 or 3 prints near a design, the calibrated log k's standardized errors at designs around it have
    an sd a little under 1 and the 95 % intervals cover at least about 95 % (here sd 0.80, coverage
    0.98; benchmarks/calibration_check.py, 30 printers: sd 0.84 and 0.85, 98 % and 99 % inside): the
    Matern correlation is a little cautious at random designs around a print, and right at the loop's
    recommendations (sd 1.0 there); on the spline's smoother printers the intervals are far too wide
    (sd 0.36 here) and this test fails."""
    rng = np.random.default_rng(5)
    half = {f: (hi - lo) / 2 for f, (lo, hi) in printers.RANGES.items()}

    def around(centre, n, scale):
        moved = {f: np.clip(centre[f] + rng.normal(0, scale * half[f], n), *printers.RANGES[f]) for f in half}
        return pd.DataFrame(moved | {f: centre[f] for f in ("layer", "raster")})[FACTORS]

    z = []
    for seed in range(16):
        printer = printers.Printer(3000 + seed, drawn=True)
        centre = {f: rng.uniform(*printers.RANGES[f]) for f in printers.RANGES}
        centre |= {f: rng.choice(printers.LEVELS[f]) for f in printers.LEVELS}
        for n in (1, 3):
            model = designer.calibrate(study, printer.prints(around(centre, n, 0.15), rng)).model("k_x")
            q = around(centre, 30, 0.3)
            mu, s = model.log_moments({f: q[f].to_numpy() for f in FACTORS})
            z.extend((np.log(printer.k(q)) - mu) / s)
    z = np.array(z)
    assert 0.7 < z.std() < 1.3 and np.mean(np.abs(z) < model.t95) > 0.85, (z.std(), np.mean(np.abs(z) < 1.96))


def test_next_prints_proposes_distinct_printable_designs_and_stops_when_sure(study, table):
    nxt = designer.next_prints(study, k=0.8, n=3)
    assert not nxt.stop and len(nxt.prints) == 3 and nxt.p_after > nxt.p_now
    for p in nxt.prints:
        check_design(p.params)
        assert p.params["width"] >= 2.0 and p.params["layer"] in (0.12, 0.16, 0.2)
    keys = {tuple(round(p.params[f], 2) for f in FACTORS) for p in nxt.prints}
    assert len(keys) == 3
    # the first print is design #1, the design most likely to land now (the loop measured fewer
    # prints to a hit so than with the knowledge gradient's exploratory first print); the others not
    assert nxt.prints[0].params == nxt.recommendation.params and nxt.prints[0].recommended
    assert not any(p.recommended for p in nxt.prints[1:])
    # four prints at one design that measures 0.8: the recommendation there is sure enough
    rec = nxt.recommendation.params
    runs = pd.DataFrame([rec] * 4).assign(k_x=0.8, c_x=2e-3)
    sure = designer.next_prints(designer.calibrate(study, runs), k=0.8, n=3)
    assert sure.stop and sure.prints == [] and sure.p_now >= 0.9


@pytest.mark.parametrize("rows", [[12], [3, 10, 20], list(range(1, 41, 4))])
def test_cli_calibrate_and_next(tmp_path, capsys, table, rows):
    runs = tmp_path / "mine.csv"
    _rows(table, rows, scale=0.8).to_csv(runs, index=False)
    out = tmp_path / "mine.json"
    code, stdout, err = run_inprocess(["calibrate", runs, "-o", out, "--json"], capsys)
    assert code == 0, err
    rep = json.loads(stdout)
    assert rep["n_runs"] == len(rows)
    loo = rep["responses"]["k_x"]["loo_user"]
    assert (loo is None) if len(rows) == 1 else loo["n"] == len(rows)
    factor = rep["responses"]["k_x"]["printer_factor"]
    assert factor["low"] < factor["value"] < factor["high"]
    code, stdout, err = run_inprocess(
        ["next", "--k", "0.8", "--n", "2", "--surrogate", out, "--json"], capsys
    )
    assert code == 0, err
    data = json.loads(stdout)
    assert data["stop"] or len(data["prints"]) == 2
    for cmd in (
        ["suggest", "--k", "0.8"],
        ["predict", *SIX],
    ):
        code, _, err = run_inprocess([*cmd, "--surrogate", out], capsys)
        assert code == 0, err


@pytest.mark.parametrize(
    "content, words",
    [
        ("a,b\n1,2\n", "density"),  # none of the study's factors
        ("density,length,width,height,layer,raster,k_x,c_x\n60,24,1.5,9,0.16,0,0.8,0.002\n", "width"),
        ("density,length,width,height,layer,raster,k_theta,c_theta\n60,24,4.5,9,0.16,0,8,0.2\n", "k_x"),
    ],
)
def test_cli_calibrate_bad_input(tmp_path, capsys, content, words):
    bad = tmp_path / "bad.csv"
    bad.write_text(content)
    code, _, err = run_inprocess(["calibrate", bad, "-o", tmp_path / "o.json"], capsys)
    assert_clean_failure(code, err, allowed=(2,))
    assert words in err
    assert not (tmp_path / "o.json").exists()


def test_a_new_printer_carries_the_printer_factor_and_the_studys_own_runs(study, table):
    from designer.model.calibration import new_printer
    from designer.model.correction import PRINTER_SD

    fresh = new_printer(study)
    X = table[FACTORS]
    a, b = study.predict(X)["k_x"], fresh.predict(X)["k_x"]
    t95 = study.model("k_x").t95
    s_study, s_fresh = _log_sd(a, t95), _log_sd(b, t95)
    # the printer's factor is unknown: no interval narrower than it, none wider than study + factor
    assert np.all(s_fresh >= PRINTER_SD * (1 - 1e-9))
    assert np.all(s_fresh**2 <= s_study**2 + PRINTER_SD**2 + 1e-12)
    # the study's runs observe the local correction: at its designs the prediction moves towards
    # what the study measured
    before = np.abs(np.log(table["k_x"] / a.value))
    after = np.abs(np.log(table["k_x"] / b.value))
    assert np.median(after) < 0.5 * np.median(before)
    # and calibrating it continues from the study, as calibrating the study does
    runs = _rows(table, [1, 2])
    np.testing.assert_allclose(
        designer.calibrate(fresh, runs).predict(X)["k_x"].value,
        designer.calibrate(study, runs).predict(X)["k_x"].value,
        rtol=1e-12,
    )


@pytest.mark.parametrize("seed, k", [(11, 0.6), (12, 0.9), (13, 1.1)])
def test_the_loop_lands_on_a_simulated_printer_within_four_prints(study, seed, k):
    """calibrate -> next (n=1) -> print and measure, against a printer of tests/printers.py."""
    printer = printers.Printer(seed)
    assert printer.best(k=k)[1], "the test's target must be reachable on this printer"
    rng = np.random.default_rng(seed)
    runs = pd.DataFrame()
    for _ in range(4):
        nxt = designer.next_prints(designer.calibrate(study, runs), k=k, n=1)
        design = nxt.prints[0].params if nxt.prints else nxt.recommendation.params
        run = printer.prints(pd.DataFrame([design]), rng)
        if abs(run["k_x_N_per_mm"][0] / k - 1) <= 0.1:
            break
        runs = pd.concat([runs, run], ignore_index=True)
    else:
        pytest.fail(f"printer {seed} (factor {printer.factor_k:.2f}) missed k = {k} four times")


#: one print as the design loop makes it: the study's suggestion for 0.36 N/mm, on a printer whose k
#: there came out 0.363 N/mm. Before the grid backed the search, `next --k 0.342` answered "out of
#: reach ... the surrogate predicts k_x from 0.242 to 2.04 N/mm; the nearest design is predicted at
#: 0.397 (+16 %)", though its own model predicts 0.342 within +-10 % at printable designs.
ONE_PRINT = {
    "density": [100.0], "length": [30.0], "width": [7.0], "height": [14.0], "layer": [0.2],
    "raster": [45.0], "k_x": [0.36293000791563435], "c_x": [0.0014389662741348668],
}  # fmt: skip


@pytest.mark.parametrize(
    ("runs", "fixed", "targets"),
    [
        (ONE_PRINT, {}, (0.342061313697906, 0.3, 0.43)),
        ("3:0.656", {}, (0.3488, 1.6)),
        ("12,30:0.656", {"raster": 0.0}, (0.3488, 0.43)),
        ("5,18,40:1.45", {}, (0.3, 1.6)),
    ],
)
def test_next_is_never_out_of_reach_where_a_printable_design_is_predicted_within_tolerance(
    study, table, runs, fixed, targets
):
    """The printable grid of tests/printers.py (not the tool's search) says where the calibrated model
    itself predicts a target within +-10 %: there `next` must answer, not say "out of reach"; and the
    range it states when it does say so holds its own nearest design."""
    if isinstance(runs, str):  # study rows, measured at a printer factor
        rows, factor = runs.split(":")
        runs = _rows(table, [int(i) for i in rows.split(",")], scale=float(factor))
    cal = designer.calibrate(study, pd.DataFrame(runs))
    grid = printers.grid(fixed, points=6)
    predicted = cal.predict(grid)["k_x"].value
    for k in targets:
        nxt = designer.next_prints(cal, k=k, fixed=fixed, n=1)
        if np.any(np.abs(predicted / k - 1) <= 0.1):
            assert nxt.reachable, (k, nxt.statements)
            assert not any("out of reach" in s for s in nxt.statements), nxt.statements
        sug = designer.suggest(cal, k=k, fixed=fixed)
        if not sug.reachable:
            lo, hi = sug.ranges["k"]["predicted"]
            assert lo <= sug.candidates[0].predicted["k"].value <= hi


def test_the_stated_spread_holds_at_the_recommendation_on_mechanism_printers(study):
    """Where the user acts on it: on printers that depart from the study through a mechanism
    (tests/printers.py: a drawn truth, as rough between the study's runs as its cross-validation
    measures, with offsets, layer- and raster-dependent bonds and another infill together),
    after one print of `next`'s first recommendation, a print of the next recommendation (what P is
    about: the printer's truth with its print scatter) has a log k standardized error against the
    calibrated model's predictive t with an sd near 1, and the 95 % intervals cover."""
    z, inside = [], []
    for seed in range(24):
        printer = printers.Printer(500 + seed, mechanism="combined", drawn=True)
        k = float(np.geomspace(0.35, 1.3, 6)[seed % 6])
        first = designer.next_prints(study, k=k, n=1).recommendation.params
        runs = printer.prints(pd.DataFrame([first]), np.random.default_rng(seed))
        cal = designer.calibrate(study, runs)
        rec = designer.suggest(cal, k=k, top=1).candidates[0].params
        model = cal.model("k_x")
        p = cal.predict(pd.DataFrame([rec])[FACTORS])["k_x"].at(0)
        mu, s = math.log(p.value), (math.log(p.high) - math.log(p.value)) / model.t95
        measured = float(
            printer.prints(pd.DataFrame([rec]), np.random.default_rng(100 + seed))["k_x_N_per_mm"][0]
        )
        z.append((math.log(measured) - mu) / s)
        inside.append(p.low <= measured <= p.high)
    z = np.array(z)
    assert 0.6 < z.std() < 1.45 and abs(z.mean()) < 0.6, (z.std(), z.mean())
    assert np.mean(inside) >= 0.85, np.mean(inside)


def test_calibrate_reads_an_identify_table_with_its_text_columns(study, table, tmp_path):
    """identify's table carries the log's name beside the coefficients: calibrate uses the settings and
    the coefficients and leaves the text alone."""
    runs = _rows(table, [3, 12], scale=0.8).assign(log=["a.csv", "b.csv"])
    runs.to_csv(tmp_path / "runs.csv", index=False)
    cal = designer.calibrate(study, tmp_path / "runs.csv")
    assert cal.model("k_x").printer_factor().low < 0.8 < cal.model("k_x").printer_factor().high


def test_the_reports_leave_one_out_equals_recalibrating_without_each_run(study, table):
    """`report`'s leave-one-out over the user's runs is computed in closed form (one inversion; it
    recalibrated once per run before: 200 runs took 206 s in `designer calibrate`). Oracle: drop each
    run, calibrate on the rest, predict it as `Surrogate.predict` does (as printed: a 2 mm section
    solid), for runs of both responses, with a repeated design."""
    runs = _rows(table, [1, 5, 9, 14, 14, 22, 30], scale=0.8).reset_index(drop=True)
    runs.loc[2, "width"] = 2.0  # walls fill the section: printed solid whatever the infill
    cal = designer.calibrate(study, runs)
    rep = report(cal)
    for r in ("k_x", "c_x"):
        rows = runs.index[runs[r].notna()]
        held = cal.model(r).own_loo()
        for j, i in enumerate(rows):
            others = designer.calibrate(study, runs.drop(index=i))
            p = others.predict(runs.loc[[i], FACTORS])[r]
            assert np.allclose(
                [held.value[j], held.low[j], held.high[j]], [p.value[0], p.low[0], p.high[0]], rtol=1e-9
            )
        y = runs.loc[rows, r].to_numpy()
        errors = np.abs(held.value - y) / y
        assert rep["responses"][r]["loo_user"]["n"] == len(rows)
        assert rep["responses"][r]["loo_user"]["mape"] == pytest.approx(100 * np.median(errors))


def test_calibrate_refuses_more_runs_than_it_takes_before_any_work(tmp_path, capsys, table):
    """Issue 37, cause 6: 10 000 rows reached 7 GB of memory in 20 s with no estimate or limit. Now
    one line naming the count, the limit and the memory it would need; 2000 rows are calibrated."""
    from designer.model.calibration import MAX_RUNS

    many = table.sample(MAX_RUNS + 1, replace=True, random_state=0)[FACTORS + ["k_x", "c_x"]]
    path = tmp_path / "many.csv"
    many.to_csv(path, index=False)
    code, _, err = run_inprocess(["calibrate", path, "-o", tmp_path / "o.json"], capsys)
    assert_clean_failure(code, err, allowed=(2,))
    assert f"runs has {MAX_RUNS + 1} rows" in err and "designer fit" in err and "about 290 MiB" in err
    assert not (tmp_path / "o.json").exists()
    assert (
        designer.calibrate(Surrogate.load(), many.iloc[:MAX_RUNS]).calibration["table"].shape[0] == MAX_RUNS
    )
