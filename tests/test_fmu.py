"""The joint FMU: validation, exact step response, force element, second importer, robustness, memcheck."""

from __future__ import annotations

import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Model, FMU2Slave
from fmpy.fmi3 import FMU3Model, FMU3Slave
from fmpy.validation import validate_fmu

from designer.errors import DesignerError
from designer.export import build
from designer.export.fmu import export_fmu, value_reference
from designer.joint import Joint

M, C, K, F = 0.01, 2e-3, 0.8, 2.744  # kg, N.s/mm, N/mm, N (the study's 280 g static load)
K_SI, C_SI = K * 1e3, C * 1e3
S, V, FV = value_reference("x", "s"), value_reference("x", "v"), value_reference("x", "f")


@pytest.fixture(scope="module", autouse=True)
def cache(fmu_cache):
    """Every test here builds into a throw-away cache."""


@pytest.fixture(scope="module")
def joint():
    return Joint.from_coefficients({"x": {"k": K, "c": C, "m": M}})


@pytest.fixture(scope="module")
def fmus(joint, tmp_path_factory):
    d = tmp_path_factory.mktemp("fmus")
    return {(v, i): export_fmu(joint, d / f"j{v}{i}.fmu", v, i) for v in (2, 3) for i in ("force", "body")}


def analytic(t: np.ndarray) -> np.ndarray:
    """Step response of m y'' + c y' + k y = F from rest (under-damped)."""
    wn = np.sqrt(K_SI / M)
    z = C_SI / (2 * np.sqrt(K_SI * M))
    wd = wn * np.sqrt(1 - z * z)
    return F / K_SI * (1 - np.exp(-z * wn * t) * (np.cos(wd * t) + z / np.sqrt(1 - z * z) * np.sin(wd * t)))


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("interface", ["force", "body"])
def test_validate_fmu_reports_no_problem(fmus, version, interface):
    path = fmus[(version, interface)]
    assert validate_fmu(str(path)) == []
    md = read_model_description(str(path))
    assert md.coSimulation and md.modelExchange
    units = {u.name for u in md.unitDefinitions}
    assert {"N/m", "N.s/m", "m", "N"} <= units
    names = {v.name for v in md.modelVariables}
    expected = {"x.m", "x.c", "x.k", "x.offset", "x.enabled", "x.s", "x.v", "x.f"}
    assert expected <= names and ("x.a" in names) == (interface == "body")
    k = next(v for v in md.modelVariables if v.name == "x.k")
    assert float(k.start) == K_SI and k.unit == "N/m" and k.causality == "parameter"


@pytest.mark.parametrize("interface", ["force", "body"])
def test_fmi2_start_values_follow_the_spec_and_the_fmi_library_parses_quietly(fmus, interface):
    path = fmus[(2, interface)]
    for v in read_model_description(str(path)).modelVariables:
        # FMI 2 section 2.2.7: a start is required for parameters, inputs and initial exact/approx,
        # forbidden otherwise and on the independent variable (left implicit, see export/fmu.py)
        assert v.causality != "independent"
        needs = v.causality in ("parameter", "input") or v.initial in ("exact", "approx")
        assert (v.start is not None) == needs, v.name
    script = (
        "import sys\n"
        "from libcosimpy.CosimExecution import CosimExecution\n"
        "from libcosimpy.CosimLogging import CosimLogLevel, log_output_level\n"
        "from libcosimpy.CosimSlave import CosimLocalSlave\n"
        "log_output_level(CosimLogLevel.WARNING)\n"
        "ex = CosimExecution.from_step_size(step_size=1_000_000)\n"
        "slave = CosimLocalSlave(fmu_path=sys.argv[1], instance_name='j')\n"
        "print('index', ex.add_local_slave(local_slave=slave))\n"
    )
    r = subprocess.run([sys.executable, "-c", script, str(path)], capture_output=True, text=True)
    assert r.returncode == 0 and "index 0" in r.stdout, r.stderr
    assert "Start attribute is required" not in r.stdout + r.stderr
    assert "[error]" not in r.stdout + r.stderr and "[warning]" not in r.stdout + r.stderr


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("fmi_type, tol", [("CoSimulation", 1e-9), ("ModelExchange", 1e-5)])
def test_body_step_response_matches_analytic(fmus, version, fmi_type, tol):
    r = simulate_fmu(
        str(fmus[(version, "body")]),
        fmi_type=fmi_type,
        stop_time=2.0,
        step_size=1e-3,
        output_interval=1e-3,
        relative_tolerance=1e-10,
        start_values={"x.f": F},
        output=["x.s", "x.v", "x.a"],
    )
    exact = analytic(r["time"])
    rel = np.max(np.abs(r["x.s"] - exact)) / np.max(np.abs(exact))
    assert rel <= tol
    assert r["x.s"][-1] == pytest.approx(F / K_SI, rel=1e-9)  # settles at F/k
    assert abs(r["x.a"][-1]) < 1e-6


def test_body_cs_is_exact_at_a_coarse_step(fmus):
    """ZOH is exact for a constant load at any step: 20 ms is well beyond the 22 ms period here."""
    r = simulate_fmu(
        str(fmus[(2, "body")]),
        stop_time=1.0,
        step_size=0.02,
        output_interval=0.02,
        start_values={"x.f": F},
        output=["x.s"],
    )
    assert np.max(np.abs(r["x.s"] - analytic(r["time"]))) <= 1e-9 * F / K_SI


def _slave(path, version, name="joint"):
    d = extract(str(path))
    md = read_model_description(d)
    cls = FMU2Slave if version == 2 else FMU3Slave
    fmu = cls(
        guid=md.guid, unzipDirectory=d, modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name
    )
    return fmu, d


def _start(fmu, version):
    fmu.instantiate()
    if version == 2:
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
    else:
        fmu.enterInitializationMode(startTime=0.0)
    fmu.exitInitializationMode()


def _set(fmu, version, vrs, values):
    (fmu.setReal if version == 2 else fmu.setFloat64)(vrs, values)


def _get(fmu, version, vrs):
    return (fmu.getReal if version == 2 else fmu.getFloat64)(vrs)


@pytest.mark.parametrize("version", [2, 3])
def test_force_element_answers_at_the_same_instant(fmus, version):
    """Model Exchange defines set inputs, read outputs at one instant (co-simulation does not)."""
    d = extract(str(fmus[(version, "force")]))
    md = read_model_description(d)
    cls = FMU2Model if version == 2 else FMU3Model
    fmu = cls(
        guid=md.guid, unzipDirectory=d, modelIdentifier=md.modelExchange.modelIdentifier, instanceName="j"
    )
    _start(fmu, version)
    fmu.enterContinuousTimeMode()
    for i, (s, v) in enumerate([(1e-3, 0.0), (-2e-3, 0.05), (3.7e-4, -0.2)]):
        fmu.setTime(i * 1e-3)
        _set(fmu, version, [S, V], [s, v])
        assert _get(fmu, version, [FV])[0] == -(K_SI * s + C_SI * v)  # exactly, at the same instant
    fmu.terminate()
    fmu.freeInstance()
    shutil.rmtree(d)


def test_libcosimpy_runs_the_fmi2_cs_fmu(fmus):
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    log_output_level(CosimLogLevel.ERROR)
    ex = CosimExecution.from_step_size(step_size=1_000_000)  # 1 ms in ns
    index = ex.add_local_slave(
        local_slave=CosimLocalSlave(fmu_path=str(fmus[(2, "body")]), instance_name="j")
    )
    obs = CosimObserver.create_last_value()
    ex.add_observer(observer=obs)
    ex.real_initial_value(slave_index=index, variable_reference=FV, value=F)
    s = []
    for _ in range(500):
        ex.step()
        s.append(obs.last_real_values(slave_index=index, variable_references=[S])[0])
    t = np.arange(1, 501) * 1e-3
    assert np.max(np.abs(np.array(s) - analytic(t))) <= 1e-9 * F / K_SI


def test_calls_out_of_order_return_an_error(fmus):
    fmu, d = _slave(fmus[(2, "body")], 2)
    fmu.instantiate()
    with pytest.raises(FMICallException) as exc:
        fmu.doStep(0.0, 1e-3)  # before initialization
    assert exc.value.status == 3  # fmi2Error
    fmu.freeInstance()
    shutil.rmtree(d)


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("value", [float("nan"), float("inf")])
def test_non_finite_input_or_parameter_is_an_error(fmus, version, value):
    fmu, d = _slave(fmus[(version, "force")], version)
    _start(fmu, version)
    for vr in (S, value_reference("x", "k")):
        with pytest.raises(FMICallException):
            _set(fmu, version, [vr], [value])
        fmu.reset()
        _start_after_reset(fmu, version)
    fmu.freeInstance()
    shutil.rmtree(d)


def _start_after_reset(fmu, version):
    if version == 2:
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
    else:
        fmu.enterInitializationMode(startTime=0.0)
    fmu.exitInitializationMode()


def test_invalid_parameters_are_rejected(fmus):
    fmu, d = _slave(fmus[(2, "body")], 2)
    _start(fmu, 2)
    for field, bad in (("m", 0.0), ("k", -1.0), ("c", -1.0)):
        with pytest.raises(FMICallException):
            fmu.setReal([value_reference("x", field)], [bad])
        fmu.reset()
        _start_after_reset(fmu, 2)
    with pytest.raises(FMICallException):
        fmu.setReal([S], [1.0])  # a state after initialization
    fmu.freeInstance()
    shutil.rmtree(d)


def test_thousand_instantiations_and_two_instances(fmus):
    fmu, d = _slave(fmus[(2, "force")], 2)
    for _ in range(1000):
        fmu.instantiate()  # raises if the FMU returns NULL
        fmu.fmi2FreeInstance(fmu.component)  # fmpy's freeInstance also unloads the library
    fmu.freeLibrary()
    a = FMU2Slave(guid=fmu.guid, unzipDirectory=d, modelIdentifier="FlexJoint", instanceName="a")
    b = FMU2Slave(guid=fmu.guid, unzipDirectory=d, modelIdentifier="FlexJoint", instanceName="b")
    _start(a, 2)
    _start(b, 2)
    a.setReal([value_reference("x", "k")], [100.0])
    b.setReal([value_reference("x", "k")], [300.0])
    for x in (a, b):
        x.setReal([S, V], [0.01, 0.0])
    assert a.getReal([FV])[0] == -1.0 and b.getReal([FV])[0] == -3.0
    a.freeInstance()
    b.freeInstance()
    shutil.rmtree(d)


def test_wrong_token_fails_to_instantiate(fmus):
    d = extract(str(fmus[(2, "force")]))
    fmu = FMU2Slave(guid="{not-this-fmu}", unzipDirectory=d, modelIdentifier="FlexJoint", instanceName="x")
    with pytest.raises(Exception, match="instantiate"):
        fmu.instantiate()
    shutil.rmtree(d)


@pytest.mark.parametrize("version", [2, 3])
def test_get_set_and_serialize_fmu_state(fmus, version):
    fmu, d = _slave(fmus[(version, "body")], version)
    _start(fmu, version)
    _set(fmu, version, [FV], [F])
    for i in range(10):
        fmu.doStep(i * 1e-3, 1e-3)
    state = fmu.getFMUState()
    data = fmu.serializeFMUState(state)
    fmu.doStep(0.01, 1e-3)
    after = _get(fmu, version, [S, V])
    for restore in (state, fmu.deserializeFMUState(data) if version == 3 else fmu.deSerializeFMUstate(data)):
        fmu.setFMUState(restore)
        fmu.doStep(0.01, 1e-3)
        assert _get(fmu, version, [S, V]) == after
    fmu.freeInstance()
    shutil.rmtree(d)


def test_directional_derivatives_of_the_force(fmus):
    fmu, d = _slave(fmus[(2, "force")], 2)
    _start(fmu, 2)
    assert fmu.getDirectionalDerivative([FV], [S, V], [1.0, 0.0]) == [-K_SI]
    assert fmu.getDirectionalDerivative([FV], [S, V], [0.0, 1.0]) == [-C_SI]
    fmu.freeInstance()
    shutil.rmtree(d)


def test_same_joint_gives_identical_bytes_and_other_joint_another_token(joint, tmp_path):
    a = export_fmu(joint, tmp_path / "a.fmu", 3, "body")
    b = export_fmu(joint, tmp_path / "b.fmu", 3, "body")
    assert a.read_bytes() == b.read_bytes()
    other = Joint.from_coefficients({"x": {"k": 0.9, "c": C, "m": M}})
    c = export_fmu(other, tmp_path / "c.fmu", 3, "body")
    tokens = {read_model_description(str(p)).guid for p in (a, c)}
    assert len(tokens) == 2


def test_archive_carries_sources_resources_and_provenance(fmus):
    with zipfile.ZipFile(fmus[(3, "body")]) as z:
        names = set(z.namelist())
        assert {"sources/buildDescription.xml", "sources/model.c", "sources/fmi3Functions.c"} <= names
        assert "resources/joint.json" in names and "binaries/x86_64-linux/FlexJoint.so" in names
        assert b"entered by hand" in z.read("resources/joint.json")
    with zipfile.ZipFile(fmus[(2, "force")]) as z:
        assert "sources/fmi2Functions.c" in z.namelist() and "binaries/linux64/FlexJoint.so" in z.namelist()


def test_warm_export_does_not_compile(joint, tmp_path, monkeypatch):
    export_fmu(joint, tmp_path / "first.fmu")

    def fail(*args, **kwargs):
        raise AssertionError("the compiler ran on a warm export")

    monkeypatch.setattr(build.subprocess, "run", fail)
    export_fmu(joint, tmp_path / "second.fmu")


def test_missing_compiler_message_and_source_only(joint, tmp_path, monkeypatch):
    monkeypatch.setenv("CC", "no-such-compiler-xyz")
    monkeypatch.setattr(build, "zig_available", lambda: False)
    with pytest.raises(DesignerError, match="source_only=True"):
        export_fmu(joint, tmp_path / "j.fmu", platforms="host", rebuild=True)
    with pytest.raises(DesignerError, match=r"flexjoint-designer\[build\]"):
        export_fmu(joint, tmp_path / "j.fmu", platforms="x86_64-windows", rebuild=True)
    # without a compiler the shipped binaries still export, for every platform
    with zipfile.ZipFile(export_fmu(joint, tmp_path / "j.fmu")) as z:
        assert len([n for n in z.namelist() if n.startswith("binaries/")]) == len(build.PLATFORMS)
    path = export_fmu(joint, tmp_path / "j.fmu", 3, source_only=True)
    with zipfile.ZipFile(path) as z:
        assert not any(n.startswith("binaries/") for n in z.namelist())
        assert "sources/buildDescription.xml" in z.namelist()


def test_body_interface_without_mass_is_refused(tmp_path):
    with pytest.raises(DesignerError, match="needs a mass"):
        export_fmu(Joint.from_coefficients({"x": {"k": K, "c": C}}), tmp_path / "j.fmu", interface="body")


def test_sources_rebuild_into_a_working_binary(fmus, tmp_path):
    """The shipped sources/ compile on their own (what an importer on another platform does)."""
    if shutil.which("cc") is None:
        pytest.skip("no C compiler")
    d = extract(str(fmus[(2, "body")]))
    src = f"{d}/sources"
    out = tmp_path / "rebuilt.so"
    cmd = [
        "cc",
        *build.FLAGS,
        f"-I{src}",
        *(f"{src}/{Path(n).name}" for n in build.c_sources(2)),
    ]
    subprocess.run([*cmd, "-o", str(out), "-lm"], check=True)
    shutil.copy(out, f"{d}/binaries/linux64/FlexJoint.so")
    r = simulate_fmu(d, stop_time=0.2, step_size=1e-3, start_values={"x.f": F}, output=["x.s"])
    assert np.max(np.abs(r["x.s"] - analytic(r["time"]))) <= 1e-9 * F / K_SI
    shutil.rmtree(d)


DRIVER = r"""
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "fmi2Functions.h"
static void logger(fmi2ComponentEnvironment e, fmi2String n, fmi2Status s, fmi2String c, fmi2String m, ...) {
    (void)e; (void)n; (void)s; (void)c; (void)m;
}
int main(int argc, char **argv) {
    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    fmi2ValueReference f = @F@, s = @S@, k = @K@; /* fmus/FlexJoint/config.h */
    fmi2Real load = 2.744, x = 0, nan = NAN;
    fmi2FMUstate st = NULL;
    size_t n;
    int i, j;
    (void)argc;
    for (j = 0; j < 20; j++) {
        fmi2Component c = fmi2Instantiate("m", fmi2CoSimulation, argv[2], argv[1], &cb, 0, 1);
        if (!c) return 2;
        if (fmi2DoStep(c, 0, 1e-3, 0) != fmi2Error) return 3;
        fmi2Reset(c);
        fmi2SetupExperiment(c, 0, 0, 0, 0, 0);
        fmi2EnterInitializationMode(c);
        fmi2ExitInitializationMode(c);
        fmi2SetReal(c, &f, 1, &load);
        for (i = 0; i < 100; i++) fmi2DoStep(c, i * 1e-3, 1e-3, 0);
        fmi2GetFMUstate(c, &st);
        fmi2SerializedFMUstateSize(c, st, &n);
        {
            fmi2Byte *buf = malloc(n);
            fmi2SerializeFMUstate(c, st, buf, n);
            fmi2FreeFMUstate(c, &st);
            fmi2DeSerializeFMUstate(c, buf, n, &st);
            free(buf);
        }
        fmi2SetFMUstate(c, st);
        fmi2FreeFMUstate(c, &st);
        fmi2GetReal(c, &s, 1, &x);
        if (fmi2SetReal(c, &k, 1, &nan) != fmi2Error) return 4;
        fmi2FreeInstance(c);
    }
    printf("%.17g\n", x);
    return 0;
}
"""


def test_memcheck_is_clean(fmus, tmp_path):
    if shutil.which("valgrind") is None or shutil.which("cc") is None:
        pytest.skip("valgrind or cc not installed")
    d = extract(str(fmus[(2, "body")]))
    src = f"{d}/sources"
    driver = DRIVER
    for field in ("f", "s", "k"):
        driver = driver.replace(f"@{field.upper()}@", str(value_reference("x", field)))
    (tmp_path / "driver.c").write_text(driver)
    exe = tmp_path / "driver"
    files = [f"{src}/{Path(n).name}" for n in build.c_sources(2)]
    subprocess.run(
        [
            "cc",
            "-std=gnu99",
            "-g",
            "-O1",
            f"-I{src}",
            str(tmp_path / "driver.c"),
            *files,
            "-o",
            str(exe),
            "-lm",
        ],
        check=True,
    )
    guid = read_model_description(d).guid
    done = subprocess.run(
        [
            "valgrind",
            "--error-exitcode=9",
            "--leak-check=full",
            "--errors-for-leak-kinds=definite,indirect",
            str(exe),
            f"file://{d}/resources",
            guid,
        ],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    assert float(done.stdout) == pytest.approx(analytic(np.array([0.1]))[0], rel=1e-9)
    shutil.rmtree(d)
