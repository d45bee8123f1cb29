"""The rig pipeline: log schema and validation, virtual rig -> identification closed loop, cleaning."""

import json
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

from designer.chirp import Chirp
from designer.errors import DesignerError
from designer.mass import specimen_mass
from designer.rig.clean import clean
from designer.rig.identify import identify, results_table
from designer.rig.logs import read_log, sidecar_path, validate_frame, write_log
from designer.rig.simulate import simulate
from designer.study.data import load_table

FACTORS = {"density": 60, "length": 24, "width": 4.5, "height": 9, "layer": 0.16, "raster": 0}
CLI = [sys.executable, "-I", "-c", "from designer_cli.main import main; main()"]


def _cli(*args, **kw):
    return subprocess.run(CLI + [str(a) for a in args], capture_output=True, text=True, **kw)


@pytest.mark.parametrize(
    "k, c",
    [(0.246, 4.91e-4), (0.8, 2e-3), (2.09, 4.52e-3)],  # the bundled table's lowest, middle, highest k
)
def test_closed_loop_recovers_k_and_c_within_1_percent(k, c):
    df = simulate({"x": {"m": 0.001, "c": c, "k": k}}, duration=120, noise=0.01, dropouts=0.001, seed=7)
    assert df["Fx"].isna().any() and (df["Fx"] == 0).sum() >= 10  # dropouts of both kinds are present
    fit = identify(validate_frame(df, factors=FACTORS))[0].axes["x"]
    assert fit.k == pytest.approx(k, rel=0.01)
    assert fit.c == pytest.approx(c, rel=0.01)
    assert fit.r2 > 0.999 and 0 < fit.nrmse < 0.01
    # a gram-scale mass is not identifiable at the study's frequencies: say so, give the geometric mass
    assert not fit.m_identified and fit.m_se > 0
    assert fit.mass() == pytest.approx(specimen_mass(FACTORS))
    assert "not identifiable" in fit.statement() and "geometry" in fit.statement()


def test_strong_inertial_excitation_recovers_m_within_5_percent():
    df = simulate(
        {"x": {"m": 0.01, "c": 2e-3, "k": 0.8}}, duration=60, noise=0.01, dropouts=0.001, seed=3, f1=20
    )
    fit = identify(validate_frame(df))[0].axes["x"]
    assert fit.m_identified
    assert fit.m == pytest.approx(0.01, rel=0.05)
    assert fit.k == pytest.approx(0.8, rel=0.01)
    assert "identified" in fit.statement()


def test_chirp_derivatives_are_exact():
    chirp = Chirp(sweep=50.0)
    t = np.linspace(0, 50, 200001)
    q, dq, ddq = chirp.motion(t)
    assert np.abs(np.gradient(q, t) - dq)[10:-10].max() < 1e-4
    assert np.abs(np.gradient(dq, t) - ddq)[10:-10].max() < 1e-3
    # the instantaneous frequency sweeps 0.2 -> 1.85 Hz
    assert dq[0] == pytest.approx(2 * np.pi * 0.2)
    assert np.abs(dq[t > 49]).max() == pytest.approx(2 * np.pi * 1.85, rel=5e-3)


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_write_read_round_trip_six_axes(tmp_path, suffix):
    coef = {a: {"m": 0.0, "c": 1e-3, "k": 0.5} for a in ("x", "y", "z", "theta", "phi", "psi")}
    df = simulate(coef, duration=30, noise=0.0, dropouts=0.002, seed=1)
    path = write_log(df, tmp_path / f"run{suffix}", FACTORS)
    assert sidecar_path(path).exists()
    log = read_log(path)
    assert log.axes == ["x", "y", "z", "theta", "phi", "psi"]
    assert log.rate == pytest.approx(1000.0) and log.factors == {k: float(v) for k, v in FACTORS.items()}
    assert np.allclose(log.data["Fx"].fillna(-1), df["Fx"].fillna(-1), rtol=1e-12, atol=0)
    assert all(log.dropouts[a].any() for a in log.axes) and log.dropout_segments("x")
    res = identify(log)[0]
    assert res.axes["psi"].k == pytest.approx(0.5, rel=1e-3)
    table = results_table([res])
    assert list(table.columns[:8]) == [
        "density",
        "length",
        "width",
        "height",
        "layer",
        "raster",
        "c_x",
        "k_x",
    ]


def _log(**cols):
    t = np.arange(100) / 100.0
    base = {"t": t, "x": np.sin(t), "Fx": np.cos(t)}
    base.update(cols)
    return pd.DataFrame({k: v for k, v in base.items() if v is not None})


@pytest.mark.parametrize(
    "frame, words",
    [
        (_log(t=np.r_[np.arange(50), 49, np.arange(51, 100)] / 100.0), ["time repeated", "row 51"]),
        (_log(Fx=None), ["missing column 'Fx'"]),
        (_log(t=None), ["missing column 't'"]),
        (_log(Fx=np.full(100, np.nan)), ["'Fx'", "all NaN"]),
        (_log().rename(columns={"x": "x [in]"}), ["'x [in]'", "units"]),
        (_log().rename(columns={"Fx": "Fx_kN"}), ["'Fx_kN'", "units"]),
        (_log(x=["a"] + [0.1] * 99), ["'x' row 1"]),
    ],
)
def test_bad_logs_name_the_column_or_row(frame, words):
    with pytest.raises(DesignerError) as err:
        validate_frame(frame)
    for w in words:
        assert w in str(err.value)


def test_bad_log_exits_2_with_one_line(tmp_path):
    bad = _log(t=np.r_[np.arange(50), 49, np.arange(51, 100)] / 100.0)
    bad.to_csv(tmp_path / "bad.csv", index=False)
    out = _cli("identify", tmp_path / "bad.csv")
    assert out.returncode == 2
    assert out.stderr.count("\n") == 1 and "time repeated at row 51" in out.stderr
    assert "Traceback" not in out.stderr


def test_cli_simulate_identify_json_and_table(tmp_path):
    log = tmp_path / "log.csv"
    factors = [a for n, v in FACTORS.items() for a in (f"--{n}", v)]
    out = _cli(
        "rig",
        "simulate",
        "--k",
        0.8,
        "--c",
        2e-3,
        "--duration",
        60,
        "--dropouts",
        0.001,
        "--seed",
        1,
        *factors,
        "-o",
        log,
    )
    assert out.returncode == 0, out.stderr
    out = _cli("identify", log, "--json", "-o", tmp_path / "table.csv")
    assert out.returncode == 0, out.stderr
    doc = json.loads(out.stdout)
    x = doc["logs"][0]["axes"]["x"]
    assert doc["logs"][0]["path"] == str(log)
    assert (
        x["k"] == pytest.approx(0.8, rel=0.01) and x["c"] == pytest.approx(2e-3, rel=0.01) and x["r2"] > 0.999
    )
    table = load_table(tmp_path / "table.csv")
    assert table["k_x"].iloc[0] == pytest.approx(x["k"])


def test_clean_drops_sensor_failures_and_dbscan_noise_with_reasons():
    table = load_table()
    raw = table.copy()
    raw.loc[2, "c_x"] = np.nan
    raw.loc[5, "k_x"] = 0.0
    raw.loc[7, "k_x"] = 50.0  # far from every other run
    res = clean(raw)
    reasons = dict(zip(res.dropped["row"], res.dropped["reason"], strict=True))
    assert "c_x is NaN" in reasons[3] and "k_x is zero" in reasons[6]
    assert reasons[8].startswith("DBSCAN noise")
    assert len(res.table) + len(res.dropped) == len(raw)
    assert (res.table["k_x"] < 50).all()
    # looser clustering keeps every valid run but the far one
    loose = clean(raw, eps=3.0, min_samples=3)
    assert list(loose.dropped["row"]) == [3, 6, 8]


@pytest.mark.parametrize("f1, rate", [(900.0, 1000.0), (60.0, 500.0)])
def test_a_chirp_the_sampling_cannot_carry_is_refused(f1, rate):
    """Aliased (f1 above rate / 2) or too coarse to differentiate (under 10 samples per period)."""
    from designer.rig.simulate import simulate

    with pytest.raises(DesignerError, match="sampling theorem"):
        simulate({"x": {"m": 0.001, "c": 2e-3, "k": 0.8}}, duration=10.0, rate=rate, f1=f1)
    Chirp(f1=f1).check_sampling(10 * f1)  # 10 samples per period is enough


def test_a_rig_scenario_whose_step_aliases_the_chirp_is_refused(tmp_path):
    from pathlib import Path

    from designer import cosim

    text = (Path(__file__).parents[1] / "examples" / "rig.toml").read_text()
    bad = tmp_path / "rig.toml"
    bad.write_text(text.replace("f1 = 1.85", "f1 = 1e6", 1))
    with pytest.raises(DesignerError, match="aliased at 1 / step = 1000 Hz"):
        cosim.load(bad)
