"""The public Python API: names, misuse answered with DesignerError naming the argument, no CLI talk."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import designer
from designer import DesignerError

DESIGN = {"density": 60, "length": 24, "width": 4.5, "height": 9, "layer": 0.16, "raster": 0}
LIBRARY = Path(designer.__file__).resolve().parent


def test_public_names_are_there_and_documented():
    for name in designer.__all__:
        obj = getattr(designer, name)
        assert obj.__doc__, name
    assert list(designer.load_table().columns[:6]) == list(designer.study.space.FACTOR_NAMES)
    assert callable(designer.cosim.run) and callable(designer.cosim.write_outputs)


def test_fit_on_a_raw_table_names_the_missing_column():
    raw = pd.DataFrame({"infill": [60] * 10, "k_x": [0.8] * 10})
    with pytest.raises(DesignerError, match="missing factor column"):
        designer.Surrogate().fit(raw)


def test_a_misnamed_response_is_refused():
    table = designer.load_table()
    with pytest.raises(DesignerError, match=r"responses=\['k_y'\] names column\(s\) the table lacks: k_y"):
        designer.Surrogate().fit(table, responses=["k_y"])


def test_a_nan_response_is_refused_with_column_and_row():
    table = designer.load_table()
    table.loc[5, "k_x"] = np.nan
    with pytest.raises(DesignerError, match="column 'k_x' row 6"):
        designer.Surrogate().fit(table)


def test_an_unfitted_surrogate_does_not_predict():
    with pytest.raises(DesignerError, match="not fitted"):
        designer.Surrogate().predict(DESIGN)
    from designer.model.prediction import ResponseSurface

    with pytest.raises(DesignerError, match="not fitted"):
        ResponseSurface("k_x", "linear").predict({k: [v] for k, v in DESIGN.items()})


def test_predict_checks_ranges_unless_extrapolation_is_allowed():
    sur = designer.Surrogate.load()
    with pytest.raises(DesignerError, match="density = 300 % is outside the tested range"):
        sur.predict(DESIGN | {"density": 300})
    with pytest.raises(DesignerError, match="allow_extrapolation=True"):
        sur.predict(DESIGN | {"width": 8})
    wide = sur.predict(DESIGN | {"width": 8}, allow_extrapolation=True)["k_x"]
    assert wide.low[0] < wide.value[0] < wide.high[0]


def test_one_prediction_shape_everywhere():
    sur = designer.Surrogate.load()
    p = sur.predict(DESIGN, responses=["k_x"])["k_x"]
    assert isinstance(p, designer.Prediction) and p.value.shape == (1,)
    one = p.at(0)
    assert one.to_dict() == {"value": one.value, "low": one.low, "high": one.high}
    assert designer.Prediction.from_dict(one.to_dict()) == one
    sug = designer.suggest(sur, k=0.8, top=2)
    assert isinstance(sug.candidates[0].predicted["k"], designer.Prediction)
    assert set(sug.to_dict()["candidates"][0]["predicted"]["k"]) == {"value", "low", "high"}
    joint = designer.Joint.from_suggestion(sug, candidate=1)
    assert joint.axes["x"].predicted["k"] == sug.candidates[0].predicted["k"]
    assert joint.to_dict()["axes"]["x"]["predicted"]["k"] == sug.candidates[0].predicted["k"].to_dict()


@pytest.mark.parametrize(
    "writer, suffix",
    [
        ("export_fmu", ".mo"),
        ("export_modelica", ".fmu"),
        ("export_mjcf", ".mo"),
        ("export_urdf", ".xml"),
        ("export_usd", ".xml"),
    ],
)
def test_a_writer_refuses_a_suffix_that_is_not_its_format(tmp_path, writer, suffix):
    joint = designer.Joint.from_coefficients({"x": {"k": 0.8, "c": 2e-3, "m": 0.01}})
    with pytest.raises(DesignerError, match="path"):
        getattr(designer, writer)(joint, tmp_path / f"joint{suffix}")
    assert list(tmp_path.iterdir()) == []


def test_export_fmu_names_its_arguments(tmp_path):
    joint = designer.Joint.from_coefficients({"x": {"k": 0.8, "c": 2e-3}})
    with pytest.raises(DesignerError, match=r"fmi_version=4 .*use fmi_version=2 or 3"):
        designer.export_fmu(joint, tmp_path / "j.fmu", fmi_version=4)


def _strings(node: ast.AST) -> list[str]:
    return [n.value for n in ast.walk(node) if isinstance(n, ast.Constant) and isinstance(n.value, str)]


def test_library_messages_name_python_arguments_and_the_library_never_prints():
    flag = re.compile(r"(?<![\w-])--[a-z][a-z-]*")
    found = []
    for path in sorted(LIBRARY.rglob("*.py")):
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            if not isinstance(node, ast.Call):
                continue
            name = getattr(node.func, "id", getattr(node.func, "attr", ""))
            if name == "print":
                found.append(f"{path.name}:{node.lineno} print()")
            if name == "DesignerError":
                for text in _strings(node):
                    for m in flag.findall(text.replace(" --version'", "").replace("cc --version", "")):
                        found.append(f"{path.name}:{node.lineno} {m}")
    assert not found, found


def test_no_function_of_the_library_or_the_cli_is_over_80_lines():
    """The style rule (small functions that say what they do), kept by a scan of the installed code."""
    import designer_cli

    long = []
    for root in (LIBRARY, Path(designer_cli.__file__).parent):
        for path in sorted(root.rglob("*.py")):
            for node in ast.walk(ast.parse(path.read_text())):
                if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                    lines = node.end_lineno - node.lineno + 1
                    if lines > 80:
                        long.append(f"{path.name}:{node.lineno} {node.name} ({lines} lines)")
    assert not long, long


def test_the_api_tour_runs_with_public_names_only(tmp_path):
    import subprocess
    import sys

    script = Path(__file__).resolve().parent.parent / "examples" / "api_tour.py"
    text = script.read_text()
    tree = ast.parse(text)
    imports = {a.name for n in ast.walk(tree) if isinstance(n, (ast.Import, ast.ImportFrom)) for a in n.names}
    assert imports == {"sys", "Path", "designer"}
    used = {
        n.attr
        for n in ast.walk(tree)
        if isinstance(n, ast.Attribute) and getattr(n.value, "id", "") == "designer"
    }
    assert used <= set(designer.__all__), used - set(designer.__all__)
    code = [line for line in text.splitlines() if line.strip() and not line.lstrip().startswith("#")]
    body = code[code.index('"""') + 1 :] if '"""' in code else code
    assert len(body) < 30, len(body)
    run = subprocess.run([sys.executable, "-I", str(script), str(tmp_path)], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert "k_x = " in run.stdout and "overshoot" in run.stdout
    assert {p.name for p in tmp_path.iterdir()} == {"joint.fmu", "arm.toml"}


def test_public_functions_are_not_hidden_by_submodules():
    import importlib

    for module in (
        "designer.design.suggestions",
        "designer.model.surrogate",
        "designer.joint",
        "designer.rig.identify",
    ):
        importlib.import_module(module)
    assert callable(designer.suggest) and not isinstance(designer.suggest, type(designer))
    assert callable(designer.identify) and not isinstance(designer.identify, type(designer))
