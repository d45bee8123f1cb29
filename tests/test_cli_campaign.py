"""A campaign of bad inputs over every command: each ends with exit 1 or 2, one line (for 2), no
traceback, and no file written or left behind (hidden part files included).

Most cases run in this process (`designer_cli.main.run`) for speed; a representative subset runs as
real `python -I` processes of the installed package.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from clitools import assert_clean_failure, enter_workdir, make_inputs, run_inprocess, run_process, snapshot

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"

# commands that write one file with -o, and the suffix they write
FILE_COMMANDS = {
    "fit": (["fit"], ".json"),
    "identify": (["identify", "in/log.csv"], ".csv"),
    "rig simulate": (["rig", "simulate", "--k", "0.8", "--c", "2e-3", "--duration", "5"], ".csv"),
    "clean": (["clean", "in/good.csv", "--max-drop", "1"], ".csv"),
    "doe": (["doe"], ".csv"),
    "export fmu": (["export", "fmu", "--k", "0.8", "--c", "2e-3"], ".fmu"),
    "export modelica": (["export", "modelica", "--k", "0.8", "--c", "2e-3"], ".mo"),
    "export mjcf": (["export", "mjcf", "--k", "0.8", "--c", "2e-3"], ".xml"),
    "export urdf": (["export", "urdf", "--k", "0.8", "--c", "2e-3"], ".urdf"),
    "plot effects": (["plot", "effects"], ".png"),
    "plot heatmap": (["plot", "heatmap"], ".png"),
    "plot loo": (["plot", "loo"], ".png"),
    "plot space": (["plot", "space"], ".png"),
    "plot timeseries": (["plot", "timeseries", "in/ts.csv"], ".png"),
}
BAD_OUTPUTS = {
    "existing folder": lambda suffix: "in",
    "under /proc": lambda suffix: f"/proc/out{suffix}",
    "missing folder": lambda suffix: f"no/such/folder/out{suffix}",
    "wrong suffix": lambda suffix: "out.txt",
}
BAD_TABLES = [
    "semicolon.csv",
    "tabs.csv",
    "binary.csv",
    "empty.csv",
    "header.csv",
    "parquet.csv",
    "text.parquet",
    "negk.csv",
    "textcell.csv",
    "nocol.csv",
    "badunit.csv",
    "levels.csv",
    "density500.csv",
    "k1e308.csv",
    "subnormal.csv",
    "dupcol.csv",
    "missing.csv",
]
TABLE_COMMANDS = {
    "fit": lambda t: ["fit", "--data", t],
    "analyze": lambda t: ["analyze", "--data", t],
    "doe --augment": lambda t: ["doe", "--augment", "2", "--data", t],
    "plot effects": lambda t: ["plot", "effects", "--data", t],
    "plot heatmap": lambda t: ["plot", "heatmap", "--data", t],
    "clean": lambda t: ["clean", t],
    "validate": lambda t: ["validate", "--data", t],
}
BAD_LOGS = [
    "log_semicolon.csv",
    "log_noload.csv",
    "log_backwards.csv",
    "log_unit.csv",
    "log_empty.csv",
    "log_binary.csv",
    "side_typo.csv",
    "side_range.csv",
    "side_text.csv",
    "side_unknown.csv",
    "side_list.csv",
    "side_notjson.csv",
    "nolog.csv",
]
BAD_SUGGESTIONS = [
    "sug_notjson.json",
    "sug_list.json",
    "sug_other.json",
    "sug_typo.json",
    "sug_extra.json",
    "sug_empty.json",
    "sug_noparams.json",
    "sug_range.json",
    "sug_axis.json",
    "sug_candkey.json",
    "nosuggestion.json",
]
K = ["--k", "0.8", "--c", "2e-3"]
SIX = [
    "--density",
    "60",
    "--length",
    "24",
    "--width",
    "4.5",
    "--height",
    "9",
    "--layer",
    "0.16",
    "--raster",
    "0",
]
BAD_FLAGS = [
    ["suggest", "--k", "-1"],
    ["suggest", "--k", "nan"],
    ["suggest", "--k", "inf"],
    ["suggest", "--k", "stiff"],
    ["suggest", "--c", "-1"],
    ["suggest", "--k", "0.8", "--fix", "colour=red"],
    ["suggest", "--k", "0.8", "--fix", "width"],
    ["suggest", "--k", "0.8", "--fix", "width=wide"],
    ["suggest", "--k", "0.8", "--fix", "width=3", "--fix", "width=5"],
    ["suggest", "--k", "0.8", "--fix", "width=100"],
    ["suggest", "--k", "0.8", "--fix", "=3"],
    ["suggest", "--k", "0.8", "--axis", "w"],
    ["suggest", "--k", "0.8", "--top", "0"],
    ["suggest", "--k", "0.8", "--surrogate", "in/good.csv"],
    ["suggest", "--k", "0.8", "--surrogate", "in/missing.json"],
    ["predict", "--density", "60"],
    ["predict", *SIX[:-2], "--raster", "30"],
    ["predict", *SIX[:2], "--density", "500", *SIX[2:]],
    ["predict", *SIX, "--axis", "q"],
    ["predict", *SIX[:8], "--layer", "0.3", "--raster", "0"],
    ["export", "fmu", "--k", "-1", "--c", "1"],
    ["export", "fmu", "--k", "0.8"],
    ["export", "fmu", *K, "--fmi", "4"],
    ["export", "fmu", *K, "--interface", "spring"],
    ["export", "fmu"],
    ["export", "fmu", *K, *SIX],
    ["export", "fmu", "--k", "nan", "--c", "1"],
    ["export", "fmu", *K, "--axis", "w"],
    ["export", "fmu", *K, "--axis", "x", "--axis", "x"],
    ["export", "fmu", *K, "--interface", "body"],
    ["export", "mjcf", "--k", "inf", "--c", "1"],
    ["export", "mjcf", "--k", "1e300", "--c", "1"],
    ["export", "fmu", "--k", "0.8", "--c", "1e12"],
    ["export", "urdf", *K, "--density", "60"],
    ["export", "modelica", *K, "--from", "in/suggestion.json"],
    ["rig", "simulate", *K, "--duration", "1e9", "-o", "big.csv"],
    ["rig", "simulate", *K, "--duration", "-1", "-o", "l.csv"],
    ["rig", "simulate", *K, "--rate", "0", "-o", "l.csv"],
    ["rig", "simulate", *K, "--noise", "-1", "-o", "l.csv"],
    ["rig", "simulate", *K, "--dropouts", "0.9", "-o", "l.csv"],
    ["rig", "simulate", *K, "--axis", "w", "-o", "l.csv"],
    ["rig", "simulate", "--k", "0", "--c", "1", "-o", "l.csv"],
    ["rig", "simulate", *K, "--density", "60", "-o", "l.csv"],
    ["rig", "simulate", *K, "-o", "l.xlsx"],
    ["rig", "simulate", *K],
    ["identify", "in/log.csv", "--window", "-1"],
    ["identify", "in/log.csv", "--window", "0"],
    ["identify"],
    ["doe", "--augment", "0"],
    ["doe", "--augment", "100000"],
    ["doe", "--augment", "-3"],
    ["doe", "--all-continuous", "--augment", "3"],
    ["doe", "--center", "2", "--augment", "3"],
    ["doe", "--k", "0.8"],
    ["clean", "in/good.csv", "--eps", "0"],
    ["clean", "in/good.csv", "--eps", "nan"],
    ["clean", "in/good.csv", "--min-samples", "0"],
    ["clean", "in/good.csv", "--max-drop", "2"],
    ["clean", "in/good.csv", "-o", "kept.csv"],  # drops 12 of 44 (27 %): refused, exit 1
    ["plot", "space", "--target", "-1"],
    ["plot", "space", "--x", "colour"],
    ["plot", "space", "--response", "q"],
    ["plot", "space", "--z", "density"],
    ["plot", "space", "--volume"],
    ["plot", "space", "--fix", "colour=red"],
    ["plot", "heatmap", "--data", "in/onerun.csv"],
    ["plot", "effects", "--response", "q"],
    ["plot", "loo", "--axis", "theta"],
    ["plot", "timeseries", "in/nots.csv"],
    ["plot", "timeseries", "in/ts.csv", "--columns", "nope"],
    ["plot", "timeseries", "in/ts_semicolon.csv"],
    ["plot", "timeseries", "in/ts.csv", "--reference", "in/binary.csv"],
    ["cosim", "in/noscenario.toml"],
    ["cosim", "in/bad.toml"],
    ["cosim", "in/binary.toml"],
    ["cosim", "in/good.csv"],
    ["cosim", "in/diverge.toml", "-o", "res"],
    ["cosim", "in/typo.toml", "-o", "res"],
    ["cosim", "in/huge.toml", "-o", "res"],
    ["cosim", "in/stifness.toml", "-o", "res"],
    ["cosim", "in/bad.toml", "-o", "in/good.csv"],
    ["validate", "-o", "in/good.csv"],
    ["validate", "-o", "/proc/report"],
    ["sweep", "in/nope.toml", "-o", "r"],
    ["sweep", "in/bad.toml"],
    ["sweep", "in/binary.toml"],
    ["sweep", "in/typo.toml", "-o", "in/good.csv"],
    ["tune", "in/bad.toml"],
    ["tune", "in/nope.toml"],
    ["profile", "-o", "in"],
    ["profile", "-o", "x.txt"],
    ["profile", "--target", "colour"],
    ["profile", "--suggestion", "in/sug_other.json"],
    ["frobnicate"],
    ["fit", "--bogus"],
    ["predict", "--density"],
    ["analyze", "--data"],
]

CASES = (
    [
        pytest.param([*cmd, "-o", bad(suffix)], id=f"{name}-out-{what}")
        for name, (cmd, suffix) in FILE_COMMANDS.items()
        for what, bad in BAD_OUTPUTS.items()
    ]
    + [
        pytest.param(make(f"in/{t}"), id=f"{name}-table-{t}")
        for name, make in TABLE_COMMANDS.items()
        for t in BAD_TABLES
    ]
    + [pytest.param(["identify", f"in/{log}"], id=f"identify-{log}") for log in BAD_LOGS]
    + [
        pytest.param(["export", fmt, "--from", f"in/{s}"], id=f"export-{fmt}-{s}")
        for fmt in ("fmu", "mjcf")
        for s in BAD_SUGGESTIONS
    ]
    + [
        pytest.param(
            ["export", "fmu", "--from", "in/suggestion.json", "--candidate", "9"], id="export-candidate-9"
        )
    ]
    + [pytest.param(args, id=" ".join(args)[:60]) for args in BAD_FLAGS]
)


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    folder = tmp_path_factory.mktemp("inputs")
    make_inputs(folder)
    return folder


@pytest.fixture()
def workdir(tmp_path, inputs, monkeypatch):
    return enter_workdir(tmp_path, inputs, monkeypatch)


def test_campaign_has_at_least_200_cases():
    assert len(CASES) >= 200


@pytest.mark.parametrize("args", CASES)
def test_bad_input(args, workdir, inputs, capsys):
    before = snapshot(workdir, inputs)
    code, out, err = run_inprocess(args, capsys)
    assert_clean_failure(code, err)
    assert snapshot(workdir, inputs) == before, "a file was written or left behind"


REAL = [
    ["fit", "-o", "in"],
    ["export", "fmu", *K, "-o", "/proc/j.fmu"],
    ["fit", "--data", "in/semicolon.csv"],
    ["identify", "in/log_binary.csv"],
    ["export", "fmu", "--from", "in/sug_other.json"],
    ["suggest", "--k", "0.8", "--fix", "colour=red"],
    ["rig", "simulate", *K, "--duration", "1e9", "-o", "big.csv"],
    ["doe", "--augment", "100000"],
    ["cosim", "in/bad.toml", "-o", "in/good.csv"],
    ["clean", "in/empty.csv", "-o", "c.csv"],
    ["cosim", "in/diverge.toml", "-o", "res"],
]


@pytest.mark.parametrize("args", REAL, ids=[" ".join(a)[:50] for a in REAL])
def test_bad_input_real_process(args, workdir, inputs):
    before = snapshot(workdir, inputs)
    r = run_process(args, workdir, env=dict(os.environ))
    assert_clean_failure(r.returncode, r.stderr)
    assert r.stdout == ""
    assert snapshot(workdir, inputs) == before


def test_messages_name_the_problem(workdir, capsys):
    """The poor messages of issue 12, each now naming the problem and the fix."""
    expect = {
        ("fit", "--data", "in/semicolon.csv"): "separated by semicolons",
        ("fit", "--data", "in/binary.csv"): "binary data",
        ("suggest", "--k", "0.8", "--fix", "colour=red"): "unknown factor 'colour'",
        ("suggest", "--k", "0.8", "--fix", "width=3", "--fix", "width=5"): "given twice",
        ("export", "fmu", "--from", "in/sug_other.json"): "is not a suggestion: no 'axis'",
        ("export", "fmu", "--from", "in/sug_typo.json"): "did you mean 'candidates'",
        ("export", "fmu", "--from", "in/sug_range.json"): "density = 500 % cannot be printed",
        ("plot", "heatmap", "--data", "in/onerun.csv"): "a correlation needs at least 3 runs",
        ("fit", "--data", "in/density500.csv"): "row 6: density = 500 % cannot be printed",
        ("cosim", "in/typo.toml"): "did you mean 'duration'",
        ("cosim", "in/huge.toml"): "TiB",
        ("export", "mjcf", "--k", "1e300", "--c", "1"): "beyond any physical joint",
        ("identify", "in/side_typo.csv"): "did you mean 'load_delay_s'",
        ("rig", "simulate", *K, "--duration", "1e9", "-o", "big.csv"): "TiB",
        ("doe", "--augment", "100000"): "486",
        ("doe", "--all-continuous", "--augment", "3"): "--all-continuous",
        ("fit", "-o", "in"): "is a folder",
        ("rig", "simulate", *K, "-o", "l.xlsx"): "suffix '.xlsx'",
        ("cosim", str(EXAMPLES / "rig.toml"), "-o", "in/good.csv"): "is a file",
    }
    for args, text in expect.items():
        code, out, err = run_inprocess(list(args), capsys)
        assert code == 2 and text in err, (args, err)
    # the binary bytes of a file are never echoed back
    code, out, err = run_inprocess(["fit", "--data", "in/binary.csv"], capsys)
    assert all(ch.isprintable() or ch == "\n" for ch in err)
