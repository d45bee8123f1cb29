"""Property-based tests over the CLI's inputs (hypothesis): flags, tables, logs, scenarios and
suggestion files. Whatever the input, the exit code is 0, 1 or 2, there is no traceback, a failure
leaves no file behind, and a success writes only physically possible numbers."""

from __future__ import annotations

import contextlib
import io
import json
import math
import os
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

import pandas as pd
from clitools import FACTORS, assert_clean_failure, bundled_table, snapshot
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

SETTINGS = settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.too_slow])

numbers = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True, width=64),
    st.sampled_from([0.0, -1.0, 1e300, -1e-300, 0.16, 45.0, 60.0]),
)
number_text = st.one_of(
    numbers.map(repr), st.text(max_size=8), st.sampled_from(["", "1e", "--", "0x10", "½"])
)


def call(args: list[str], folder: Path) -> tuple[int, str, str]:
    """Run the command line in-process with `folder` as the current folder."""
    from designer_cli.main import run

    out, err = io.StringIO(), io.StringIO()
    here = os.getcwd()
    os.chdir(folder)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = run([str(a) for a in args])
    finally:
        os.chdir(here)
    return code, out.getvalue(), err.getvalue()


def check(args: list[str], folder: Path) -> tuple[int, str]:
    """Run and assert the contract; returns the exit code and stdout."""
    before = snapshot(folder)
    code, out, err = call(args, folder)
    if code != 0:
        assert_clean_failure(code, err)
        assert snapshot(folder) == before, f"{args}: a file was left behind"
    else:
        assert "Traceback" not in err
    return code, out


@SETTINGS
@given(fixes=st.lists(st.text(max_size=12), min_size=1, max_size=3), target=number_text)
def test_fix_and_target_flags(fixes, target):
    with tempfile.TemporaryDirectory() as tmp:
        args = ["suggest", "--k", target, "--json"] + [a for f in fixes for a in ("--fix", f)]
        code, out = check(args, Path(tmp))
        if code == 0:
            for cand in json.loads(out)["candidates"]:
                assert 0 < cand["params"]["density"] <= 100 and cand["predicted"]["k"]["value"] > 0


@SETTINGS
@given(
    values=st.fixed_dictionaries({n: number_text for n in FACTORS}), axis=st.sampled_from(["x", "w", "theta"])
)
def test_predict_flags(values, axis):
    with tempfile.TemporaryDirectory() as tmp:
        args = ["predict", "--json", "--axis", axis] + [a for n, v in values.items() for a in (f"--{n}", v)]
        code, out = check(args, Path(tmp))
        if code == 0:
            k = json.loads(out)["predicted"]["k"]
            assert 0 < k["low"] <= k["value"] <= k["high"] and math.isfinite(k["high"])


@st.composite
def tables(draw):
    """The study table with random damage: dropped columns, rows, cells replaced by odd values."""
    t = bundled_table().astype(object)
    cols = draw(st.lists(st.sampled_from(list(t.columns)), max_size=2, unique=True))
    t = t.drop(columns=cols)
    n = draw(st.integers(0, len(t)))
    t = t.iloc[:n].copy()
    for _ in range(draw(st.integers(0, 3))):
        if len(t) and len(t.columns):
            r, c = draw(st.integers(0, len(t) - 1)), draw(st.sampled_from(list(t.columns)))
            t.iloc[r, t.columns.get_loc(c)] = draw(st.one_of(numbers, st.text(max_size=5)))
    sep = draw(st.sampled_from([",", ",", ";", "\t"]))
    return t, sep


@SETTINGS
@given(table=tables(), command=st.sampled_from(["analyze", "clean"]))
def test_tables(table, command):
    frame, sep = table
    with tempfile.TemporaryDirectory() as tmp:
        frame.to_csv(Path(tmp, "t.csv"), sep=sep, index=False)
        args = (
            ["analyze", "--data", "t.csv", "--json"]
            if command == "analyze"
            else ["clean", "t.csv", "-o", "k.csv"]
        )
        code, out = check(args, Path(tmp))
        if code == 0 and command == "clean":
            kept = pd.read_csv(Path(tmp, "k.csv"))
            assert len(kept) > 0 and (kept["k_x"] > 0).all() and (kept["c_x"] >= 0).all()


_LOG = []


def _base_log() -> pd.DataFrame:
    if not _LOG:
        from designer.rig.simulate import simulate

        _LOG.append(simulate({"x": {"m": 1e-3, "c": 2e-3, "k": 0.8}}, duration=10, rate=100, seed=1))
    return _LOG[0]


@st.composite
def logs(draw):
    """A short simulated rig log with random damage, and a random sidecar."""
    df = _base_log().copy()
    cols = draw(st.lists(st.sampled_from(list(df.columns)), max_size=1, unique=True))
    df = df.drop(columns=cols)
    for _ in range(draw(st.integers(0, 3))):
        r, c = draw(st.integers(0, len(df) - 1)), draw(st.sampled_from(list(df.columns)))
        df.iloc[r, df.columns.get_loc(c)] = draw(numbers)
    keys = st.sampled_from(["factors", "load_delay_s", "factor", "loaddelay", "x"])
    factor_values = st.dictionaries(
        st.sampled_from([*FACTORS, "colour"]), st.one_of(numbers, st.text(max_size=3))
    )
    sidecar = draw(st.one_of(st.none(), st.dictionaries(keys, st.one_of(numbers, factor_values), max_size=3)))
    return df, sidecar


@SETTINGS
@given(log=logs())
def test_logs(log):
    df, sidecar = log
    with tempfile.TemporaryDirectory() as tmp:
        df.to_csv(Path(tmp, "run.csv"), index=False)
        if sidecar is not None:
            Path(tmp, "run.json").write_text(json.dumps(sidecar))
        code, out = check(["identify", "run.csv", "-o", "t.csv", "--json"], Path(tmp))
        if code == 0:
            for fit in json.loads(out)["logs"][0]["axes"].values():
                assert fit["k"] > 0 and fit["c"] >= 0


def _mutate(draw, doc):
    """A random change deep in a JSON document: delete a key, retype a value, or add a key."""
    node = doc
    while True:
        if isinstance(node, dict) and node:
            key = draw(st.sampled_from(sorted(node)))
            if draw(st.booleans()) and isinstance(node[key], (dict, list)) and node[key]:
                node = node[key]
                continue
            action = draw(st.sampled_from(["delete", "retype", "add"]))
            if action == "delete":
                del node[key]
            elif action == "retype":
                node[key] = draw(st.one_of(numbers, st.text(max_size=4), st.none(), st.just([])))
            else:
                node[draw(st.text(min_size=1, max_size=8))] = 1
            return
        if isinstance(node, list) and node:
            node = node[draw(st.integers(0, len(node) - 1))]
            continue
        return


@st.composite
def suggestions(draw, good):
    doc = json.loads(json.dumps(good))
    for _ in range(draw(st.integers(1, 3))):
        _mutate(draw, doc)
    return doc


_GOOD = {}


def _good_suggestion() -> dict:
    if not _GOOD:
        from designer.design.suggestions import suggest
        from designer.model.surrogate import Surrogate

        _GOOD.update(suggest(Surrogate.load(), k=0.8, top=2).to_dict())
    return _GOOD


@SETTINGS
@given(data=st.data())
def test_suggestion_files(data):
    doc = data.draw(suggestions(_good_suggestion()))
    with tempfile.TemporaryDirectory() as tmp:
        Path(tmp, "s.json").write_text(json.dumps(doc))
        code, out = check(["export", "mjcf", "--from", "s.json", "-o", "j.xml"], Path(tmp))
        if code == 0:
            for joint in ET.parse(Path(tmp, "j.xml")).iter("joint"):
                for attr in ("stiffness", "damping"):
                    if attr in joint.attrib:
                        value = float(joint.attrib[attr])
                        assert math.isfinite(value) and value >= 0


SCENARIO_KEYS = {
    "simulation": ["duration", "step", "algorithm", "integrator", "duraton", "stepp"],
    "robot": ["model", "lengths", "masses", "modle"],
    "outputs": ["csv", "parquet", "plot", "cvs"],
}


@st.composite
def scenarios(draw):
    """A scenario TOML: the example arm's structure with random keys and values (short durations)."""
    values = st.one_of(
        st.floats(1e-4, 0.05),
        st.integers(-2, 3),
        st.text(max_size=6),
        st.sampled_from(["euler", "jacobi", "arm"]),
    )
    lines = []
    for table, keys in SCENARIO_KEYS.items():
        lines.append(f"[{table}]")
        for key in draw(st.lists(st.sampled_from(keys), max_size=3, unique=True)):
            lines.append(f"{key} = {json.dumps(draw(values))}")
    lines += ["[joints.j1]", f"coefficients = {{ k = {draw(st.sampled_from([300, -1, 0]))}, c = 0.8 }}"]
    return "\n".join(lines) + "\n"


@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(text=scenarios())
def test_scenarios(text):
    with tempfile.TemporaryDirectory() as tmp:
        Path(tmp, "s.toml").write_text(text)
        code, out = check(["cosim", "s.toml", "-o", "res", "--json"], Path(tmp))
        if code == 0:
            for joint in json.loads(out)["metrics"].values():
                assert math.isfinite(joint["tracking_rms_rad"])


SWEEP_TABLES = {
    "sweep": ["path", "check", "duration", "limits", "workers", "batch"],
    "cases": ["type", "joints", "n", "seed", "candidates"],
}
TYPOS = {"sweep": ["limts", "duraton"], "cases": ["sed", "typ"]}
#: values each key takes in a working sweep: drawn most of the time, so random files run cases too
VALID = {
    "path": ['"engine"', '"fmu"'], "check": ["0", "1"], "duration": ["0.03"],
    "limits": ['["overshoot<=50%"]'], "workers": ["1"], "batch": ["2"], "type": ['"montecarlo"'],
    "joints": ['["j1"]'], "n": ["2", "3"],
    "seed": ["1"], "candidates": ["[1]"],
}  # fmt: skip
ONE_LINK = f"""[simulation]
duration = 0.05
step = 1e-3
[robot]
model = "{Path(__file__).resolve().parents[1] / "examples" / "one_link.xml"}"
[joints.j1]
axis = "theta"
design = {{ density = 60, length = 24, width = 4.5, height = 9, layer = 0.16, raster = 0 }}
reference = {{ type = "step", amplitude = 0.5, at = 0.01 }}
"""


@st.composite
def sweeps(draw):
    """A sweep TOML over a tiny one-link scenario: random keys (sometimes misspelt) with working values
    or, one time in six, random ones of any TOML type, nested tables included."""
    values = st.one_of(
        st.integers(-2, 3),
        st.floats(allow_nan=True, allow_infinity=True),
        st.sampled_from(['"engine"', '"fmu"', '"montecarlo"', '"grid"', '"suggestion"', "true", '"x"']),
        st.sampled_from(['["j1"]', '["overshoot<=5%"]', "[1, 2]", "{ a = 1 }", "{ j1 = { k = [3e2] } }"]),
    )
    lines = ['scenario = "one_link.toml"']
    for table, keys in SWEEP_TABLES.items():
        lines.append(f"[{table}]")
        chosen = draw(st.lists(st.sampled_from(keys), max_size=3, unique=True))
        if table == "cases" and draw(st.integers(0, 4)) > 0:  # most files name their cases
            chosen = ["type", "n", *(k for k in chosen if k not in ("type", "n"))]
        if draw(st.integers(0, 4)) == 0:
            chosen.append(draw(st.sampled_from(TYPOS[table])))
        for key in chosen:
            valid = st.sampled_from(VALID.get(key, ["1"]))
            value = draw(valid if draw(st.integers(0, 5)) else values)  # mostly working values
            lines.append(f"{key} = {value if isinstance(value, str) else json.dumps(value)}")
    return "\n".join(lines).replace("NaN", "nan").replace("Infinity", "inf") + "\n"


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(text=sweeps())
def test_sweeps(text):
    with tempfile.TemporaryDirectory() as tmp:
        Path(tmp, "one_link.toml").write_text(ONE_LINK)
        Path(tmp, "s.toml").write_text(text)
        code, out = check(["sweep", "s.toml", "-o", "sw", "--workers", "1", "--json", "--no-plot"], Path(tmp))
        if code == 0:
            summary = json.loads(out)
            assert summary["ok"] >= 1 and summary["cases"] >= summary["ok"]
        elif code == 2:  # refused before any case ran: no results folder
            assert not Path(tmp, "sw").exists()
