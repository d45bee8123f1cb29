"""Issue 26's campaign, in-process classes: tables with decimal commas, BOM, CRLF, odd encodings,
1e308, subnormal and negative-zero values, duplicated columns; hand-edited suggestion JSON and
scenario / sweep TOML with wrong types or nested tables; aliased chirps; unreachable targets; and the
Python API called with wrong types. (Signals and the file system run as real processes in
tests/test_cli_interrupts.py and tests/test_files_hostile.py.)

Every bad input: exit 1 or 2, one line for 2, no traceback, nothing written or left. Every valid one
(BOM, CRLF, -0.0, blank lines): exit 0 and the same answer as the plain file."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from clitools import assert_clean_failure, bundled_table, enter_workdir, run_inprocess, run_process, snapshot
from test_cli_campaign import SIX, K

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _tables(good: pd.DataFrame) -> tuple[dict[str, bytes], dict[str, bytes]]:
    """(valid variants of the bundled table, invalid ones) as file bytes, written from the descriptions
    of issue 26 (not from the reader's code)."""
    text = good.to_csv(index=False)
    lines = text.splitlines()

    def cell(col: str, row: int, value) -> bytes:
        t = good.copy()
        t[col] = t[col].astype(object)
        t.loc[row, col] = value
        return t.to_csv(index=False).encode()

    valid = {
        "bom.csv": ("\ufeff" + text).encode(),
        "crlf.csv": text.replace("\n", "\r\n").encode(),
        "bom_crlf.csv": ("\ufeff" + text.replace("\n", "\r\n")).encode(),
        "cr_only.csv": text.replace("\n", "\r").encode(),
        "mixed_eol.csv": "".join(ln + ("\r\n" if i % 2 else "\n") for i, ln in enumerate(lines)).encode(),
        "negzero_raster.csv": good.assign(raster=good["raster"].where(good["raster"] != 0, -0.0))
        .to_csv(index=False)
        .encode(),
        "blank_lines.csv": (text + "\n\n\n").encode(),
        "spaces.csv": "\n".join(", ".join(ln.split(",")) for ln in lines).encode(),
    }
    invalid = {
        "deccomma_semicolon.csv": good.to_csv(sep=";", decimal=",", index=False).encode(),
        "deccomma_quoted.csv": good.to_csv(decimal=",", index=False).encode(),
        "latin1.csv": ("# Prüfung\n" + text).encode("latin-1"),
        "utf16.csv": text.encode("utf-16"),
        "nul.csv": text.replace("\n", "\n\0", 1).encode(),
        "k_inf.csv": cell("k_x", 1, np.inf),
        "c_neginf.csv": cell("c_x", 1, -np.inf),
        "k_1e999.csv": cell("k_x", 1, "1e999"),
        "width_1e308.csv": cell("width", 1, 1e308),
        "length_1e308.csv": cell("length", 3, 1e308),
        "density_subnormal.csv": cell("density", 1, 5e-324),
        "c_subnormal.csv": cell("c_x", 1, 5e-324),
        "k_negzero.csv": cell("k_x", 2, -0.0),
        "width_negzero.csv": cell("width", 2, -0.0),
        "dup_factor.csv": ("\n".join([lines[0] + ",width"] + [r + ",5" for r in lines[1:]]) + "\n").encode(),
        "dup_c.csv": ("\n".join([lines[0] + ",c_x"] + [r + ",0.002" for r in lines[1:]]) + "\n").encode(),
        "k_nan_text.csv": cell("k_x", 0, "NaN"),
        "k_word.csv": cell("k_x", 5, "stiff"),
        "header_bom_only.csv": ("\ufeff" + lines[0] + "\r\n").encode(),
    }
    return valid, invalid


TABLE_COMMANDS = {
    "fit": lambda t: ["fit", "--data", t, "--json"],
    "analyze": lambda t: ["analyze", "--data", t, "--json"],
    "doe --augment": lambda t: ["doe", "--augment", "2", "--data", t, "--json"],
    "clean": lambda t: ["clean", t, "--max-drop", "1", "--json"],
}
VALID_TABLES, INVALID_TABLES = _tables(bundled_table())


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    folder = tmp_path_factory.mktemp("hostile_inputs")
    bundled_table().to_csv(folder / "good.csv", index=False)
    for name, data in {**VALID_TABLES, **INVALID_TABLES}.items():
        (folder / name).write_bytes(data)
    _write_suggestions(folder)
    _write_scenarios(folder)
    _write_sweeps(folder)
    return folder


@pytest.fixture()
def workdir(tmp_path, inputs, monkeypatch):
    return enter_workdir(tmp_path, inputs, monkeypatch)


def _bad(args, workdir, inputs, capsys, allowed=(1, 2)) -> str:
    before = snapshot(workdir, inputs)
    code, out, err = run_inprocess(args, capsys)
    assert_clean_failure(code, err, allowed)
    assert snapshot(workdir, inputs) == before, "a file was written or left behind"
    return err


# --- tables -------------------------------------------------------------------------------------


#: for `clean`, a NaN or zero coefficient is a sensor dropout to drop (its purpose), not bad input
DROPOUTS = {"k_nan_text.csv", "k_negzero.csv"}


@pytest.mark.parametrize("name", sorted(INVALID_TABLES))
@pytest.mark.parametrize("command", sorted(TABLE_COMMANDS))
def test_invalid_table(command, name, workdir, inputs, capsys):
    if command == "clean" and name in DROPOUTS:
        code, out, err = run_inprocess(TABLE_COMMANDS[command](f"in/{name}"), capsys)
        assert code == 0, err
        dropped = json.loads(out)["dropped"]
        assert any("sensor failure" in d["reason"] for d in dropped), dropped
        return
    _bad(TABLE_COMMANDS[command](f"in/{name}"), workdir, inputs, capsys, allowed=(2,))


def test_table_messages_say_what_is_wrong(workdir, inputs, capsys):
    expect = {
        "deccomma_semicolon.csv": "separated by semicolons",
        "deccomma_quoted.csv": "a decimal comma",
        "latin1.csv": "not UTF-8 text",
        "utf16.csv": "UTF-16",
        "width_1e308.csv": "build volume",
        "density_subnormal.csv": "cannot be printed",
        "c_subnormal.csv": "outside what a printed joint can have",
        "k_negzero.csv": "k_x",
        "dup_factor.csv": "'width' appears twice",
        "k_inf.csv": "not a finite number",
    }
    for name, text in expect.items():
        err = _bad(["fit", "--data", f"in/{name}"], workdir, inputs, capsys, allowed=(2,))
        assert text in err, (name, err)


@pytest.mark.parametrize("name", sorted(VALID_TABLES))
def test_valid_table_variants_give_the_plain_tables_answer(name, workdir, capsys):
    """BOM, CRLF, CR, blank lines, spaces after commas, -0.0 for raster 0: the same analysis, exit 0."""
    code, out, err = run_inprocess(["analyze", "--data", "in/good.csv", "--json"], capsys)
    assert code == 0, err
    plain = json.loads(out)
    code, out, err = run_inprocess(["analyze", "--data", f"in/{name}", "--json"], capsys)
    assert code == 0, err
    assert json.loads(out) == plain


# --- suggestion files ---------------------------------------------------------------------------


def _write_suggestions(folder: Path) -> None:
    good = json.loads((EXAMPLES / "suggestion.json").read_text())
    cand = good["candidates"][0]

    def with_cand(**change):
        return {**good, "candidates": [{**cand, **change}]}

    def with_param(name, value):
        return with_cand(params={**cand["params"], name: value})

    docs = {
        "axis_number": {**good, "axis": 3},
        "axis_null": {**good, "axis": None},
        "axis_list": {**good, "axis": ["x"]},
        "cands_text": {**good, "candidates": "x"},
        "cands_dict": {**good, "candidates": {"1": cand}},
        "cands_number": {**good, "candidates": [3]},
        "cands_nested": {**good, "candidates": [[cand]]},
        "params_list": with_cand(params=list(cand["params"].values())),
        "params_text": with_cand(params="density=60"),
        "density_text": with_param("density", "60"),
        "density_bool": with_param("density", True),
        "density_table": with_param("density", {"value": 60}),
        "density_null": with_param("density", None),
        "density_list": with_param("density", [60]),
        "width_1e308": with_param("width", 1e308),
        "width_negzero": with_param("width", -0.0),
        "predicted_text": with_cand(predicted="k=0.8"),
        "predicted_k_text": with_cand(predicted={**cand["predicted"], "k": "0.8"}),
        "predicted_k_list": with_cand(predicted={**cand["predicted"], "k": [0.8]}),
        "predicted_value_text": with_cand(predicted={**cand["predicted"], "k": {"value": "big"}}),
        "predicted_value_neg": with_cand(
            predicted={**cand["predicted"], "k": {**cand["predicted"]["k"], "value": -0.8}}
        ),
        "predicted_value_inf": with_cand(
            predicted={**cand["predicted"], "k": {**cand["predicted"]["k"], "value": 1e308}}
        ),
        "targets_list": {**good, "targets": [0.8]},
        "nested_doc": {"suggestion": good},
        "top_number": 3,
        "top_string": "suggestion",
    }
    for name, doc in docs.items():
        (folder / f"sj_{name}.json").write_text(json.dumps(doc))
    (folder / "sj_nan.json").write_text(json.dumps(with_param("width", 4.5)).replace("4.5", "NaN", 1))
    (folder / "sj_bom.json").write_bytes(b"\xef\xbb\xbf" + json.dumps(good).encode())


SUGGESTIONS = sorted(
    [
        "axis_number",
        "axis_null",
        "axis_list",
        "cands_text",
        "cands_dict",
        "cands_number",
        "cands_nested",
        "params_list",
        "params_text",
        "density_text",
        "density_bool",
        "density_table",
        "density_null",
        "density_list",
        "width_1e308",
        "width_negzero",
        "predicted_text",
        "predicted_k_text",
        "predicted_k_list",
        "predicted_value_text",
        "predicted_value_neg",
        "predicted_value_inf",
        "targets_list",
        "nested_doc",
        "top_number",
        "top_string",
        "nan",
    ]
)


@pytest.mark.parametrize("name", SUGGESTIONS)
@pytest.mark.parametrize("fmt", ["fmu", "mjcf"])
def test_hand_edited_suggestion(fmt, name, workdir, inputs, capsys):
    _bad(["export", fmt, "--from", f"in/sj_{name}.json"], workdir, inputs, capsys, allowed=(2,))


def test_a_suggestion_saved_with_a_bom_is_read(workdir, capsys):
    code, out, err = run_inprocess(["export", "fmu", "--from", "in/sj_bom.json", "-o", "j.fmu"], capsys)
    assert code == 0 and (workdir / "j.fmu").is_file(), err


# --- scenario and sweep files --------------------------------------------------------------------

ARM = """[simulation]
duration = {duration}
step = {step}
[robot]
model = "{model}"
[joints.j1]
axis = {axis}
coefficients = {coefficients}
reference = {reference}
"""
ARM_GOOD = dict(
    duration="0.2",
    step="1e-3",
    model=str(EXAMPLES / "one_link.xml"),
    axis='"theta"',
    coefficients="{ k = 300, c = 20 }",
    reference='{ type = "step", amplitude = 0.5, at = 0.02 }',
)
RIG = """[simulation]
duration = 2.0
step = 1e-3
[rig]
amplitude = {amplitude}
f0 = {f0}
f1 = {f1}
sweep = {sweep}
joint = {{ axis = "theta", coefficients = {{ k = 330, c = 0.83, m = 2e-6 }} }}
"""
RIG_GOOD = dict(amplitude="1.0", f0="0.2", f1="1.85", sweep="2.0")
SCENARIOS = {
    "duration_text": ("arm", {"duration": '"5"'}),
    "duration_bool": ("arm", {"duration": "true"}),
    "duration_list": ("arm", {"duration": "[1.0]"}),
    "duration_table": ("arm", {"duration": "{ value = 1.0 }"}),
    "duration_date": ("arm", {"duration": "1979-05-27"}),
    "duration_nan": ("arm", {"duration": "nan"}),
    "duration_inf": ("arm", {"duration": "inf"}),
    "duration_negzero": ("arm", {"duration": "-0.0"}),
    "step_text": ("arm", {"step": '"1ms"'}),
    "step_table": ("arm", {"step": "{ a = 1 }"}),
    "step_subnormal": ("arm", {"step": "5e-324"}),
    "step_1e308": ("arm", {"step": "1e308"}),
    "model_number": ("arm", {"model": "3"}),
    "axis_number": ("arm", {"axis": "5"}),
    "axis_list": ("arm", {"axis": '["theta"]'}),
    "coefficients_number": ("arm", {"coefficients": "3"}),
    "coefficients_list": ("arm", {"coefficients": "[300, 20]"}),
    "k_text": ("arm", {"coefficients": '{ k = "stiff", c = 20 }'}),
    "k_bool": ("arm", {"coefficients": "{ k = true, c = 20 }"}),
    "k_nested": ("arm", {"coefficients": "{ k = { value = 300 }, c = 20 }"}),
    "k_1e308": ("arm", {"coefficients": "{ k = 1e308, c = 20 }"}),
    "k_subnormal": ("arm", {"coefficients": "{ k = 5e-324, c = 20 }"}),
    "c_negzero_k_negzero": ("arm", {"coefficients": "{ k = -0.0, c = -0.0 }"}),
    "reference_text": ("arm", {"reference": '"step"'}),
    "amplitude_text": ("arm", {"reference": '{ type = "step", amplitude = "big", at = 0.02 }'}),
    "rig_f1_1e6": ("rig", {"f1": "1e6"}),
    "rig_f1_600": ("rig", {"f1": "600"}),
    "rig_f1_text": ("rig", {"f1": '"fast"'}),
    "rig_f1_list": ("rig", {"f1": "[1.85]"}),
    "rig_f0_table": ("rig", {"f0": "{ hz = 0.2 }"}),
    "rig_amplitude_inf": ("rig", {"amplitude": "inf"}),
    "rig_sweep_negzero": ("rig", {"sweep": "-0.0"}),
}
HEAD = '[simulation]\nduration = 1.0\nstep = 1e-3\n[robot]\nmodel = "arm"\n'
RAW_SCENARIOS = {
    "simulation_array": '[[simulation]]\nduration = 1.0\nstep = 1e-3\n[robot]\nmodel = "arm"\n',
    "simulation_number": 'simulation = 3\n[robot]\nmodel = "arm"\n',
    "joints_number": HEAD + "joints = 3\n",
    "joints_array": HEAD + '[[joints]]\naxis = "theta"\n',
    "joint_number": HEAD + "[joints]\nj1 = 3\n",
    "robot_number": "[simulation]\nduration = 1.0\nstep = 1e-3\nrobot = 3\n",
    "outputs_text": ARM.format(**ARM_GOOD) + '[outputs]\ncsv = "yes"\n',
    "outputs_nested": ARM.format(**ARM_GOOD) + "[outputs.csv]\nyes = true\n",
    "rig_number": "[simulation]\nduration = 1.0\nstep = 1e-3\nrig = 3\n",
    "rig_joint_text": RIG.format(**RIG_GOOD).replace("joint = {", 'joint = "j1"\n# {'),
    "bom": "\ufeff" + ARM.format(**ARM_GOOD),
}


def _write_scenarios(folder: Path) -> None:
    for name, (kind, change) in SCENARIOS.items():
        text = ARM.format(**{**ARM_GOOD, **change}) if kind == "arm" else RIG.format(**{**RIG_GOOD, **change})
        (folder / f"sc_{name}.toml").write_text(text)
    for name, text in RAW_SCENARIOS.items():
        (folder / f"sc_{name}.toml").write_text(text)
    (folder / "sc_good.toml").write_text(ARM.format(**ARM_GOOD))
    (folder / "sc_crlf.toml").write_bytes(ARM.format(**ARM_GOOD).replace("\n", "\r\n").encode())


SWEEP = 'scenario = "{scenario}"\n{body}'
MC = '[cases]\ntype = "montecarlo"\nn = 2\n'
SWEEPS = {
    "scenario_number": 'scenario = 3\n[cases]\ntype = "montecarlo"\nn = 2\n',
    "scenario_table": '[scenario]\nfile = "sc_good.toml"\n[cases]\ntype = "montecarlo"\nn = 2\n',
    "sweep_number": SWEEP.format(scenario="sc_good.toml", body="sweep = 3\n"),
    "cases_text": SWEEP.format(scenario="sc_good.toml", body='cases = "grid"\n'),
    "cases_array": SWEEP.format(scenario="sc_good.toml", body='[[cases]]\ntype = "grid"\n'),
    "n_text": SWEEP.format(scenario="sc_good.toml", body='[cases]\ntype = "montecarlo"\nn = "10"\n'),
    "n_float": SWEEP.format(scenario="sc_good.toml", body='[cases]\ntype = "montecarlo"\nn = 2.5\n'),
    "n_1e308": SWEEP.format(scenario="sc_good.toml", body='[cases]\ntype = "montecarlo"\nn = 1e308\n'),
    "seed_text": SWEEP.format(
        scenario="sc_good.toml", body='[cases]\ntype = "montecarlo"\nn = 2\nseed = "a"\n'
    ),
    "type_number": SWEEP.format(scenario="sc_good.toml", body="[cases]\ntype = 3\n"),
    "joints_text": SWEEP.format(
        scenario="sc_good.toml", body='[cases]\ntype = "montecarlo"\nn = 2\njoints = "j1"\n'
    ),
    "limits_text": SWEEP.format(
        scenario="sc_good.toml",
        body='[sweep]\nlimits = "overshoot<=5%"\n[cases]\ntype = "montecarlo"\nn = 2\n',
    ),
    "limits_nested": SWEEP.format(
        scenario="sc_good.toml",
        body='[sweep]\nlimits = [{ overshoot = 5 }]\n[cases]\ntype = "montecarlo"\nn = 2\n',
    ),
    "duration_text": SWEEP.format(
        scenario="sc_good.toml", body='[sweep]\nduration = "1"\n[cases]\ntype = "montecarlo"\nn = 2\n'
    ),
    "grid_text": SWEEP.format(
        scenario="sc_good.toml", body='[cases]\ntype = "grid"\n[cases.j1]\nk = "300"\n'
    ),
    "grid_nested": SWEEP.format(
        scenario="sc_good.toml", body='[cases]\ntype = "grid"\n[cases.j1.k]\nvalues = [300]\n'
    ),
    "workers_text": SWEEP.format(
        scenario="sc_good.toml", body='[sweep]\nworkers = "2"\n[cases]\ntype = "montecarlo"\nn = 2\n'
    ),
    "typo_top": SWEEP.format(scenario="sc_good.toml", body='[case]\ntype = "montecarlo"\nn = 2\n'),
    "typo_sweep": SWEEP.format(scenario="sc_good.toml", body=f'[sweep]\nlimts = ["overshoot<=5%"]\n{MC}'),
    "typo_cases": SWEEP.format(scenario="sc_good.toml", body=f"{MC}sed = 3\n"),
    "typo_cluster": SWEEP.format(
        scenario="sc_good.toml", body='[cases]\ntype = "montecarlo"\nn = 2\n[cluster]\nworker = 2\n'
    ),
    "aliased_rig": SWEEP.format(scenario="sc_rig_f1_1e6.toml", body='[cases]\ntype = "montecarlo"\nn = 2\n'),
    # another case type's key was ignored: a Monte Carlo sweep ran its draws, not candidate 1
    "other_types_key": SWEEP.format(scenario="sc_good.toml", body=f"{MC}candidates = [1]\n"),
}


def _write_sweeps(folder: Path) -> None:
    for name, text in SWEEPS.items():
        (folder / f"sw_{name}.toml").write_text(text)


@pytest.mark.parametrize("name", sorted([*SCENARIOS, *[n for n in RAW_SCENARIOS if n != "bom"]]))
def test_hand_edited_scenario(name, workdir, inputs, capsys):
    _bad(["cosim", f"in/sc_{name}.toml", "-o", "res"], workdir, inputs, capsys, allowed=(2,))


@pytest.mark.parametrize("name", ["rig_f1_1e6", "rig_f1_600", "k_text", "simulation_array", "duration_text"])
def test_hand_edited_scenario_in_tune(name, workdir, inputs, capsys):
    _bad(["tune", f"in/sc_{name}.toml", "-o", "t.json"], workdir, inputs, capsys, allowed=(2,))


def test_aliased_rig_scenario_names_the_sampling_theorem(workdir, inputs, capsys):
    for name in ("rig_f1_1e6", "rig_f1_600"):
        err = _bad(["cosim", f"in/sc_{name}.toml", "-o", "res"], workdir, inputs, capsys, allowed=(2,))
        assert "Nyquist" in err or "sampling" in err, err


@pytest.mark.parametrize("name", ["good", "crlf", "bom"])
def test_valid_scenario_encodings_run(name, workdir, capsys):
    code, out, err = run_inprocess(["cosim", f"in/sc_{name}.toml", "-o", "res", "--json"], capsys)
    assert code == 0, err
    assert (workdir / "res" / "metrics.json").is_file()


@pytest.mark.parametrize("name", sorted(SWEEPS))
def test_hand_edited_sweep(name, workdir, inputs, capsys):
    _bad(["sweep", f"in/sw_{name}.toml", "-o", "sw", "--workers", "1"], workdir, inputs, capsys, allowed=(2,))


# --- rig logs (identification's readers, issue 23: on main) ------------------------------------------


def _write_logs(folder: Path) -> None:
    """A clean simulated log and its variants: each with the same sidecar (print settings)."""
    from designer.rig.logs import write_log
    from designer.rig.simulate import simulate

    df = simulate({"x": {"m": 1e-3, "c": 2e-3, "k": 0.8}}, duration=20, rate=200, seed=1)
    write_log(df, folder / "lg_clean.csv", {"density": 60, "length": 24, "width": 4.5, "height": 9, **LAYER})
    side = (folder / "lg_clean.json").read_text()
    variants = {
        "huge": df.assign(x=df["x"] * 1e300, Fx=df["Fx"] * 1e300),
        "reversed_t": df.assign(t=df["t"].iloc[::-1].to_numpy()),
        "duplicated_t": df.assign(t=df["t"].where(df.index != 10, df["t"][9])),
        "nan_t": df.assign(t=df["t"].where(df.index != 10, np.nan)),
        "subnormal": df.assign(x=df["x"] * 5e-324),
        "one_inf": df.assign(Fx=df["Fx"].where(df.index != 50, np.inf)),
        "negzero": df.assign(x=df["x"].where(df.index != 0, -0.0)),
    }
    for name, frame in variants.items():
        frame.to_csv(folder / f"lg_{name}.csv", index=False)
        (folder / f"lg_{name}.json").write_text(side)


LAYER = {"layer": 0.16, "raster": 0}
#: log -> the exit code it must give: 2 refused as bad input, 1 a failed identification (no row),
#: 0 identified (a single Inf sample is a dropout; -0.0 is 0) with k within 1 % of the true 0.8 N/mm
LOGS = {
    "huge": 2,
    "reversed_t": 2,
    "duplicated_t": 2,
    "nan_t": 2,
    "subnormal": 1,
    "one_inf": 0,
    "negzero": 0,
}


@pytest.mark.parametrize("name", sorted(LOGS))
def test_hostile_logs(name, workdir, inputs, capsys):
    if not (inputs / "lg_clean.csv").exists():
        _write_logs(inputs)
    args = ["identify", f"in/lg_{name}.csv", "--json"]
    if LOGS[name]:
        _bad(args, workdir, inputs, capsys, allowed=(LOGS[name],))
        return
    code, out, err = run_inprocess(args, capsys)
    assert code == 0, err
    (log,) = json.loads(out)["logs"]
    assert log["ok"] and abs(log["axes"]["x"]["k"] / 0.8 - 1) < 0.01, log


# --- aliasing, unreachable targets, degenerate tables ---------------------------------------------

IMPOSSIBLE = [
    ["rig", "simulate", *K, *SIX, "--f1", "900", "-o", "l.csv"],
    ["rig", "simulate", *K, *SIX, "--f1", "500", "-o", "l.csv"],
    ["rig", "simulate", *K, *SIX, "--f1", "1e6", "-o", "l.csv"],
    ["rig", "simulate", *K, *SIX, "--f1", "40", "--rate", "50", "-o", "l.csv"],
    ["rig", "simulate", *K, *SIX, "--f1", "1e308", "-o", "l.csv"],
    ["rig", "simulate", *K, *SIX, "--f1", "-0.0", "-o", "l.csv"],
    ["rig", "simulate", *K, *SIX, "--rate", "5e-324", "-o", "l.csv"],
    ["rig", "simulate", "--k", "1e308", "--c", "2e-3", *SIX, "-o", "l.csv"],
    ["rig", "simulate", "--k", "5e-324", "--c", "2e-3", *SIX, "-o", "l.csv"],
    ["rig", "simulate", "--k", "-0.0", "--c", "2e-3", *SIX, "-o", "l.csv"],
    ["doe", "--augment", "3", "--k", "50"],
    ["doe", "--augment", "3", "--k", "1e308"],
    ["doe", "--augment", "3", "--k", "5e-324"],
    ["suggest", "--k", "1e308"],
    ["suggest", "--k", "5e-324"],
    ["suggest", "--k", "-0.0"],
    ["suggest", "--c", "1e308"],
    ["predict", *SIX[:4], "--width", "1e308", *SIX[6:]],
    ["predict", *SIX[:4], "--width", "-0.0", *SIX[6:]],
    ["predict", "--density", "5e-324", *SIX[2:]],
    ["export", "fmu", "--k", "5e-324", "--c", "2e-3", "-o", "j.fmu"],
    ["export", "mjcf", "--k", "0.8", "--c", "1e308", "-o", "j.xml"],
    ["analyze", "--data", "in/constant_factor.csv"],
    ["analyze", "--data", "in/collinear.csv"],
    ["fit", "--data", "in/constant_factor.csv"],
]


@pytest.fixture()
def degenerate(inputs):
    good = bundled_table()
    good.assign(height=9.0).to_csv(inputs / "constant_factor.csv", index=False)
    good.assign(length=good["width"] * 4 + 6).to_csv(inputs / "collinear.csv", index=False)


@pytest.mark.parametrize("args", IMPOSSIBLE, ids=[" ".join(a)[:70] for a in IMPOSSIBLE])
def test_impossible_or_aliased_request_is_refused(args, workdir, inputs, capsys, degenerate):
    err = _bad(args, workdir, inputs, capsys)
    if "--f1" in args and args[args.index("--f1") + 1] in ("900", "500", "1e6", "40"):
        assert "Nyquist" in err or "sampling" in err, err


def test_negative_zero_damping_is_zero_not_minus_zero(workdir, capsys):
    """c = -0.0 is an undamped joint (valid): exported as 0, never as '-0'."""
    import zipfile

    code, out, err = run_inprocess(["export", "fmu", "--k", "0.8", "--c", "-0.0", "-o", "j.fmu"], capsys)
    assert code == 0, err
    with zipfile.ZipFile(workdir / "j.fmu") as z:
        md = z.read("modelDescription.xml").decode()
    assert 'start="-0' not in md and 'start="0"' in md or 'start="0.0"' in md


REAL = [
    ["fit", "--data", "in/deccomma_quoted.csv"],
    ["analyze", "--data", "in/utf16.csv"],
    ["export", "fmu", "--from", "in/sj_density_text.json", "-o", "j.fmu"],
    ["cosim", "in/sc_rig_f1_1e6.toml", "-o", "res"],
    ["cosim", "in/sc_axis_list.toml", "-o", "res"],
    ["sweep", "in/sw_typo_sweep.toml", "-o", "sw"],
    ["rig", "simulate", *K, *SIX, "--f1", "900", "-o", "l.csv"],
]


@pytest.mark.parametrize("args", REAL, ids=[" ".join(a)[:50] for a in REAL])
def test_a_sample_as_real_processes(args, workdir, inputs):
    """The installed package as a real `python -I` process gives the same clean failure."""
    before = snapshot(workdir, inputs)
    r = run_process(args, workdir)
    assert_clean_failure(r.returncode, r.stderr, (2,))
    assert r.stdout == "" and snapshot(workdir, inputs) == before


# --- the Python API with wrong types --------------------------------------------------------------


def _api_cases():
    import designer

    sur = designer.Surrogate.load()
    table = designer.load_table()
    design = {"density": 60, "length": 24, "width": 4.5, "height": 9, "layer": 0.16, "raster": 0}
    joint = designer.Joint.from_coefficients({"x": {"k": 0.8, "c": 2e-3}})
    return {
        "suggest(None)": ("surrogate", lambda: designer.suggest(None, k=0.8)),
        "suggest(path)": ("surrogate", lambda: designer.suggest("surrogate.json", k=0.8)),
        "suggest(DataFrame)": ("surrogate", lambda: designer.suggest(table, k=0.8)),
        "suggest(k=list)": ("k", lambda: designer.suggest(sur, k=[0.8])),
        "suggest(k=array)": ("k", lambda: designer.suggest(sur, k=np.array([0.8, 0.9]))),
        "suggest(c=dict)": ("c", lambda: designer.suggest(sur, k=0.8, c={"v": 1})),
        "suggest(top=str)": ("top", lambda: designer.suggest(sur, k=0.8, top="2")),
        "suggest(tolerance=None)": ("tolerance", lambda: designer.suggest(sur, k=0.8, tolerance=None)),
        "Surrogate().predict before fit": ("fit", lambda: designer.Surrogate().predict(design)),
        "Surrogate().fit(array)": ("table", lambda: designer.Surrogate().fit(table.to_numpy())),
        "Surrogate().fit(list)": ("table", lambda: designer.Surrogate().fit([1, 2, 3])),
        "predict(array)": ("designs", lambda: sur.predict(np.array([60, 24, 4.5, 9, 0.16, 0]))),
        "predict(None)": ("designs", lambda: sur.predict(None)),
        "predict(str)": ("designs", lambda: sur.predict("density=60")),
        "Surrogate.load(3)": ("path", lambda: designer.Surrogate.load(3)),
        "Surrogate.load(dict)": ("path", lambda: designer.Surrogate.load({"format": 1})),
        "save(None)": ("path", lambda: sur.save(None)),
        "load_table(3)": ("source", lambda: designer.load_table(3)),
        "load_table(array)": ("source", lambda: designer.load_table(np.zeros((3, 3)))),
        "Joint.from_coefficients(None)": ("coefficients", lambda: designer.Joint.from_coefficients(None)),
        "Joint.from_coefficients(array)": (
            "coefficients",
            lambda: designer.Joint.from_coefficients(np.ones(3)),
        ),
        "Joint.from_coefficients(name=3)": (
            "name",
            lambda: designer.Joint.from_coefficients({"x": {"k": 0.8, "c": 2e-3}}, name=3),
        ),
        "Joint.from_design(None)": ("params", lambda: designer.Joint.from_design(None)),
        "Joint.from_design(array)": ("params", lambda: designer.Joint.from_design(np.ones(6))),
        "Joint.from_design(surrogate=str)": (
            "surrogate",
            lambda: designer.Joint.from_design(design, surrogate="default.json"),
        ),
        "Joint.from_design(axes=None)": ("axes", lambda: designer.Joint.from_design(design, axes=None)),
        "Joint.from_suggestion(None)": ("suggestion", lambda: designer.Joint.from_suggestion(None)),
        "Joint.from_suggestion(dict)": ("suggestion", lambda: designer.Joint.from_suggestion({"axis": "x"})),
        "export_fmu(None)": ("joint", lambda: designer.export_fmu(None, "j.fmu")),
        "export_fmu(path=None)": ("path", lambda: designer.export_fmu(joint, None)),
        "export_fmu(path=3)": ("path", lambda: designer.export_fmu(joint, 3)),
        "export_mjcf(dict)": ("joint", lambda: designer.export_mjcf({"k": 1}, "j.xml")),
        "export_urdf(None)": ("joint", lambda: designer.export_urdf(None, "j.urdf")),
        "export_sdf(str)": ("joint", lambda: designer.export_sdf("joint", "j.sdf")),
        "export_usd(str)": ("joint", lambda: designer.export_usd("joint", "j.usda")),
        "export_usd(into=3)": ("into", lambda: designer.export_usd(joint, "j.usda", into=3, joint_name="j")),
        "export_usd(joint_name=3)": (
            "joint_name",
            lambda: designer.export_usd(joint, "j.usda", into="r.usda", joint_name=3),
        ),
        "export_modelica(None)": ("joint", lambda: designer.export_modelica(None, "j.mo")),
        "export_ssp(None)": ("joints", lambda: designer.export_ssp(None, "j.ssp")),
        "export_ssp([None])": ("joints[0]", lambda: designer.export_ssp([None], "j.ssp")),
        "identify(None)": ("logs", lambda: designer.identify(None)),
        "identify(array)": ("logs", lambda: designer.identify(np.zeros((100, 3)))),
        "identify(3)": ("logs", lambda: designer.identify(3)),
        "calibrate(None)": ("surrogate", lambda: designer.calibrate(None, table.iloc[:3])),
        "calibrate(runs=array)": ("runs", lambda: designer.calibrate(sur, table.to_numpy())),
        "next_prints(None)": ("surrogate", lambda: designer.next_prints(None, k=0.8)),
        "next_prints(n=str)": ("n", lambda: designer.next_prints(sur, k=0.8, n="3")),
        "cosim.load(None)": ("path", lambda: designer.cosim.load(None)),
        "cosim.load(3)": ("path", lambda: designer.cosim.load(3)),
        "cosim.run(None)": ("scenario", lambda: designer.cosim.run(None)),
        "cosim.run(path)": ("scenario", lambda: designer.cosim.run(str(EXAMPLES / "rig.toml"))),
        "cosim.write_outputs(None)": ("result", lambda: designer.cosim.write_outputs(None, "res")),
        "sweep.load(None)": ("path", lambda: designer.sweep.load(None)),
        "sweep.run(None)": ("spec", lambda: designer.sweep.run(None)),
        "sweep.run(path)": ("spec", lambda: designer.sweep.run(str(EXAMPLES / "sweep_arm.toml"))),
        "sweep.run(executor=str)": (
            "executor",
            lambda: designer.sweep.run(designer.sweep.load(EXAMPLES / "sweep_arm.toml"), executor="local"),
        ),
        "export_fmu(platforms=[3])": (
            "platforms",
            lambda: designer.export_fmu(joint, "j.fmu", platforms=[3]),
        ),
        "suggest(fixed=list)": ("fixed", lambda: designer.suggest(sur, k=0.8, fixed=[("width", 3)])),
        "suggest(importance=list)": ("importance", lambda: designer.suggest(sur, k=0.8, importance=[1])),
        "suggest(bounds=str)": ("bounds", lambda: designer.suggest(sur, k=0.8, bounds="0.5:1")),
        "Joint.from_suggestion(candidate=str)": (
            "candidate",
            lambda: designer.Joint.from_suggestion(EXAMPLES / "suggestion.json", candidate="1"),
        ),
    }


API_CASES = _api_cases()


@pytest.mark.parametrize("case", sorted(API_CASES))
def test_api_wrong_type_raises_designer_error_naming_the_argument(case, tmp_path, monkeypatch):
    from designer import DesignerError

    monkeypatch.chdir(tmp_path)
    name, call = API_CASES[case]
    with pytest.raises(DesignerError) as info:
        call()
    assert name in str(info.value), str(info.value)
    assert list(tmp_path.iterdir()) == []


def test_the_campaign_has_at_least_300_cases_with_the_earlier_rounds():
    """Issue 26's count: this file's cases, the interrupt and file-system ones (real processes) and
    the earlier rounds' campaign (tests/test_cli_campaign.py, test_cli_properties.py)."""
    import test_cli_campaign
    import test_cli_interrupts
    import test_files_hostile

    here = (
        len(INVALID_TABLES) * len(TABLE_COMMANDS)
        + len(VALID_TABLES)
        + 2 * len(SUGGESTIONS)
        + len(SCENARIOS)
        + len(RAW_SCENARIOS)
        + len(SWEEPS)
        + len(IMPOSSIBLE)
        + len(API_CASES)
        + len(REAL)
        + len(LOGS)
    )
    real = test_cli_interrupts.CASE_COUNT + test_files_hostile.CASE_COUNT
    earlier = len(test_cli_campaign.CASES) + len(test_cli_campaign.REAL)
    assert here >= 200 and real >= 30, (here, real)
    assert here + real + earlier >= 300
