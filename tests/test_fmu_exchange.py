"""The master's exchange within the FMI standard: force elements as Model Exchange at one instant,
a co-simulation-only third-party force element with a stated one-step delay, results unchanged."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from fmpy.fmi2 import FMU2Slave

from designer.cosim.fmu import FmuSystem
from designer.cosim.master import Master
from designer.export.fmu import export_fmu
from designer.joint import Joint

K, C, M = 3.0, 0.5, 2e-3  # SI on theta: N.m/rad, N.m.s/rad, kg.m^2 (the third-party FMU's values)
STEP, DURATION = 1e-3, 0.3


@pytest.fixture(scope="module", autouse=True)
def cache(fmu_cache):
    """Every test here builds into a throw-away cache."""


@pytest.fixture(scope="module")
def fmus(tmp_path_factory):
    d = tmp_path_factory.mktemp("fmus")
    # rig units: N.mm/rad and N.mm.s/rad
    joint = Joint.from_coefficients({"theta": {"k": K * 1e3, "c": C * 1e3, "m": M}})
    return {(v, i): export_fmu(joint, d / f"j{v}{i}.fmu", v, i) for v in (2, 3) for i in ("force", "body")}


@pytest.fixture(scope="module")
def third_party(tmp_path_factory):
    """A co-simulation-only FMI 2 force element built with PythonFMU (not our runtime)."""
    pytest.importorskip("pythonfmu")
    d = tmp_path_factory.mktemp("third")
    script = d / "ThirdPartySpring.py"
    shutil.copy(Path(__file__).parent / "data" / "third_party_spring.py", script)
    cmd = [sys.executable, "-m", "pythonfmu", "build", "-f", str(script), "-d", str(d)]
    subprocess.run(cmd, check=True, capture_output=True)
    return d / "ThirdPartySpring.fmu"


class Kick:
    """A state system: a torque pulse source for the body, t in [0, 0.05) s."""

    inputs: list[str] = []
    outputs = ["tau"]
    feedthrough = False

    def __init__(self) -> None:
        self.t = 0.0

    def get(self) -> np.ndarray:
        return np.array([0.02 if self.t < 0.05 else 0.0])

    def set(self, values: np.ndarray) -> None:
        pass

    def do_step(self, h: float) -> None:
        self.t += h


def _loop(body: Path, force, algorithm: str):
    """Body (co-simulation) on a spring-damper force element, plus an external kick added to it."""
    spring = force if not isinstance(force, Path) else FmuSystem(force, ["theta"], name="spring")
    systems = {"body": FmuSystem(body, ["theta"], name="body"), "spring": spring}
    adder = Adder()
    systems["kick"], systems["sum"] = Kick(), adder
    connections = [
        ("body.theta.s", "spring.theta.s"),
        ("body.theta.v", "spring.theta.v"),
        ("spring.theta.f", "sum.a"),
        ("kick.tau", "sum.b"),
        ("sum.y", "body.theta.f"),
    ]
    try:
        return Master(systems, connections, algorithm).run(DURATION, STEP), spring
    finally:
        for s in systems.values():
            if isinstance(s, FmuSystem):
                s.close()


class Adder:
    """A feedthrough sum y = a + b (pure Python, evaluated at the same instant)."""

    inputs = ["a", "b"]
    outputs = ["y"]
    feedthrough = True

    def __init__(self) -> None:
        self.y = 0.0

    def get(self) -> np.ndarray:
        return np.array([self.y])

    def set(self, values: np.ndarray) -> None:
        self.y = float(values[0] + values[1])

    def do_step(self, h: float) -> None:
        pass


@pytest.mark.parametrize("version", [2, 3])
def test_force_element_runs_as_model_exchange_and_matches_the_law_at_the_same_instant(fmus, version):
    res, spring = _loop(fmus[(version, "body")], fmus[(version, "force")], "gauss-seidel")
    assert spring.kind == "model-exchange" and spring.feedthrough and spring.delay is None
    assert res.delays == ()
    s, v, f = (res.column(c) for c in ("body.theta.s", "body.theta.v", "spring.theta.f"))
    # the law evaluated in Python on the same inputs at the same instant (no delay)
    np.testing.assert_array_equal(f, -(K * s + C * v))
    assert np.max(np.abs(s)) > 1e-4  # the kick moved the body


def _old_sequence(body: Path, force: Path) -> np.ndarray:
    """The exchange before this change: Set then Get on a co-simulation instance (FMI 2), by hand."""
    out = []
    slaves = {}
    for name, path in (("body", body), ("spring", force)):
        from fmpy import extract, read_model_description

        md = read_model_description(str(path))
        fmu = FMU2Slave(
            guid=md.guid, unzipDirectory=extract(str(path)), modelIdentifier="FlexJoint", instanceName=name
        )
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        slaves[name] = (fmu, {v.name: v.valueReference for v in md.modelVariables})
    (b, rb), (sp, rs) = slaves["body"], slaves["spring"]
    kick = Kick()
    for i in range(int(round(DURATION / STEP)) + 1):
        s, v, a = b.getReal([rb["theta.s"], rb["theta.v"], rb["theta.a"]])
        sp.setReal([rs["theta.s"], rs["theta.v"]], [s, v])
        (f,) = sp.getReal([rs["theta.f"]])
        b.setReal([rb["theta.f"]], [f + kick.get()[0]])
        out.append([s, v, a, f])
        if i == int(round(DURATION / STEP)):
            break
        b.doStep(i * STEP, STEP)
        sp.doStep(i * STEP, STEP)
        kick.do_step(STEP)
    for fmu, _ in slaves.values():
        fmu.terminate()
        fmu.freeInstance()
    return np.array(out)


def test_results_are_bit_identical_to_the_old_get_after_set_sequence(fmus):
    res, _ = _loop(fmus[(2, "body")], fmus[(2, "force")], "gauss-seidel")
    cols = ["body.theta.s", "body.theta.v", "body.theta.a", "spring.theta.f"]
    new = np.column_stack([res.column(c) for c in cols])
    assert new.tobytes() == _old_sequence(fmus[(2, "body")], fmus[(2, "force")]).tobytes()


def test_cs_only_third_party_force_element_is_delayed_one_step_and_says_so(fmus, third_party):
    spring = FmuSystem(third_party, ["theta"], name="spring")
    assert spring.kind == "co-simulation" and not spring.feedthrough
    res, _ = _loop(fmus[(2, "body")], spring, "gauss-seidel")
    assert len(res.delays) == 1 and "spring" in res.delays[0] and "one step" in res.delays[0]
    s, v, f = (res.column(c) for c in ("body.theta.s", "body.theta.v", "spring.theta.f"))
    # the third party's output at step i is its law on the inputs of step i - 1
    np.testing.assert_allclose(f[1:], -(K * s[:-1] + C * v[:-1]), rtol=1e-15, atol=0)
    assert f[0] == 0.0
    assert np.max(np.abs(s)) > 1e-4


class Recorder:
    """A system recording the master's calls, to check the exchange order."""

    def __init__(self, log: list, name: str, inputs, outputs, feedthrough: bool) -> None:
        self.log, self.name = log, name
        self.inputs, self.outputs, self.feedthrough = inputs, outputs, feedthrough

    def get(self) -> np.ndarray:
        self.log.append((self.name, "get"))
        return np.zeros(len(self.outputs))

    def set(self, values: np.ndarray) -> None:
        self.log.append((self.name, "set"))

    def do_step(self, h: float) -> None:
        self.log.append((self.name, "step"))


def test_gauss_seidel_never_reads_a_state_system_between_set_and_step():
    log: list = []
    systems = {
        "a": Recorder(log, "a", ["u"], ["y"], False),
        "f": Recorder(log, "f", ["u"], ["y"], True),
    }
    Master(systems, [("a.y", "f.u"), ("f.y", "a.u")]).run(2e-3, 1e-3)
    one = [("a", "get"), ("f", "set"), ("f", "get"), ("a", "set"), ("a", "step"), ("f", "step")]
    assert log == one * 2 + one[:4]


def test_cosim_run_states_the_delay_of_a_cs_only_joint_in_its_notes(third_party, tmp_path):
    """designer.cosim.run on the example arm with one joint the third-party co-simulation-only FMU."""
    import dataclasses

    from designer import cosim
    from designer.cosim.scenario import JointSource

    sc = cosim.load(Path(__file__).parents[1] / "examples" / "two_link_arm.toml")
    # the example joints' law (about 0.33 N.m/rad, 8e-4 N.m.s/rad), in the third party's parameters
    spring = JointSource(axis="theta", fmu=third_party, parameters={"theta.k": 0.333, "theta.c": 8e-4})
    joints = dict(sc.joints, j2=spring)
    sc = dataclasses.replace(sc, joints=joints, duration=0.05)
    result = cosim.run(sc)
    assert len(result.notes) == 1 and "j2" in result.notes[0] and "one step" in result.notes[0]
    assert result.summary()["notes"] == list(result.notes)
