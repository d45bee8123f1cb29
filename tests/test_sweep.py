"""Design sweeps: predictive draws, specs, limits, FMU vs in-engine paths against physics, resume."""

import dataclasses
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from designer import DesignerError, Surrogate, cosim, sweep
from designer.sweep.draws import draw
from designer.sweep.executors import SerialExecutor
from designer.sweep.limits import parse_limit
from designer.sweep.spec import Cases, Spec, with_duration

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
DESIGN = {"density": 60, "length": 24, "width": 4.5, "height": 9, "layer": 0.16, "raster": 45}
#: the one-link example's inertia about its hinge, from its MJCF numbers: Izz + m d^2 (kg.m^2)
J_ONE_LINK = 3.75e-4 + 0.2 * 0.075**2


def _without_wall(frame: pd.DataFrame) -> pd.DataFrame:
    return frame.drop(columns=["wall_s"])


def test_draws_follow_the_prediction_interval():
    """95 % of the draws fall inside the surrogate's 95 % PI; the quantiles are its ends (log form k_x)."""
    sur = Surrogate.load()
    rng = np.random.default_rng(3)
    for response in ("k_x", "c_x"):
        pred = sur.predict(DESIGN, responses=[response])[response]
        values = draw(sur.model(response), DESIGN, n=100_000, rng=rng)
        assert np.all(values > 0)
        inside = np.mean((values >= pred.low[0]) & (values <= pred.high[0]))
        if response == "k_x":  # power law: exponentiated t, nothing truncated
            assert inside == pytest.approx(0.95, abs=0.003)
            lo, hi = np.quantile(values, [0.025, 0.975])
            assert lo == pytest.approx(pred.low[0], rel=0.01)
            assert hi == pytest.approx(pred.high[0], rel=0.01)
            assert np.median(values) == pytest.approx(pred.value[0], rel=0.005)
        else:  # raw mean form: about 1 % of the t lies below zero and is redrawn
            assert 0.95 < inside < 0.965


@pytest.mark.parametrize(
    "text, metric, op, value",
    [("overshoot<=5%", "overshoot_pct", "<=", 5.0), ("settling_time <= 0.3 s", "settling_time_s", "<=", 0.3)],
)
def test_parse_limit(text, metric, op, value):
    limit = parse_limit(text)
    assert (limit.metric, limit.op, limit.value) == (metric, op, value)


@pytest.mark.parametrize("text", ["overshoot<5", "speed<=3", "overshoot<=5s", "overshoot<=nan"])
def test_bad_limits(text):
    with pytest.raises(DesignerError):
        parse_limit(text)


def _spec(tmp_path: Path, body: str) -> Path:
    path = tmp_path / "sweep.toml"
    path.write_text(f'scenario = "{EXAMPLES / "tune_one_link.toml"}"\n{body}')
    return path


@pytest.mark.parametrize(
    "body, words",
    [
        ('[cases]\ntype = "lattice"', "type"),
        ('[cases]\ntype = "grid"\n[cases.joints.j9]\nk = [1, 2]', "j9"),
        ('[cases]\ntype = "montecarlo"', "number of draws"),
        ('[cases]\ntype = "montecarlo"\nn = 5', "print settings"),
        ('[sweep]\npath = "gpu"\n[cases]\ntype = "grid"\n[cases.joints.j1]\nk = [1]', "path"),
        ('[cases]\ntype = "grid"\n[cases.joints.j1]\nk = [1]\nwidth = [3]', "not both"),
    ],
)
def test_bad_specs(tmp_path, body, words):
    with pytest.raises(DesignerError, match=words):
        spec = sweep.load(_spec(tmp_path, body))
        sweep.make_cases(spec)


def _critical_grid(tmp_path: Path) -> sweep.Spec:
    body = (
        '[sweep]\nduration = 0.5\n[cases]\ntype = "grid"\n[cases.joints.j1]\nk = [300, 1e8]\nc = [6.0, 21.2]'
    )
    return sweep.load(_spec(tmp_path, body))


def test_fmu_and_engine_paths_agree_with_the_analytic_step_response(tmp_path):
    """Overshoot of an underdamped link is exp(-pi zeta / sqrt(1 - zeta^2)); a diverging case fails alone."""
    spec = _critical_grid(tmp_path)
    fmu = sweep.run(spec, executor=SerialExecutor())
    engine = sweep.run(dataclasses.replace(spec, path="engine", check=2), executor=SerialExecutor())
    for result in (fmu, engine):
        t = result.table
        assert list(t["status"]) == ["ok", "ok", "failed", "failed"]
        assert all("diverged" in m for m in t["message"][2:])
        for i in (0, 1):
            zeta = t.loc[i, "j1.c"] * 1e-3 / (2 * math.sqrt(t.loc[i, "j1.k"] * 1e-3 * J_ONE_LINK))
            analytic = 100 * math.exp(-math.pi * zeta / math.sqrt(1 - zeta**2))
            # semi-implicit Euler at h omega = 0.007 adds about h omega / 2 to zeta
            assert t.loc[i, "j1.overshoot_pct"] == pytest.approx(analytic, abs=1.0)
    metrics = [c for c in fmu.table.columns if c.startswith("j1.") and c not in ("j1.k", "j1.c")]
    np.testing.assert_allclose(
        fmu.table[metrics].iloc[:2].to_numpy(float),
        engine.table[metrics].iloc[:2].to_numpy(float),
        atol=1e-12,
    )
    check = engine.summary["engine_check"]
    assert check["max_angle_difference_rad"] < 1e-12 and len(check["cases"]) == 2


def test_rerun_skips_finished_cases(tmp_path):
    """A journal cut mid-line (an interrupted run) is resumed: finished cases are not run again."""
    spec = dataclasses.replace(_critical_grid(tmp_path), path="engine", check=0)
    journal = tmp_path / "cases.jsonl"
    first = sweep.run(spec, executor=SerialExecutor(), journal=journal)
    ok = [line for line in journal.read_text().splitlines() if '"status": "ok"' in line]
    journal.write_text(ok[0] + "\n" + ok[1][: len(ok[1]) // 2])  # as if killed while writing
    again = sweep.run(spec, executor=SerialExecutor(), journal=journal)
    assert again.resumed == 1  # the whole line; the torn one and the failed cases run again
    pd.testing.assert_frame_equal(_without_wall(first.table), _without_wall(again.table))
    third = sweep.run(spec, executor=SerialExecutor(), journal=journal)
    assert third.resumed == 2


def test_grid_over_print_settings_goes_through_the_surrogate(tmp_path):
    body = (
        '[sweep]\nduration = 0.05\n[cases]\ntype = "grid"\n'
        f"[cases.designs.j1]\n{_toml(DESIGN)}\n[cases.joints.j1]\nheight = [4, 14]\n"
    )
    spec = sweep.load(_spec(tmp_path, body))
    cases = sweep.make_cases(spec)
    sur = Surrogate.load()
    for case, h in zip(cases, (4, 14), strict=True):
        k_x = sur.predict(DESIGN | {"height": h}, responses=["k_x"])["k_x"].value[0]
        assert case.coefficients["j1"]["k"] == pytest.approx(k_x * (0.85 * 24) ** 2, rel=1e-12)
        assert case.inputs == {"j1.height": h}


def _toml(d: dict) -> str:
    return "\n".join(f"{k} = {v}" for k, v in d.items())


def _cli(*args: str) -> subprocess.CompletedProcess:
    code = "import sys; from designer_cli.main import main; sys.argv[0] = 'designer'; main()"
    return subprocess.run([sys.executable, "-I", "-c", code, *map(str, args)], capture_output=True, text=True)


def test_example_monte_carlo_sweep_cli(tmp_path):
    """examples/sweep_arm.toml: 200 draws, 5/50/95 % percentiles, the engine path checked against the FMUs."""
    out = tmp_path / "mc"
    args = ("sweep", EXAMPLES / "sweep_arm.toml", "-o", out, "--workers", "1", "--json")
    run = _cli(*args)
    assert run.returncode == 0, run.stderr
    summary = json.loads(run.stdout)
    assert summary["cases"] == summary["ok"] == 200
    p = summary["percentiles"]["j2.overshoot_pct"]
    assert p["n"] == 200 and 0 < p["p5"] < p["p50"] < p["p95"]
    assert summary["engine_check"]["max_angle_difference_rad"] < 1e-9
    table = pd.read_parquet(out / "results.parquet")
    meets = (table["j2.overshoot_pct"] <= 40) & (table["j1.tracking_rms_rad"] <= 0.12)
    meets &= table["j2.tracking_rms_rad"] <= 0.12  # j1 follows a sine: overshoot is not defined for it
    assert summary["share_meeting_all"] == pytest.approx(meets.mean())
    assert len(table) == 200 and {"j1.k", "j2.c", "j1.k_x", "status", "wall_s"} <= set(table.columns)
    assert np.percentile(table["j2.overshoot_pct"], 50) == pytest.approx(p["p50"])
    assert (out / "metrics.png").stat().st_size > 10_000
    again = sweep.make_cases(sweep.load(EXAMPLES / "sweep_arm.toml"))  # seeded: the same draws
    assert [c.key for c in again] == table["key"].tolist()


def test_tune_finds_critical_damping(tmp_path):
    """Fastest settling without overshoot is critical damping: c within 2 % of 2 sqrt(k J)."""
    out = tmp_path / "tuned.json"
    args = ["tune", str(EXAMPLES / "tune_one_link.toml"), "--objective", "settling_time"]
    args += ["--limit", "overshoot<=0%", "--bounds", "j1.k=200:600", "--bounds", "j1.c=5:150"]
    args += ["--robustness", "10", "--workers", "1", "-o", str(out), "--json"]
    run = _cli(*args)
    assert run.returncode == 0, run.stderr
    tuned = json.loads(out.read_text())
    k, c = tuned["joints"]["j1"]["k"] * 1e-3, tuned["joints"]["j1"]["c"] * 1e-3
    assert c == pytest.approx(2 * math.sqrt(k * J_ONE_LINK), rel=0.02)
    assert tuned["feasible"] and tuned["metrics"]["j1.overshoot_pct"] == 0.0
    assert tuned["fmu_check"]["status"] == "ok"
    assert max(tuned["fmu_check"]["max_metric_difference"].values()) < 1e-9
    design = tuned["designs"]["j1"]
    assert design["candidates"] and design["fixed"] == {"length": 24.0}
    assert tuned["robustness"]["cases"] == 10


def test_cli_bad_input_is_one_line(tmp_path):
    from designer_cli.sweep import _parse_bounds

    run = _cli("tune", EXAMPLES / "tune_one_link.toml", "--bounds", "j1.k=200:600", "--limit", "speed<=3")
    assert run.returncode == 2, run.stderr
    assert run.stderr.startswith("error:") and len(run.stderr.strip().splitlines()) == 1
    for bad in ("j1.k=abc", "j1.m=1:2", "k=1:2"):
        with pytest.raises(DesignerError, match="--bounds"):
            _parse_bounds([bad])
    assert _parse_bounds(["j1.c=5:150"]) == {"j1.c": (5.0, 150.0)}


def test_spec_in_code_and_scenario_duration():
    sc = cosim.load(EXAMPLES / "tune_one_link.toml")
    spec = sweep.spec.check(
        Spec(scenario=with_duration(sc, 0.05), cases=Cases(type="grid", joints={"j1": {"c": [1.0]}}))
    )
    result = sweep.run(spec, executor=SerialExecutor())
    assert result.table["status"].tolist() == ["ok"] and result.table["j1.k"][0] == 300


def test_rig_sweep_identifies_each_case(tmp_path):
    """Each case a virtual rig run whose log is identified: k and c come back from the log."""
    path = tmp_path / "rig_sweep.toml"
    # the whole 20 s sweep: identification fails a log with under 10 cycles of excitation
    path.write_text(
        f'scenario = "{EXAMPLES / "rig.toml"}"\n[sweep]\nduration = 20.0\n'
        '[cases]\ntype = "grid"\n[cases.joints.rig]\nk = [200, 400]\n'
    )
    result = sweep.run(sweep.load(path), executor=SerialExecutor())
    t = result.table
    assert (t["status"] == "ok").all() and list(t["rig.k"]) == [200, 400]
    assert np.all(np.abs(t["rig.k_error_pct"]) < 0.1) and np.all(np.abs(t["rig.c_error_pct"]) < 0.5)
    np.testing.assert_allclose(t["rig.k_identified"], [200, 400], rtol=5e-3)
    assert result.summary["units"]["rig.k_identified"] == "N.mm/rad"
    with pytest.raises(DesignerError, match="rig"):
        sweep.spec.check(dataclasses.replace(result.spec, path="engine"))


def test_suggestion_cases_are_the_candidates(tmp_path):
    """Every combination of candidates over the joints, each joint as Joint.from_suggestion gives it."""
    from designer import Joint

    path = tmp_path / "s.toml"
    path.write_text(
        f'scenario = "{EXAMPLES / "two_link_arm.toml"}"\n[cases]\ntype = "suggestion"\n'
        f'file = "{EXAMPLES / "suggestion.json"}"\njoints = ["j1", "j2"]\ncandidates = [1, 2]\n'
    )
    cases = sweep.make_cases(sweep.load(path))
    assert [(c.inputs["j1.candidate"], c.inputs["j2.candidate"]) for c in cases] == [
        (1, 1),
        (1, 2),
        (2, 1),
        (2, 2),
    ]
    for case in cases:
        for j in ("j1", "j2"):
            joint = Joint.from_suggestion(
                EXAMPLES / "suggestion.json", candidate=int(case.inputs[f"{j}.candidate"]), axes=["theta"]
            )
            assert case.coefficients[j] == {"k": joint.axis("theta").k, "c": joint.axis("theta").c}
    assert len({c.key for c in cases}) == 4


def test_tune_on_the_fmu_path(monkeypatch):
    """Every evaluation co-simulated with the FMUs, all generations through one prepared Session;
    the limit holds at the optimum found."""
    from designer.sweep import evaluate
    from designer.sweep.tune import tune

    real, prepared = cosim.prepare, []
    monkeypatch.setattr(cosim, "prepare", lambda sc: prepared.append(sc) or real(sc))
    sc = with_duration(cosim.load(EXAMPLES / "tune_one_link.toml"), 0.3)
    result = tune(
        sc,
        objective="tracking_rms",
        limits=[parse_limit("overshoot<=20%")],
        bounds={"j1.k": (200, 600), "j1.c": (5, 150)},
        path="fmu",
        executor=SerialExecutor(),
        maxiter=2,
        popsize=3,
        robustness=0,
    )
    assert result.evaluations == 18 and result.fmu_check is None
    assert len(prepared) == 1 and not evaluate._HELD  # one Session, closed at the end
    assert result.feasible and result.metrics["j1.overshoot_pct"] <= 20
    assert 200 <= result.coefficients["j1"]["k"] <= 600 and result.designs["j1"]["candidates"]


def test_reachable_range_holds_every_printable_design():
    """Default tune bounds: every design in the tested ranges predicts k and c inside them (theta via PRB)."""
    from designer.study import space
    from designer.sweep.tune import reachable

    sur = Surrogate.load()
    box = reachable(sur, "theta")
    rng = np.random.default_rng(5)
    designs = {f.name: rng.uniform(f.low, f.high, 300) for f in space.FACTORS if not f.categorical}
    designs |= {f.name: rng.choice(f.levels, 300) for f in space.FACTORS if f.categorical}
    pred = sur.predict(designs, responses=["k_x", "c_x"])
    scale = (0.85 * designs["length"]) ** 2
    k, c_low, c_high = pred["k_x"].value * scale, pred["c_x"].low * scale, pred["c_x"].high * scale
    assert box["k"][0] <= k.min() and k.max() <= box["k"][1] * (1 + 1e-9)
    assert box["c"][0] <= c_low.min() and c_high.max() <= box["c"][1] * (1 + 1e-9)  # c: its PI envelope
