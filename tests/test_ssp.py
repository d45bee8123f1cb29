"""SSP export: the SSD validates against the SSP 1.0 schemas and runs in fmpy.ssp like the FMU alone."""

from __future__ import annotations

import zipfile
from pathlib import Path

import numpy as np
import pytest

from designer import Joint
from designer.errors import DesignerError
from designer.export.ssp import export_ssp, read_ssv
from designer.validate.export import libcosim_ssp_run, ssp_with_value, step_response

JOINT = Joint.from_coefficients({"x": {"k": 0.8, "c": 2e-3, "m": 0.01}})
STIFFER = Joint.from_coefficients({"x": {"k": 1.6, "c": 4e-3, "m": 0.01}})
#: the SSV the SSD binds to the joint's component
SSV = "resources/FlexJoint.ssv"


def constant(value: float):
    """A load held at `value` from t = 0."""
    return lambda t: value


def test_ssd_runs_in_fmpy_like_the_fmus_and_alternatives_are_parameter_sets(tmp_path):
    from fmpy import simulate_fmu
    from fmpy.ssp.simulation import simulate_ssp
    from fmpy.ssp.ssd import ParameterSet, read_ssd
    from fmpy.ssp.ssd import read_ssv as fmpy_read_ssv

    wrist = Joint.from_coefficients({"theta": {"k": 50.0, "c": 0.5, "m": 1e-5}}, name="Wrist")
    path = export_ssp(
        [JOINT, wrist],
        tmp_path / "joints.ssp",
        alternatives={"FlexJoint": {"stiffer": STIFFER}},
        system_connectors=True,
    )
    ssd = read_ssd(str(path))  # validates against the normative SSP 1.0 schemas FMPy ships
    bound = {c.name: c.parameterBindings[0].source for c in ssd.system.elements}
    assert bound == {"FlexJoint": "resources/FlexJoint.ssv", "Wrist": "resources/Wrist.ssv"}
    with zipfile.ZipFile(path) as z:
        z.extractall(tmp_path / "ssp")
    assert read_ssv(tmp_path / "ssp/resources/FlexJoint.stiffer.ssv") == {
        "x.m": 0.01,
        "x.c": 4.0,
        "x.k": 1600.0,
    }
    assert read_ssv(tmp_path / "ssp/resources/Wrist.ssv") == {
        "theta.m": 1e-5,
        "theta.c": 5e-4,
        "theta.k": 0.05,
    }
    h, stop, loads = 1e-4, 0.05, {"FlexJoint_x.f": 2.0, "Wrist_theta.f": 0.01}
    runs = {}
    for name, sources in (
        ("bound", {"FlexJoint": "resources/FlexJoint.ssv", "Wrist": "resources/Wrist.ssv"}),
        ("stiffer", {"FlexJoint": "resources/FlexJoint.stiffer.ssv", "Wrist": "resources/Wrist.ssv"}),
    ):
        ps = ParameterSet(name=name)  # fmpy.ssp applies one set, by component-prefixed names
        for component, source in sources.items():
            for p in fmpy_read_ssv(str(path), resource=source).parameters:
                p.name = f"{component}.{p.name}"
                ps.parameters.append(p)
        inputs = {n: constant(v) for n, v in loads.items()}
        runs[name] = simulate_ssp(str(path), stop_time=stop, step_size=h, parameter_set=ps, input=inputs)
    # fmpy.ssp passes connections after each step, so a load reaches the FMU one step late and the
    # output recorded at t after stepping to t + h is the undelayed response at t
    t = runs["bound"]["time"]
    alone = simulate_fmu(
        str(tmp_path / "ssp/resources/FlexJoint.fmu"),
        stop_time=stop,
        step_size=h,
        output_interval=h,
        input=np.array([(0.0, 2.0), (stop, 2.0)], dtype=[("time", float), ("x.f", float)]),
        output=["x.s"],
    )
    x = runs["bound"]["FlexJoint_x.s"]
    assert np.allclose(x, np.interp(t, alone["time"], alone["x.s"]), rtol=0, atol=1e-12)
    assert np.max(np.abs(x - step_response(0.01, 2.0, 800.0, 2.0, t))) < 1e-9
    assert np.max(np.abs(runs["bound"]["Wrist_theta.s"] - step_response(1e-5, 5e-4, 0.05, 0.01, t))) < 1e-9
    assert np.max(np.abs(runs["stiffer"]["FlexJoint_x.s"] - step_response(0.01, 4.0, 1600.0, 2.0, t))) < 1e-9


def test_doubling_k_in_the_ssv_halves_the_deflection_in_fmpy_and_libcosim(tmp_path):
    """Both SSP runners apply the SSD's parameter binding: k edited in the SSV alone changes the run."""
    pytest.importorskip("libcosimpy")
    from fmpy.ssp.simulation import simulate_ssp

    from designer.export.ssp import bound_parameters, fmpy_parameter_set

    load, k = 2.0, 800.0  # N, N/m: 2.5 mm static deflection
    default = export_ssp(JOINT, tmp_path / "j.ssp")
    stiff = ssp_with_value(default, tmp_path / "stiff.ssp", ssv=SSV, parameter="x.k", value=2 * k)
    assert bound_parameters(stiff)["FlexJoint.x.k"] == 2 * k
    # libcosim: every connection needs startElement and endElement, so the default SSD has none
    assert b"<ssd:Connection " not in zipfile.ZipFile(default).read("SystemStructure.ssd")
    got = [
        libcosim_ssp_run(p, element="FlexJoint", load=("x.f", load), output="x.s")[-1]
        for p in (default, stiff)
    ]
    assert got == pytest.approx([load / k, load / (2 * k)], rel=1e-9)
    # fmpy.ssp drives the system's connectors (system_connectors=True) and applies the set it is given
    wired = export_ssp(JOINT, tmp_path / "w.ssp", system_connectors=True)
    stiff_wired = ssp_with_value(wired, tmp_path / "stiff_w.ssp", ssv=SSV, parameter="x.k", value=2 * k)
    runs = [
        simulate_ssp(
            str(p),
            stop_time=0.5,
            step_size=1e-3,
            parameter_set=fmpy_parameter_set(p),
            input={"FlexJoint_x.f": constant(load)},
        )["FlexJoint_x.s"][-1]
        for p in (wired, stiff_wired)
    ]
    assert runs == pytest.approx([load / k, load / (2 * k)], rel=1e-9)


def test_ssp_refuses_wrong_suffix_and_foreign_alternatives(tmp_path):
    with pytest.raises(DesignerError, match="path="):
        export_ssp(JOINT, tmp_path / "j.zip")
    theta = Joint.from_coefficients({"theta": {"k": 50.0, "c": 0.5, "m": 1e-5}})
    with pytest.raises(DesignerError, match="alternatives"):
        export_ssp(JOINT, tmp_path / "j.ssp", alternatives={"FlexJoint": {"a": theta}})
    with pytest.raises(DesignerError, match="same name"):
        export_ssp([JOINT, STIFFER], tmp_path / "j.ssp")


def test_read_ssv_converts_declared_units_and_refuses_wrong_ones(tmp_path):
    n_per_mm = '<ssc:Unit name="N/mm"><ssc:BaseUnit kg="1" s="-2" factor="1000"/></ssc:Unit>'

    def ssv(name: str, unit: str) -> Path:
        p = tmp_path / "p.ssv"
        p.write_text(
            '<ssv:ParameterSet xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues" '
            'xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon" version="1.0" name="p">'
            f'<ssv:Parameters><ssv:Parameter name="{name}"><ssv:Real value="0.8" unit="{unit}"/>'
            f"</ssv:Parameter></ssv:Parameters><ssv:Units>{n_per_mm}</ssv:Units></ssv:ParameterSet>"
        )
        return p

    # N/mm as the file declares it: kg s-2 with factor 1000 (SSP: SI = factor * value + offset)
    assert read_ssv(ssv("x.k", "N/mm"))["x.k"] == pytest.approx(800.0)
    assert read_ssv(ssv("x.k", "N/m"))["x.k"] == 0.8
    with pytest.raises(DesignerError, match="parameter x.c .* not a unit of N.s/m"):
        read_ssv(ssv("x.c", "N/mm"))
    with pytest.raises(DesignerError, match="not a unit of N/m"):
        read_ssv(ssv("x.k", "lbf/in"))  # neither declared nor SI


def test_cli_exports_every_candidate_as_a_parameter_set(tmp_path):
    import subprocess
    import sys
    from pathlib import Path

    suggestion = Path(__file__).resolve().parents[1] / "examples" / "suggestion.json"
    out = tmp_path / "joint.ssp"
    cmd = "from designer_cli.main import main; main()"
    args = ["export", "ssp", "--from", str(suggestion), "--candidate", "2", "-o", str(out)]
    r = subprocess.run([sys.executable, "-I", "-c", cmd, *args], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    with zipfile.ZipFile(out) as z:
        names = z.namelist()
        ssd = z.read("SystemStructure.ssd").decode()
    assert {"resources/FlexJoint.candidate_1.ssv", "resources/FlexJoint.candidate_2.ssv"} <= set(names)
    assert 'source="resources/FlexJoint.ssv"' in ssd
    r = subprocess.run(
        [sys.executable, "-I", "-c", cmd, "export", "ssp", "--k", "0.8", "--c", "2e-3", "-o", str(out)],
        capture_output=True,
        text=True,
    )
    assert r.returncode == 2 and "body interface needs a mass" in r.stderr and "Traceback" not in r.stderr
