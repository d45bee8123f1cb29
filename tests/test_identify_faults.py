"""Sensor and rig faults that a fit alone cannot tell from physics (issue 35), on logs written from the
physics by tests/physics_logs.py: each comes out within 1 % of the truth or named as the fault itself.

The README conditions: the study's middle x joint (k 0.8 N/mm, c 2e-3 N.s/mm, 1 g, 2 mm of motion),
0.2 % position noise, 2 % load noise, 60 s at 1 kHz.
"""

import json
import subprocess
import sys

import numpy as np
import pytest
from physics_logs import make_log

from designer.rig.identify import identify
from designer.rig.logs import validate_frame

CLI = [sys.executable, "-I", "-c", "from designer_cli.main import main; main()"]
X = {"k": 0.8, "c": 2e-3, "m": 1e-3, "amplitude": 2.0}
FACTORS = {"density": 60, "length": 24, "width": 4.5, "height": 9, "layer": 0.16, "raster": 0}


def _one(df):
    res = identify(df)[0]
    assert res.ok, res.failures
    return res


@pytest.mark.parametrize(
    "scale, unit",
    [
        ({"load_unit": 1e-3}, "Fx in kN under its N column (/1000)"),
        ({"position_unit": 1e-3}, "x in m under its mm column (x1000)"),
    ],
)
@pytest.mark.parametrize("factors", [None, FACTORS])
def test_a_load_in_kn_or_a_position_in_m_is_refused_naming_the_unit(scale, unit, factors):
    """It used to give k and c 1000x off with R2 1.0000 and no warning. With the specimen's factors the
    reference is the shipped surrogate's prediction for it, without them the study's range of k."""
    log = validate_frame(
        make_log({"x": X}, duration=60, rate=1000, seed=1, **scale), "run.csv", factors=factors
    )
    res = identify(log)[0]
    assert not res.ok
    reason = res.failures["x"]
    assert reason.startswith("implausible scale, a unit error") and f"likely {unit}" in reason
    assert ("shipped surrogate" in reason) == (factors is not None)


def test_the_cli_writes_no_row_for_a_log_in_kn(tmp_path):
    path = tmp_path / "kN.csv"
    make_log({"x": X}, duration=30, rate=500, seed=2, load_unit=1e-3).to_csv(path, index=False)
    path.with_suffix(".json").write_text(json.dumps({"factors": FACTORS}))
    out = subprocess.run(
        CLI + ["identify", str(path), "-o", str(tmp_path / "table.csv")], capture_output=True, text=True
    )
    assert out.returncode == 1 and not (tmp_path / "table.csv").exists(), out.stderr
    assert "FAILED x: implausible scale" in " ".join(out.stdout.split()) and "in kN" in out.stdout


def test_a_load_sensor_clipping_at_80_percent_of_its_peak_is_refused_as_saturated():
    """It used to be read as a softening spring (secant -20 %), k -7 % and c -8 %."""
    log = make_log({"x": X}, duration=60, rate=1000, seed=1, load_clip=0.8)
    reason = identify(log)[0].failures["x"]
    assert reason.startswith("the Fx sensor saturates: 36 % of its samples sit exactly at its rails")
    assert "softening" not in reason.split("refused")[0]


def test_a_sensor_touching_its_rail_now_and_then_is_named_and_those_samples_left_out():
    """At 97 % of the peak 0.2 % of the samples touch the rail: left out, the fit is the unclipped
    log's (the same noise) within 0.1 %."""
    res = _one(make_log({"x": X}, duration=60, rate=1000, seed=1, load_clip=0.97))
    fit, unclipped = res.axes["x"], _one(make_log({"x": X}, duration=60, rate=1000, seed=1)).axes["x"]
    assert any(
        "the Fx sensor saturates: 0.21 % of its samples" in w and "left out of the fit" in w
        for w in res.warnings
    )
    assert fit.k == pytest.approx(unclipped.k, rel=1e-3) and fit.c == pytest.approx(unclipped.c, rel=1e-3)
    assert fit.k == pytest.approx(X["k"], rel=0.01)


def test_crosstalk_from_the_other_axis_is_named_with_its_share_and_fitted_out():
    """2 % of y's load (its chirp 90 deg out of phase) in x's load sensor: it used to be read as
    viscoelastic damping with c +103 %."""
    axes = {"x": dict(X, crosstalk=("y", 0.02)), "y": dict(X, phase=90)}
    res = _one(make_log(axes, duration=60, rate=1000, seed=1))
    fit = res.axes["x"]
    assert fit.departure["name"] == "crosstalk" and fit.departure["from"] == "Fy"
    assert fit.departure["value"] == pytest.approx(0.02, rel=0.05)
    assert fit.departure["linear_c"] > 1.8 * X["c"]  # what the linear fit made of it
    assert fit.c == pytest.approx(X["c"], rel=0.01) and fit.k == pytest.approx(X["k"], rel=0.01)
    assert any(w.startswith("x: cross-talk: the load sensor of x reads 2 % ") for w in res.warnings)
    assert not any("viscoelastic" in w for w in res.warnings)
    assert res.axes["y"].departure is None  # the source axis is clean


def test_two_clean_axes_out_of_phase_stay_silent_over_20_seeds():
    """Two clean axes whose chirps are 90 deg apart: neither load is taken for the other's cross-talk."""
    for seed in range(20):
        res = _one(make_log({"x": X, "y": dict(X, phase=90)}, duration=40, rate=500, seed=300 + seed))
        assert res.warnings == [] and res.notes == [], (seed, res.warnings)


def test_backlash_is_named_with_its_play_not_a_stiffening_spring():
    """A dead band of 2 % of the amplitude, the encoder on the motor: it used to be read as a
    stiffening spring (+1.7 %) with k -1.3 %."""
    play = 0.02 * X["amplitude"]
    # seed 1000: benchmarks/identify_cases.py's first (over its 20 seeds c within 0.85 %, k within 0.06 %)
    res = _one(make_log({"x": dict(X, backlash=play)}, duration=60, rate=1000, seed=1000))
    fit = res.axes["x"]
    assert fit.departure["name"] == "backlash" and fit.departure["play"] == pytest.approx(play, rel=0.05)
    assert fit.k == pytest.approx(X["k"], rel=0.002)
    assert fit.c == pytest.approx(X["c"], rel=0.01)  # the damping stops inside the band too
    assert any(w.startswith("x: backlash: the drive has a dead band of 0.0") for w in res.warnings)
    assert not any("spring" in w for w in res.warnings)


def test_an_exponential_warm_up_is_sized_and_k_given_at_mid_run_within_1_percent():
    """k falling 5 % as 1 - exp(-t / 12 s) over a 60 s log: it used to be a linear drift of -13 %
    and k 0.741 N/mm, below any k the specimen had."""
    T, tau = 60.0, 12.0
    res = _one(make_log({"x": dict(X, drift=-0.05, drift_tau=tau)}, duration=T, rate=1000, seed=1))
    fit = res.axes["x"]
    dep = fit.departure
    assert dep["name"] == "drift" and dep["tau_s"] == pytest.approx(tau, rel=0.5)
    truth = np.exp(-T / tau) - 1  # k's change from start to end over its start value, over 0.05
    assert dep["change"] == pytest.approx(0.05 * truth, abs=0.003)
    assert fit.k == pytest.approx(X["k"] * (1 - 0.05 * (1 - np.exp(-T / 2 / tau))), rel=0.01)
    assert (
        "as a warm-up, settling like exp(-t / " in dep["text"] and "mid-run value (t = 30 s)" in dep["text"]
    )


def test_a_2_khz_log_on_a_1_ms_clock_is_rebuilt_from_the_sample_index_with_a_note(tmp_path):
    """Its timestamps repeat in pairs: it used to be refused ("remove repeated rows")."""
    log = make_log({"x": X}, duration=60, rate=2000, seed=1, time_resolution=1e-3)
    assert (np.diff(log["t"]) == 0).mean() > 0.4
    res = _one(log)
    fit = res.axes["x"]
    assert res.rate == pytest.approx(2000.0) and res.warnings == []
    assert res.notes == [
        "t is on a 0.001 s clock (60000 repeated timestamps): rebuilt from the sample index at 2000 Hz "
        "(the logged times lie in a band 1 clock steps wide about it)"
    ]
    assert fit.k == pytest.approx(X["k"], rel=0.01) and fit.c == pytest.approx(X["c"], rel=0.01)
    path = tmp_path / "coarse.csv"
    make_log({"x": X}, duration=30, rate=2000, seed=2, time_resolution=1e-3).to_csv(path, index=False)
    out = subprocess.run(CLI + ["identify", str(path)], capture_output=True, text=True)
    assert out.returncode == 0 and "note: t is on a 0.001 s clock" in " ".join(out.stdout.split()), out.stderr


def _number_after(text: str, key: str) -> float:
    """The number that follows `key` in a sentence (e.g. 'k = ')."""
    import re

    return float(re.search(re.escape(key) + r"(-?[0-9.]+(?:e-?[0-9]+)?)", text).group(1))


@pytest.mark.parametrize("column", ["x", "Fx"])
def test_a_flipped_sign_is_named_with_the_fit_it_would_give(column):
    """A sensor counting the other way used to be only "physically impossible fit: k = -0.8" (k and
    c negative, R2 1): the reason now names the opposite directions and the fit with one negated."""
    df = make_log({"x": X}, duration=60, rate=1000, seed=1)
    df[column] = -df[column]
    reason = identify(df)[0].failures["x"]
    assert "x and Fx count in opposite directions" in reason and "negate that column" in reason
    told = reason.split("with one of them negated the fit gives ")[1]
    assert _number_after(told, "k = ") == pytest.approx(X["k"], rel=0.01)
    assert _number_after(told, "c = ") == pytest.approx(X["c"], rel=0.02)
    assert "unit error" not in reason


def test_a_flipped_load_in_kn_is_named_as_both():
    df = make_log({"x": X}, duration=60, rate=1000, seed=1, load_unit=1e-3)
    df["Fx"] = -df["Fx"]
    reason = identify(df)[0].failures["x"]
    assert "count in opposite directions" in reason
    assert "negated, it is still an implausible scale, a unit error" in reason and "Fx in kN" in reason


def test_swapped_position_and_load_columns_are_named_with_the_fit_exchanged(tmp_path):
    """x holding the load and Fx the position used to be only "physically impossible fit: k = 1.25,
    c = -0.0031": a negative c is a lagging load or swapped columns, and the reason says both, with
    the fit the columns exchanged would give (and, from the CLI, the flags that give a delay)."""
    df = make_log({"x": X}, duration=60, rate=1000, seed=1).rename(columns={"x": "Fx", "Fx": "x"})
    reason = identify(df)[0].failures["x"]
    assert "the load lags the position by at least" in reason and "the columns are swapped" in reason
    told = reason.split("exchanged, the fit would give about ")[1]
    assert _number_after(told, "k = ") == pytest.approx(X["k"], rel=0.01)
    assert _number_after(told, "c = ") == pytest.approx(X["c"], rel=0.05)
    path = tmp_path / "swapped.csv"
    df.to_csv(path, index=False)
    out = subprocess.run(CLI + ["identify", str(path)], capture_output=True, text=True)
    text = " ".join(out.stdout.split())
    assert out.returncode == 1 and "give it as --load-delay or --load-filter" in text, out.stdout
    assert "load_filter" not in text and "load_delay_s" not in text


def _with_header(path, header: str, df) -> None:
    path.write_text(header + df.to_csv(index=False))


def test_a_logger_header_is_read_and_a_rate_it_states_checked_against_t(tmp_path):
    """A logger's '#' lines above the header row used to be taken for the header ("missing column
    't'"); a sampling rate stated there that the time column does not have is refused (exit 2) naming
    both, since c scales with the time base; a header that agrees, or states no sampling rate, is
    read and the log identified as without it."""
    df = make_log({"x": X}, duration=30, rate=1000, seed=3)
    plain = identify(df)[0].axes["x"]
    for name, header in [
        ("agrees", "# logger: bench-2\n# Sampling rate (Hz): 1000\n"),
        ("khz", "# fs = 1 kHz\n"),
        ("other_rate", "# strain rate: 0.5, operator: A\n"),
    ]:
        path = tmp_path / f"{name}.csv"
        _with_header(path, header, df)
        fit = _one(path).axes["x"]
        assert fit.k == pytest.approx(plain.k, rel=1e-9) and fit.c == pytest.approx(plain.c, rel=1e-9), name
    path = tmp_path / "disagrees.csv"
    _with_header(path, "# rig: bench-2, sample_rate_hz: 500\n", df)
    out = subprocess.run(
        CLI + ["identify", str(path), "-o", str(tmp_path / "t.csv")], capture_output=True, text=True
    )
    assert out.returncode == 2 and not (tmp_path / "t.csv").exists(), out.stderr
    text = " ".join(out.stderr.split())
    assert "the header states 500 Hz ('# rig: bench-2, sample_rate_hz: 500')" in text
    assert "sampled at 1000 Hz" in text and "Traceback" not in text


def test_a_log_under_other_column_names_is_told_the_names_it_has(tmp_path):
    """Parquet from another tool ('time', 'disp', 'force') used to get only "missing column 't'"."""
    path = tmp_path / "other.parquet"
    make_log({"x": X}, duration=10, rate=500, seed=1).rename(
        columns={"t": "time", "x": "disp", "Fx": "force"}
    ).to_parquet(path)
    with pytest.raises(Exception, match=r"missing column 't' \(its columns are 'time', 'disp', 'force'\)"):
        identify(path)


def _encoder_log(step: float, seed: int = 1):
    """The README log with its position read by an encoder of `step` mm (no noise below a step: an
    optical encoder's error is its rounding)."""
    df = make_log({"x": X}, duration=60, rate=1000, seed=seed, position_noise=0.0)
    df["x"] = np.round(df["x"] / step) * step
    return df


def test_a_coarse_encoder_reading_zero_is_no_dropout_but_a_stuck_one_is():
    """A 0.1 mm encoder reads 0 for 5 or more samples each time the motion crosses its middle count:
    those runs used to be flagged as a sensor stuck at zero (2 % of a 1 kHz log; at 0.2 mm the log
    failed on "dropouts ... fix the sensor or its wiring"). A run that jumps to 0 from afar still is."""
    df = _encoder_log(0.1)
    assert validate_frame(df).dropouts["x"].mean() == 0.0
    moving = int(np.argmax(np.abs(df["x"].to_numpy()) > 1.0))  # a row far from zero
    df.loc[moving : moving + 49, "x"] = 0.0
    flagged = validate_frame(df).dropouts["x"]
    assert flagged[moving : moving + 50].all() and flagged.sum() == 50


@pytest.mark.parametrize("step", [0.1, 0.05])
def test_a_coarse_encoder_is_named_not_taken_for_a_spring_and_its_bias_is_in_the_errors(step):
    """A linear joint read in 0.1 mm steps (20 to the 2 mm peak) used to be named a softening spring
    with k some 6-9 standard errors off; the quantizer's describing function sizes what the steps do.
    (Seeds 2 and 3: on seed 1 the load's noise alone puts c 3.3 standard errors off, unquantized.)"""
    for seed in (2, 3):
        res = _one(_encoder_log(step, seed))
        fit = res.axes["x"]
        assert fit.departure is None, fit.departure["text"]
        assert any(w.startswith(f"x: x is read in steps of {step:g} mm") for w in res.warnings), res.warnings
        assert not any("spring:" in w for w in res.warnings)
        assert abs(fit.k - X["k"]) < 2 * fit.k_se and abs(fit.c - X["c"]) < 2 * fit.c_se, (seed, fit.k, fit.c)


def test_an_encoder_of_a_few_steps_to_the_peak_is_refused_naming_it():
    reason = identify(_encoder_log(0.25))[0].failures["x"]
    assert reason.startswith("x is read in steps of 0.25 mm, only 8 to the motion's peak of 2 mm")


def test_an_analogue_position_has_no_encoder():
    assert _one(make_log({"x": X}, duration=60, rate=1000, seed=1)).axes["x"].encoder is None


def test_backlash_read_by_a_coarse_encoder_is_still_backlash():
    """A dead band about one step wide is no artefact of the steps (the encoder alone makes one of
    under a tenth of a step): named, and k within 1 %."""
    df = make_log({"x": dict(X, backlash=0.1)}, duration=60, rate=1000, seed=2, position_noise=0.0)
    df["x"] = np.round(df["x"] / 0.1) * 0.1
    fit = _one(df).axes["x"]
    assert fit.departure["name"] == "backlash" and fit.departure["play"] == pytest.approx(0.1, rel=0.15)
    assert fit.k == pytest.approx(X["k"], rel=0.01)


@pytest.mark.parametrize(
    "column, course, size",
    [
        ("x", lambda t: 1.0 * (1 - np.exp(-t / 10)), 1.0),  # a displacement sensor warming up: 1 mm
        ("x", lambda t: 0.5 * np.sin(2 * np.pi * t / 45) + 0.3 * np.sin(2 * np.pi * t / 17), 1.0),
        ("Fx", lambda t: 0.5 * (1 - np.exp(-t / 10)), 0.5),  # a load cell's zero creeping: 0.5 N
    ],
)
def test_a_sensor_offset_drifting_below_the_band_is_named_and_filtered_out(column, course, size):
    """An offset that drifts along a curve (the fit models a constant and a straight line) stays in
    one channel: it gave k 4-45 % low with no warning, or "k drifts as a warm-up" (a material's
    name). Now the column is named and both channels are high-passed alike below the band."""
    df = make_log({"x": X}, duration=60, rate=1000, seed=2)
    df[column] = df[column] + course(df["t"].to_numpy())
    res = _one(df)
    fit = res.axes["x"]
    assert fit.sensor_drift["column"] == column and fit.departure is None
    assert any(
        w.startswith(f"x: the offset of '{column}' drifts below the excitation band") for w in res.warnings
    )
    assert not any("k drifts" in w for w in res.warnings)
    assert abs(fit.k - X["k"]) < 2 * fit.k_se and fit.k == pytest.approx(X["k"], rel=0.01)
    assert abs(fit.c - X["c"]) < 2 * fit.c_se and fit.c == pytest.approx(X["c"], rel=0.05)
    assert 0.2 * size < fit.sensor_drift["span"] < 2 * size


def test_a_k_warming_up_is_no_sensor_drift():
    """A drift of the joint's own k leaves its residual at the motion's frequencies, not below."""
    res = _one(make_log({"x": dict(X, drift=-0.05, drift_tau=12.0)}, duration=60, rate=1000, seed=1))
    assert res.axes["x"].sensor_drift is None and res.axes["x"].departure["name"] == "drift"


def test_a_still_axis_on_an_encoder_flickering_by_a_count_is_still_not_too_coarse():
    df = make_log({"x": X, "y": dict(X, still=True)}, duration=30, rate=500, seed=1)
    df["y"] = np.round(np.random.default_rng(0).normal(0, 0.004, len(df)) / 0.01) * 0.01
    res = _one(df)
    assert list(res.axes) == ["x"] and "y" in res.still and not res.failures


def test_rows_a_logger_dropped_are_noted_with_where_and_how_many():
    """300 ms of rows missing used to pass without a word (k and c right, the user never told)."""
    df = make_log({"x": X}, duration=60, rate=1000, seed=1)
    t = df["t"].to_numpy()
    res = _one(df[(t < 20.0) | (t >= 20.3)].reset_index(drop=True))
    assert res.notes == [
        "t has 1 gap (the longest 0.301 s, after row 20000; about 300 samples missing): the rows around "
        "each are left out of the fit"
    ]
    assert res.warnings == [] and res.axes["x"].k == pytest.approx(X["k"], rel=0.01)


def test_a_fine_encoder_moves_the_errors_but_warns_of_nothing():
    """4096 counts a turn on the README log's 2 mm as 0.3 rad (197 steps to the peak) bias k by at
    most 0.014 %, about one standard error: in k's error, not worth a warning (it warned before)."""
    df = make_log({"theta": dict(X, k=50.0, c=0.1, m=1e-7, amplitude=0.3)}, duration=60, rate=1000, seed=3)
    step = 2 * np.pi / 4096
    df["theta"] = np.round(df["theta"] / step) * step
    res = _one(df)
    assert res.warnings == [] and res.axes["theta"].encoder["steps_to_peak"] == pytest.approx(196, abs=2)
