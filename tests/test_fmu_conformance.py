"""The joint FMU against the FMI 2.0 and 3.0 texts: each deviation D1..D15 found in issue 13, driven
through ctypes with the exact calling sequence, checking the status and, where the standard asks for
one, the log message. Each test's docstring says how the FMU failed before."""

from __future__ import annotations

import ctypes as C
import math
import re
import struct
import subprocess
import sys
import zipfile
from xml.etree import ElementTree

import numpy as np
import pytest
from fmi_calls import CS, DISCARD, ERROR, ME, OK, Fmu, doubles, unpack, vrs

from designer.export.fmu import export_fmu, value_reference
from designer.joint import Joint

M, C_SI, K_SI = 0.01, 2.0, 800.0  # kg, N.s/m, N/m
VR = {f: value_reference("x", f) for f in ("m", "c", "k", "offset", "enabled", "s", "v", "f", "a")}


@pytest.fixture(scope="module", autouse=True)
def cache(fmu_cache):
    """Every test here builds into a throw-away cache."""


@pytest.fixture(scope="module")
def paths(tmp_path_factory):
    d = tmp_path_factory.mktemp("fmus")
    joint = Joint.from_coefficients({"x": {"k": K_SI / 1e3, "c": C_SI / 1e3, "m": M}})
    return {(v, i): export_fmu(joint, d / f"j{v}{i}.fmu", v, i) for v in (2, 3) for i in ("force", "body")}


@pytest.fixture(scope="module")
def fmu(paths, tmp_path_factory):
    """fmu[(version, interface)]: the loaded binary of that export."""
    return {key: Fmu(*unpack(p, tmp_path_factory.mktemp(f"u{key[0]}{key[1]}"))) for key, p in paths.items()}


def _errors(f: Fmu) -> list[str]:
    return [m for s, _, m in f.log if s == ERROR]


def test_d1_fmi2_log_messages_are_safe_printf_formats(fmu):
    """Before: the instance name went into the message unescaped; an importer's printf-style logger
    (libcosim) read `%s` conversions with no arguments and crashed inside fmi2Instantiate."""
    f = fmu[(2, "force")]
    f.log.clear()
    name = "joint%s%s%s%s"
    c = f.instantiate(CS, name=name)
    assert c
    assert f("fmi2DoStep", c, 0.0, 1e-3, 0) == ERROR  # an error logged in Instantiated
    assert f.log, "logging is on: instantiation and the error are logged"
    libc = C.CDLL(None)
    for _, _, message in f.log:
        assert "%" not in message.replace("%%", ""), message  # every '%' is a literal '%%'
        buf = C.create_string_buffer(4096)
        libc.snprintf(buf, C.c_size_t(4096), message.encode())  # what a printf-style logger does
        assert "%" not in message or "%s" in buf.value.decode()
    assert any(
        name in (C.create_string_buffer(m.replace("%%", "%").encode()).value.decode()) for _, _, m in f.log
    )
    f.free(c)


LIBCOSIM = """
import sys
from libcosimpy.CosimExecution import CosimExecution
from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
from libcosimpy.CosimSlave import CosimLocalSlave
log_output_level(CosimLogLevel.ERROR)
ex = CosimExecution.from_step_size(step_size=1_000_000)
ex.add_local_slave(local_slave=CosimLocalSlave(fmu_path=sys.argv[1], instance_name="joint%s%s%s%s"))
for _ in range(10):
    ex.step()
print("stepped")
"""


def test_d1_libcosim_runs_an_instance_named_with_percent_signs(paths):
    """Before: libcosim (a printf-style FMI 2 logger) crashed with SIGSEGV inside fmi2Instantiate."""
    pytest.importorskip("libcosimpy")
    done = subprocess.run(
        [sys.executable, "-I", "-c", LIBCOSIM, str(paths[(2, "body")])], capture_output=True, text=True
    )
    assert done.returncode == 0 and done.stdout.strip() == "stepped", done.stderr[-2000:]


def _me_at(f: Fmu, interface: str, *, s=1.5e-3, v=-0.02, offset=2e-4, load=0.3):
    c = f.instantiate(ME)
    f.start(c)
    f(f"fmi{f.version}EnterContinuousTimeMode", c)
    assert f.set(c, [VR["offset"]], [offset]) == OK
    assert f.set(c, [VR["s"], VR["v"]], [s, v]) == OK  # inputs (force) or states in CT Mode (D4)
    if interface == "body":
        assert f.set(c, [VR["f"]], [load]) == OK
    return c


def _directional(f: Fmu, c, unknown: int, known: int) -> float:
    out = doubles(0.0)
    if f.version == 2:
        st = f("fmi2GetDirectionalDerivative", c, vrs(unknown), 1, vrs(known), 1, doubles(1.0), out)
    else:
        st = f("fmi3GetDirectionalDerivative", c, vrs(unknown), 1, vrs(known), 1, doubles(1.0), 1, out, 1)
    assert st == OK, f.log[-1:]
    return out[0]


@pytest.mark.parametrize("version", [2, 3])
def test_d2_derivative_of_the_force_wrt_offset_is_k(fmu, version):
    """Before: d x.f / d x.offset was 0 with status OK; finite differences give +k = +800."""
    f = fmu[(version, "force")]
    c = _me_at(f, "force")
    assert _directional(f, c, VR["f"], VR["offset"]) == K_SI
    f.free(c)


def _dependencies(path, tag: str, vr: int) -> set[int]:
    with zipfile.ZipFile(path) as z:
        root = ElementTree.fromstring(z.read("modelDescription.xml"))
    el = next(e for e in root.find("ModelStructure") if e.tag == tag and int(e.get("valueReference")) == vr)
    return {int(x) for x in el.get("dependencies").split()}


def test_d3_fmi3_dependencies_declare_the_tunable_parameters(paths):
    """Before: Output and derivative dependencies omitted m, c, k, offset and enabled (switching the
    spring-damper off changes x.f and x.a), declaring those partial derivatives zero."""
    assert _dependencies(paths[(3, "force")], "Output", VR["f"]) == {
        VR[x] for x in ("s", "v", "c", "k", "offset", "enabled")
    }
    for tag in ("ContinuousStateDerivative", "Output"):
        deps = _dependencies(paths[(3, "body")], tag, VR["a"])
        assert deps == {VR[x] for x in ("s", "v", "f", "m", "c", "k", "offset", "enabled")}


@pytest.mark.parametrize("version", [2, 3])
def test_d4_continuous_states_set_in_continuous_time_mode(fmu, version):
    """Before: setting x.s, x.v in Continuous-Time Mode returned Error and killed the instance."""
    f = fmu[(version, "body")]
    c = _me_at(f, "body", s=3e-3, v=0.1)
    x = doubles(0.0, 0.0)
    get = "fmi2GetContinuousStates" if version == 2 else "fmi3GetContinuousStates"
    assert f(get, c, x, 2) == OK and list(x[:2]) == [3e-3, 0.1]
    f.free(c)


@pytest.mark.parametrize("version", [2, 3])
def test_d5_nominals_in_instantiated(fmu, version):
    """Before: fmi2GetNominalsOfContinuousStates in Instantiated was refused and killed the instance."""
    f = fmu[(version, "body")]
    c = f.instantiate(ME)
    x = doubles(0.0, 0.0)
    assert f(f"fmi{version}GetNominalsOfContinuousStates", c, x, 2) == OK and list(x[:2]) == [1.0, 1.0]
    f.start(c)  # and the instance lives on
    f.free(c)


def test_d6_event_mode_used_without_has_event_mode_is_refused(fmu):
    """Before: fmi3InstantiateCoSimulation(eventModeUsed = true) succeeded though hasEventMode = false."""
    f = fmu[(3, "force")]
    f.log.clear()
    assert not f.instantiate(CS, event_mode=True)
    assert any("hasEventMode" in m for m in _errors(f))


@pytest.mark.parametrize("version", [2, 3])
def test_d7_logging_off_means_no_log_calls(fmu, version):
    """Before: errors were logged with logging off, and SetDebugLogging(off, 0, NULL) did not silence them."""
    f = fmu[(version, "force")]
    f.log.clear()
    c = f.instantiate(CS, logging=False)
    assert f(f"fmi{version}EnterContinuousTimeMode", c) == ERROR and f.log == []
    f.free(c)
    c = f.instantiate(CS, logging=True)
    assert f(f"fmi{version}SetDebugLogging", c, 0, 0, None) == OK
    f.log.clear()
    assert f(f"fmi{version}EnterContinuousTimeMode", c) == ERROR and f.log == []
    f.free(c)


def _do_step(f: Fmu, c, t: float, h: float) -> int:
    if f.version == 2:
        return f("fmi2DoStep", c, t, h, 1)
    flags = [C.c_bool() for _ in range(3)]
    last = C.c_double()
    return f("fmi3DoStep", c, t, h, True, *map(C.byref, flags), C.byref(last))


@pytest.mark.parametrize("version", [2, 3])
def test_d8_no_step_past_the_stop_time(fmu, version):
    """Before: stopTime was ignored; a step past it returned OK."""
    f = fmu[(version, "body")]
    c = f.instantiate(CS)
    f.start(c, stop=0.01)
    assert _do_step(f, c, 0.0, 0.01) == OK
    f.log.clear()
    assert _do_step(f, c, 0.01, 1e-3) == ERROR
    assert any("stop time" in m for m in _errors(f))
    f.free(c)


@pytest.mark.parametrize("version", [2, 3])
def test_d13_communication_point_must_be_the_instance_time(fmu, version):
    """Before: DoStep(5.0, 1e-3) at t = 0 returned OK and jumped."""
    f = fmu[(version, "body")]
    c = f.instantiate(CS)
    f.start(c)
    f.log.clear()
    assert _do_step(f, c, 5.0, 1e-3) == ERROR
    assert any("communication point" in m for m in _errors(f))
    f.free(c)


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_d14_non_finite_times_are_refused(fmu, version, bad):
    """Before: a NaN or infinite start time, stop time or ME time was accepted."""
    f = fmu[(version, "body")]
    c = f.instantiate(CS)
    f.log.clear()
    if version == 2:
        assert f("fmi2SetupExperiment", c, 0, 0.0, bad, 0, 0.0) == ERROR
    else:
        assert f("fmi3EnterInitializationMode", c, False, 0.0, bad, False, 0.0) == ERROR
    assert _errors(f)
    f.free(c)
    c = f.instantiate(ME)
    f.start(c)
    assert f(f"fmi{version}SetTime", c, bad) == ERROR
    f.free(c)
    c = f.instantiate(CS)
    f.start(c)
    assert _do_step(f, c, bad, 1e-3) == ERROR
    f.free(c)


def test_d9_fmi3_functions_of_the_other_interface_are_refused(fmu):
    """Before: an ME instance accepted EnterStepMode and DoStep, a CS instance answered ME-only calls,
    EnterEventMode was accepted in Event Mode."""
    f = fmu[(3, "body")]
    me = f.instantiate(ME)
    f.start(me)  # Event Mode
    assert f("fmi3EnterEventMode", me) == ERROR
    for call in (lambda i: f("fmi3EnterStepMode", i), lambda i: _do_step(f, i, 0.0, 1e-3)):
        f.free(me)
        me = f.instantiate(ME)
        f.start(me)
        assert call(me) == ERROR
    f.free(me)
    n = C.c_size_t(99)
    for name, args in [
        ("fmi3EnterContinuousTimeMode", ()),
        ("fmi3SetTime", (0.5,)),
        ("fmi3GetNumberOfContinuousStates", (C.byref(n),)),
        ("fmi3GetContinuousStates", (doubles(0, 0), 2)),
    ]:
        cs = f.instantiate(CS)
        f.start(cs)
        f.log.clear()
        assert f(name, cs, *args) == ERROR, name
        assert any("Model Exchange function" in m for m in _errors(f))
        f.free(cs)


def test_d10_discard_is_logged(fmu):
    """Before: fmi2GetRealStatus and the other status calls returned fmi2Discard without a message."""
    f = fmu[(2, "body")]
    c = f.instantiate(CS)
    f.start(c)
    f.log.clear()
    value = C.c_double()
    assert f("fmi2GetRealStatus", c, 0, C.byref(value)) == DISCARD  # fmi2DoStepStatus: not a Real
    assert [cat for s, cat, _ in f.log if s == DISCARD] == ["logStatusDiscard"]
    f.free(c)


def test_d11_fmi2_value_reference_zero_is_unknown(fmu):
    """Before: FMI 2 read value reference 0 (time, not declared in FMI 2) with OK."""
    f = fmu[(2, "force")]
    c = f.instantiate(CS)
    f.log.clear()
    assert f("fmi2GetReal", c, vrs(0), 1, doubles(0.0)) == ERROR
    assert any("unknown value reference 0" in m for m in _errors(f))
    f.free(c)
    g = fmu[(3, "force")]  # FMI 3 declares time with value reference 0
    c = g.instantiate(CS)
    g.start(c, start=0.25)
    assert g.get(c, 0) == [0.25]
    g.free(c)


def _state_bytes(f: Fmu, c) -> bytes:
    state, size = C.c_void_p(), C.c_size_t()
    v = f.version
    assert f(f"fmi{v}GetFMU{'state' if v == 2 else 'State'}", c, C.byref(state)) == OK
    assert f(f"fmi{v}SerializedFMU{'state' if v == 2 else 'State'}Size", c, state, C.byref(size)) == OK
    buf = C.create_string_buffer(size.value)
    assert f(f"fmi{v}SerializeFMU{'state' if v == 2 else 'State'}", c, state, buf, size.value) == OK
    assert f(f"fmi{v}FreeFMU{'state' if v == 2 else 'State'}", c, C.byref(state)) == OK
    return buf.raw


def _load(f: Fmu, c, data: bytes) -> int:
    state = C.c_void_p()
    name = "fmi2DeSerializeFMUstate" if f.version == 2 else "fmi3DeserializeFMUState"
    status = f(name, c, C.create_string_buffer(data, len(data)), len(data), C.byref(state))
    if status == OK:
        status = f("fmi2SetFMUstate" if f.version == 2 else "fmi3SetFMUState", c, state)
        f("fmi2FreeFMUstate" if f.version == 2 else "fmi3FreeFMUState", c, C.byref(state))
    return status


def _fnv1a(data: bytes) -> int:
    h = 2166136261
    for b in data:
        h = ((h ^ b) * 16777619) & 0xFFFFFFFF
    return h


@pytest.mark.parametrize("version", [2, 3])
def test_d12_serialized_state_defends_itself(fmu, version):
    """Before: only the byte count was checked: a body state loaded into a force FMU gave x.f = +2.744
    instead of -2.75, corrupted bytes reached invalid bool loads and a division by zero."""
    body, force = fmu[(version, "body")], fmu[(version, "force")]
    b = body.instantiate(CS)
    body.start(b)
    body.set(b, [VR["f"]], [2.744])
    assert _do_step(body, b, 0.0, 1e-3) == OK
    data = _state_bytes(body, b)
    assert data[:4] == b"FJST" and struct.unpack("<IIIII", data[4:24]) == (1, 1, 1, 1, 1)
    assert _fnv1a(data[:24] + data[28:]) == struct.unpack("<I", data[24:28])[0]  # independent checksum
    assert _load(body, b, data) == OK  # the round trip
    f = force.instantiate(CS)
    force.start(f)
    force.set(f, [VR["s"], VR["v"]], [3e-3, 0.1])
    expected = force.get(f, VR["f"])
    mutations = {
        "another interface": data,
        "checksum": data[:-3] + bytes([data[-3] ^ 1]) + data[-2:],
        "too short": data[:20],
        "magic": b"XXXX" + data[4:],
    }
    for problem, bad in mutations.items():
        target, inst = (force, f) if problem == "another interface" else (body, b)
        target.log.clear()
        assert _load(target, inst, bad) == ERROR, problem
        assert any(problem.split()[-1] in m for m in _errors(target)), (problem, target.log)
        target.free(inst)
        inst = target.instantiate(CS)
        target.start(inst)
        if target is force:
            f = inst
            force.set(f, [VR["s"], VR["v"]], [3e-3, 0.1])
            assert force.get(f, VR["f"]) == expected
        else:
            b = inst
    # a valid checksum over an invalid bool (enabled = 2) and a zero mass: refused, not loaded
    for offset, value in ((len(data) - 1, b"\x02"), (49, struct.pack("<d", 0.0))):
        bad = bytearray(data)
        bad[offset : offset + len(value)] = value
        bad[24:28] = struct.pack("<I", _fnv1a(bytes(bad[:24] + bad[28:])))
        assert _load(body, b, bytes(bad)) == ERROR
        body.free(b)
        b = body.instantiate(CS)
        body.start(b)
    body.free(b)
    force.free(f)


@pytest.mark.parametrize("version", [2, 3])
def test_d12_a_snapshot_of_another_interface_is_refused(fmu, version):
    """An in-memory FMU state of a body instance set into a force instance of the same binary."""
    body, force = fmu[(version, "body")], fmu[(version, "force")]
    if body.lib._name == force.lib._name:
        pytest.skip("same library")
    b, f = body.instantiate(CS), force.instantiate(CS)
    body.start(b)
    force.start(f)
    state = C.c_void_p()
    v = "state" if version == 2 else "State"
    assert body(f"fmi{version}GetFMU{v}", b, C.byref(state)) == OK
    # the two exports load the same source into two libraries; pass the pointer across the boundary
    force.log.clear()
    assert force(f"fmi{version}SetFMU{v}", f, state) == ERROR
    assert any("another interface" in m for m in _errors(force))
    body(f"fmi{version}FreeFMU{v}", b, C.byref(state))
    body.free(b)
    force.free(f)


def test_d15_fmi3_null_arrays_are_errors_and_adjoint_is_declared(fmu, paths):
    """Before: NULL arrays with n > 0 segfaulted in the FMI 3 layer; providesAdjointDerivatives was
    not declared though fmi3GetAdjointDerivative is implemented."""
    f = fmu[(3, "body")]
    for name, args in [
        ("fmi3GetBoolean", (vrs(VR["enabled"]), 1, None, 1)),
        ("fmi3SetBoolean", (None, 1, None, 1)),
        ("fmi3GetContinuousStates", (None, 2)),
        ("fmi3SetContinuousStates", (None, 2)),
        ("fmi3GetContinuousStateDerivatives", (None, 2)),
        ("fmi3GetNominalsOfContinuousStates", (None, 2)),
        ("fmi3GetFloat64", (None, 2, None, 2)),
    ]:
        c = f.instantiate(ME)
        f.start(c)
        if name == "fmi3SetContinuousStates":
            f("fmi3EnterContinuousTimeMode", c)
        f.log.clear()
        assert f(name, c, *args) == ERROR, name
        assert any("NULL" in m for m in _errors(f)), (name, f.log)
        f.free(c)
    with zipfile.ZipFile(paths[(3, "force")]) as z:
        md = z.read("modelDescription.xml").decode()
    assert len(re.findall(r'providesAdjointDerivatives="true"', md)) == 2


KNOWNS = {"force": ("s", "v", "c", "k", "offset"), "body": ("s", "v", "f", "m", "c", "k", "offset")}
UNKNOWNS = {"force": ("f",), "body": ("s", "v", "a")}


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("interface", ["force", "body"])
def test_partial_derivatives_match_finite_differences(fmu, version, interface):
    """Every unknown against every known (inputs, states and the parameters m, c, k, offset): the
    directional derivative (and in FMI 3 the adjoint) equals central finite differences."""
    f = fmu[(version, interface)]
    c = _me_at(f, interface)
    knowns, unknowns = KNOWNS[interface], UNKNOWNS[interface]
    base = dict(zip(knowns, f.get(c, *(VR[k] for k in knowns)), strict=True))
    jac = np.zeros((len(unknowns), len(knowns)))
    for j, k in enumerate(knowns):
        h = 1e-6 * max(1.0, abs(base[k]))
        values = []
        for sign in (1, -1):
            assert f.set(c, [VR[k]], [base[k] + sign * h]) == OK
            values.append(np.array(f.get(c, *(VR[u] for u in unknowns))))
        assert f.set(c, [VR[k]], [base[k]]) == OK
        jac[:, j] = (values[0] - values[1]) / (2 * h)
        for i, u in enumerate(unknowns):
            assert _directional(f, c, VR[u], VR[k]) == pytest.approx(jac[i, j], rel=1e-6, abs=1e-9), (u, k)
    assert np.any(jac[:, [knowns.index(p) for p in ("k", "offset")]] != 0)
    if version == 3:
        seed = np.arange(1.0, len(unknowns) + 1)
        out = doubles(*([0.0] * len(knowns)))
        refs_u, refs_k = vrs(*(VR[u] for u in unknowns)), vrs(*(VR[k] for k in knowns))
        n_u, n_k = len(unknowns), len(knowns)
        assert f("fmi3GetAdjointDerivative", c, refs_u, n_u, refs_k, n_k, doubles(*seed), n_u, out, n_k) == OK
        np.testing.assert_allclose(out[:n_k], seed @ jac, rtol=1e-6, atol=1e-9)
    f.free(c)


def test_fmi2_resource_location_in_every_form_the_standard_allows(paths, tmp_path):
    """FMI 2.0.4 section 2.1.5: file:///path, file:/path, file://localhost/path, percent-encoded UTF-8
    (a folder with a space and a user called Jürgen). Each loads the start values (k as exported)."""
    from urllib.parse import quote

    folder = tmp_path / "Jürgen dir"
    f = Fmu(*unpack(paths[(2, "body")], folder))
    res = str(folder / "resources")
    forms = {
        "file:///": (folder / "resources").as_uri(),
        "file:/": "file:" + quote(res),
        "file://localhost/": "file://localhost" + quote(res),
        "unencoded file:///": "file://" + res,
    }
    for form, uri in forms.items():
        inst = f.instantiate(CS, resources=uri)
        assert inst, (form, uri, f.log[-3:])
        f.start(inst)
        assert f.get(inst, VR["k"]) == [pytest.approx(K_SI)], form
        f.free(inst)
