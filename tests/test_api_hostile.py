"""Hypothesis over the Python API's arguments (issue 26): whatever value of whatever type reaches a
public function's argument (None, bools, huge and subnormal numbers, NaN, text, bytes, lists, dicts,
numpy arrays, DataFrames, arbitrary objects), it returns a result or raises `DesignerError`, never an
exception from numpy, pandas, concurrent.futures or Python itself."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
SUGGESTION = EXAMPLES / "suggestion.json"
ARM = EXAMPLES / "one_link.xml"
DESIGN = {"density": 60, "length": 24, "width": 4.5, "height": 9, "layer": 0.16, "raster": 0}


def _specials(table: pd.DataFrame) -> list:
    """The values every argument meets, each one (hypothesis adds random ones of the same kinds)."""
    return [
        None, True, 0, -1, -0.0, 5e-324, 1e308, float("nan"), float("inf"), "", "x", b"", [], {}, (),
        np.zeros((2, 3)), np.array([]), np.array(["a"]), np.float64(0.8), pd.DataFrame(), table.iloc[:2],
        object(), DESIGN, dict(DESIGN, width="w"), {"x": {"k": 0.8, "c": 2e-3}}, {"x": {"k": None, "c": 1}},
        ("a", 1), [0.8], ["x", 3],
    ]  # fmt: skip


def _values(specials: list):
    return st.one_of(
        st.integers(-(10**6), 10**6),
        st.floats(allow_nan=True, allow_infinity=True),
        st.text(max_size=8),
        st.binary(max_size=8),
        st.lists(st.floats(allow_nan=True), max_size=3),
        st.lists(st.text(max_size=4), max_size=3),
        st.dictionaries(st.text(max_size=6), st.floats(allow_nan=True) | st.text(max_size=3), max_size=3),
        st.sampled_from(specials),
    )


def _calls():
    import designer

    sur = designer.Surrogate.load()
    table = designer.load_table()
    joint = designer.Joint.from_design(DESIGN)
    t = np.arange(200) / 100
    log = pd.DataFrame({"t": t, "x": np.sin(3 * t), "Fx": np.cos(3 * t)})
    calls = {
        "suggest(k=)": lambda v: designer.suggest(sur, k=v),
        "suggest(c=)": lambda v: designer.suggest(sur, k=0.8, c=v),
        "suggest(fixed=)": lambda v: designer.suggest(sur, k=0.8, fixed=v),
        "suggest(top=)": lambda v: designer.suggest(sur, k=0.8, top=v),
        "suggest(axis=)": lambda v: designer.suggest(sur, k=0.8, axis=v),
        "suggest(tolerance=)": lambda v: designer.suggest(sur, k=0.8, tolerance=v),
        "suggest(bounds=)": lambda v: designer.suggest(sur, k=0.8, bounds=v),
        "suggest(importance=)": lambda v: designer.suggest(sur, k=0.8, importance=v),
        "predict(designs)": lambda v: sur.predict(v),
        "predict(responses=)": lambda v: sur.predict(DESIGN, responses=v),
        "Joint.from_coefficients": lambda v: designer.Joint.from_coefficients(v),
        "Joint.from_coefficients(axis)": lambda v: designer.Joint.from_coefficients({"x": v}),
        "Joint.from_coefficients(k)": lambda v: designer.Joint.from_coefficients({"x": {"k": v, "c": 1e-3}}),
        "Joint.from_design": lambda v: designer.Joint.from_design(v),
        "Joint.from_design(axes=)": lambda v: designer.Joint.from_design(DESIGN, axes=v),
        "Joint.from_design(name=)": lambda v: designer.Joint.from_design(DESIGN, name=v),
        "load_table": lambda v: designer.load_table(v),
        "Surrogate().fit": lambda v: designer.Surrogate().fit(v, nested=False),
        "Surrogate().fit(responses=)": lambda v: designer.Surrogate().fit(table, responses=v, nested=False),
        "identify": lambda v: designer.identify(v),
        "identify(axes=)": lambda v: designer.identify(log, axes=v),
        "calibrate(runs)": lambda v: designer.calibrate(sur, v),
        "calibrate(printer_sd=)": lambda v: designer.calibrate(sur, table.iloc[:2], printer_sd=v),
        "export_mjcf(path)": lambda v: designer.export_mjcf(joint, v),
        "export_fmu(fmi_version=)": lambda v: designer.export_fmu(joint, "j.fmu", fmi_version=v),
        "export_fmu(interface=)": lambda v: designer.export_fmu(joint, "j.fmu", interface=v),
        "export_modelica(msl=)": lambda v: designer.export_modelica(joint, "j.mo", msl=v),
        "export_urdf(axis=)": lambda v: designer.export_urdf(joint, "j.urdf", axis=v),
        "next_prints(n=)": lambda v: designer.next_prints(sur, k=0.8, n=v),
        "next_prints(stop=)": lambda v: designer.next_prints(sur, k=0.8, stop=v),
        "suggest(weight=)": lambda v: designer.suggest(sur, k=0.8, weight=v),
        "Surrogate.load": lambda v: designer.Surrogate.load(v),
        "from_suggestion(candidate=)": lambda v: designer.Joint.from_suggestion(SUGGESTION, candidate=v),
        "export_ssp(joints)": lambda v: designer.export_ssp(v, "j.ssp"),
        "export_mjcf(joint_name=)": lambda v: designer.export_mjcf(joint, "j.xml", into=ARM, joint_name=v),
        "identify(load_delay_s=)": lambda v: designer.identify(log, load_delay_s=v),
        "cosim.load": lambda v: designer.cosim.load(v),
        "sweep.load": lambda v: designer.sweep.load(v),
    }
    specials = _specials(table)
    return calls, specials, _values(specials)


CALLS, SPECIALS, VALUES = _calls()


@pytest.mark.parametrize("name", sorted(CALLS))
def test_any_argument_value_gives_a_result_or_a_designer_error(name, tmp_path, monkeypatch):
    from designer import DesignerError

    monkeypatch.chdir(tmp_path)
    call = CALLS[name]

    def one(value):
        try:
            call(value)
        except DesignerError:
            pass

    for value in SPECIALS:
        one(value)
    settings(max_examples=20, deadline=None, suppress_health_check=list(HealthCheck), database=None)(
        given(value=VALUES)(one)
    )()
