"""The compiled co-simulation kernel against the Python master: the same bits, the same errors."""

import math
import shutil
import subprocess
import sys
import textwrap
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from designer.cosim import binding, kernel, prepare
from designer.cosim.master import Master
from designer.cosim.references import Chirp, Sine, Step, Trajectory
from designer.cosim.robot import Robot, SpringDamper, load_spec
from designer.cosim.robot_scenario import robot_reference
from designer.cosim.scenario_file import load
from designer.errors import DesignerError

EXAMPLE = Path(__file__).resolve().parent.parent / "examples" / "two_link_arm.toml"
REFERENCES = [
    '{ type = "sine", amplitude = 0.5, frequency = 0.7, offset = 0.1, phase = 0.3 }',
    '{ type = "step", amplitude = 0.3, at = 0.2, initial = -0.1 }',
    '{ type = "chirp", amplitude = 0.4, f0 = 0.5, f1 = 3.0, sweep = 1.0 }',
    '{ type = "csv", file = "motor.csv" }',
]

# A force element written with PythonFMU (a third-party FMU runtime): f computed in do_step, so its
# output answers the inputs of the previous step; theta.m < 0 makes do_step fail with a logged error.
SPRING = """
from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real
from pythonfmu.enums import Fmi2Status


class Spring(Fmi2Slave):
    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.vals = {"theta.s": 0.0, "theta.v": 0.0, "theta.f": 0.0,
                     "theta.m": 0.0, "theta.c": 1e-3, "theta.k": 0.33, "theta.offset": 0.0}
        for name in ("theta.s", "theta.v"):
            self._add(name, causality=Fmi2Causality.input)
        self._add("theta.f", causality=Fmi2Causality.output)
        for name in ("theta.m", "theta.c", "theta.k", "theta.offset"):
            self._add(name, causality=Fmi2Causality.parameter, variability=Fmi2Variability.tunable)

    def _add(self, name, **kwargs):
        def setter(x):
            self.vals[name] = x
        self.register_variable(Real(name, getter=lambda: self.vals[name], setter=setter, **kwargs))

    def do_step(self, current_time, step_size):
        v = self.vals
        if v["theta.m"] < 0 and current_time > 0.1:
            self.log(f"theta.m = {v['theta.m']} is negative", Fmi2Status.error)
            return False
        v["theta.f"] = -(v["theta.k"] * (v["theta.s"] - v["theta.offset"]) + v["theta.c"] * v["theta.v"])
        return True
"""


def both(sc, algorithm=None, step=None, duration=None):
    """The scenario run by the Python master and by the kernel, in one prepared Session (so the
    kernel's run also checks that a reset gives back the first run's start)."""
    sc = replace(sc, algorithm=algorithm or sc.algorithm)
    with prepare(sc) as session:
        return [session.trace(step=step, duration=duration, engine=e) for e in ("python", "kernel")]


def assert_same(py, ker):
    assert (py.engine, ker.engine) == ("python", "kernel")
    assert py.columns == ker.columns
    np.testing.assert_array_equal(py.time, ker.time)
    assert np.array_equal(py.values, ker.values), np.max(np.abs(py.values - ker.values))


@pytest.mark.parametrize("algorithm", ["gauss-seidel", "jacobi"])
def test_example_arm_bit_identical(algorithm):
    py, ker = both(load(EXAMPLE), algorithm=algorithm)
    assert_same(py, ker)
    assert len(py.time) == 10001 and np.ptp(py.column("robot.j2.q")) > 0.1


def n_link(tmp_path, n, algorithm, fmi3=False):
    t = np.linspace(0.0, 0.8, 9)
    np.savetxt(
        tmp_path / "motor.csv",
        np.column_stack([t, 0.3 * np.sin(4 * t)]),
        delimiter=",",
        header="t,q",
        comments="",
    )
    joints = "".join(
        f"[joints.j{i + 1}]\ncoefficients = {{ k = {200 + 40 * i}, c = {0.5 + 0.1 * i} }}\n"
        f"fmi_version = {3 if fmi3 and i % 2 else 2}\nreference = {REFERENCES[i % 4]}\n"
        for i in range(n)
    )
    lengths = ", ".join(f"{0.08 - 0.005 * i:g}" for i in range(n))
    masses = ", ".join(f"{0.03 - 0.002 * i:g}" for i in range(n))
    text = (
        f'[simulation]\nduration = 1.0\nstep = 1e-3\nalgorithm = "{algorithm}"\n'
        f'[robot]\nmodel = "arm"\nlengths = [{lengths}]\nmasses = [{masses}]\n{joints}'
    )
    (tmp_path / "arm.toml").write_text(text)
    return load(tmp_path / "arm.toml")


@pytest.mark.parametrize(
    "n, algorithm, fmi3", [(1, "gauss-seidel", False), (4, "gauss-seidel", True), (6, "jacobi", True)]
)
def test_n_link_arms_bit_identical(tmp_path, n, algorithm, fmi3):
    py, ker = both(n_link(tmp_path, n, algorithm, fmi3))
    assert_same(py, ker)
    assert len(py.columns) == 4 * n + n


def test_rig_bit_identical():
    py, ker = both(load(EXAMPLE.parent / "rig.toml"), duration=2.0)
    assert_same(py, ker)
    assert np.ptp(ker.column("hub.f")) > 0


def test_divergence_is_found_at_the_same_instant():
    sc = replace(load(EXAMPLE), algorithm="jacobi")
    errors = []
    with prepare(sc) as session:
        for engine in ("python", "kernel"):
            with pytest.raises(DesignerError, match="diverged") as info:
                session.trace(step=5e-3, duration=1.0, engine=engine)
            errors.append(str(info.value))
    assert errors[0] == errors[1] and "t = 0.135 s" in errors[0]


def test_kernel_references_match_python(tmp_path):
    refs = [
        Step(0.3, at=0.2, initial=-0.1),
        Sine(0.5, 0.7, offset=0.1, phase=0.3),
        Chirp(0.4, 0.5, 3.0, 1.0),
        Trajectory(np.array([0.0, 0.1, 0.25, 0.3]), np.array([0.2, -0.1, 0.4, 0.0])),
    ]
    # forward in time as a run goes, then jumping back (the table's cursor must restart)
    times = [*np.arange(-0.05, 0.4, 1e-3), 0.25, 0.0, 0.1, 0.1, math.nextafter(0.1, 0), 0.31, -1.0]
    lib = kernel.library()
    for ref in refs:
        keep = []
        struct = binding.reference(ref, keep)
        q, v = kernel.ctypes.c_double(), kernel.ctypes.c_double()
        for t in times:
            lib.ks_reference_eval(kernel.ctypes.byref(struct), float(t), q, v)
            assert (q.value, v.value) == ref(float(t)), (ref, t)


@pytest.fixture(scope="module")
def spring_fmu(tmp_path_factory):
    if shutil.which("pythonfmu") is None and not _has_pythonfmu():
        pytest.skip("pythonfmu is not installed")
    folder = tmp_path_factory.mktemp("spring")
    (folder / "spring.py").write_text(SPRING)
    subprocess.run(
        [sys.executable, "-m", "pythonfmu", "build", "-f", "spring.py", "-d", str(folder)],
        cwd=folder,
        check=True,
        capture_output=True,
    )
    return folder / "Spring.fmu"


def _has_pythonfmu():
    try:
        import pythonfmu  # noqa: F401
    except ImportError:
        return False
    return True


def spring_arm(tmp_path, fmu, parameters=""):
    text = f"""
    [simulation]
    duration = 0.3
    step = 1e-3
    [robot]
    model = "arm"
    [joints.j1]
    coefficients = {{ k = 330, c = 0.83 }}
    reference = {{ type = "sine", amplitude = 0.5, frequency = 0.5 }}
    [joints.j2]
    fmu = "{fmu}"
    {parameters}
    reference = {{ type = "step", amplitude = 0.3, at = 0.05 }}
    """
    (tmp_path / "spring.toml").write_text(textwrap.dedent(text))
    return load(tmp_path / "spring.toml")


def test_third_party_fmu_bit_identical(tmp_path, spring_fmu):
    py, ker = both(spring_arm(tmp_path, spring_fmu))
    assert_same(py, ker)
    assert np.max(np.abs(ker.column("j2.theta.f"))) > 0.01


def test_fmu_error_status_comes_with_the_fmus_log(tmp_path, spring_fmu):
    sc = spring_arm(tmp_path, spring_fmu, parameters='parameters = { "theta.m" = -1.0 }')
    messages = []
    with prepare(sc) as session:
        for engine in ("python", "kernel"):
            with pytest.raises(DesignerError) as info:
                session.trace(engine=engine)
            messages.append(str(info.value))
    assert messages[0] == messages[1]
    assert "FMU j2: fmi2DoStep returned Discard at t = 0.101 s" in messages[0]
    assert "theta.m = -1.0 is negative" in messages[0]


def test_auto_falls_back_to_python_without_a_compiler(tmp_path, monkeypatch):
    sc = load(EXAMPLE)
    with prepare(sc) as session:
        monkeypatch.setenv("CC", str(tmp_path / "no-such-cc"))
        monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
        kernel.library.cache_clear()
        try:
            res = session.trace(duration=0.05)
            assert res.engine == "python"
            with pytest.raises(DesignerError, match="no-such-cc"):
                session.trace(duration=0.05, engine="kernel")
        finally:
            kernel.library.cache_clear()


def test_in_engine_reference_bit_identical():
    sc = load(EXAMPLE)
    laws = {j: {"k": 0.333, "c": 8.3e-4, "offset": 0.01} for j in sc.joints}
    ker = robot_reference(sc, laws, 1e-3, 2.0, "rk4")
    py = _reference_master(sc, laws).run(2.0, 1e-3)
    assert_same(py, ker)


def _reference_master(sc, laws):
    springs = {j: SpringDamper(p["k"], p["c"], p["offset"]) for j, p in laws.items()}
    robot = Robot(load_spec(sc.model, sc.lengths, sc.masses), sc.motors, 1e-3, "rk4", in_engine=springs)
    return Master({"robot": robot}, [])


class Hold:
    """A system written in Python: the kernel cannot run it."""

    feedthrough = False
    inputs: list = []
    outputs = ["x"]

    def get(self):
        return np.array([1.0])

    def set(self, values):
        pass

    def do_step(self, h):
        pass


def test_systems_the_kernel_cannot_run_go_to_python():
    master = Master({"hold": Hold()}, [])
    assert kernel.run_master(master, 0.01, 1e-3).engine == "python"
    with pytest.raises(DesignerError, match="cannot run system hold"):
        kernel.run(master, 0.01, 1e-3)
    with pytest.raises(DesignerError, match="unknown engine"):
        kernel.run_master(master, 0.01, 1e-3, engine="fast")


def asking_fmus(monkeypatch, every=250, fail_at=None):
    """Joint FMUs made to need CompletedIntegratorStep, asking for an event every `every`th call and
    answering Error at call `fail_at`; the kernel calls the fake through its pointer, the Python
    master through fmpy's method. Returns the list the event iterations are recorded in."""
    import ctypes

    from fmpy.fmi1 import FMICallException

    from designer.cosim import fmu as fmu_module

    proto = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.c_int, ctypes.c_void_p, ctypes.c_void_p)
    original_init, real_function = fmu_module.FmuSystem.__init__, fmu_module.fmi_function
    events, fakes, keep = [], {}, []

    def asking(fmu):
        real, count = proto(real_function(fmu, "fmi2CompletedIntegratorStep")), [0]

        def completed(component, no_set, enter, stop):
            status = real(component, no_set, enter, stop)
            count[0] += 1
            ctypes.cast(enter, ctypes.POINTER(ctypes.c_int))[0] = count[0] % every == 0
            return 3 if count[0] == fail_at else status

        return proto(completed)

    def init(self, *args, **kwargs):
        original_init(self, *args, **kwargs)
        fake = asking(self.fmu)
        keep.append(fake)
        fakes[id(self.fmu)] = ctypes.cast(fake, ctypes.c_void_p).value
        self.mode.completed = True  # a ModelExchange mode: CompletedIntegratorStep after each step

        def python_completed():
            enter, stop = ctypes.c_int(0), ctypes.c_int(0)
            status = fake(self.fmu.component, 1, ctypes.addressof(enter), ctypes.addressof(stop))
            if status > 1:
                raise FMICallException("fmi2CompletedIntegratorStep", status)
            return bool(enter.value), bool(stop.value)

        self.fmu.completedIntegratorStep = python_completed
        iteration = self.event_iteration
        self.event_iteration = lambda: (events.append((self.fmu.instanceName, self.steps)), iteration())

    def function(fmu, name):
        return fakes[id(fmu)] if name.endswith("CompletedIntegratorStep") else real_function(fmu, name)

    monkeypatch.setattr(fmu_module.FmuSystem, "__init__", init)
    monkeypatch.setattr(fmu_module, "fmi_function", function)
    return events


def test_model_exchange_completed_steps_and_events_match(monkeypatch):
    """The kernel calls CompletedIntegratorStep through the pointer and hands the event iterations
    the FMUs ask for to Python, as the master does."""
    events = asking_fmus(monkeypatch)
    py, ker = both(load(EXAMPLE), duration=1.0)
    assert_same(py, ker)
    half = len(events) // 2
    # per run: each joint's event iteration after initialisation (its reset, at step 0), then the
    # ones it asks for every 250 steps
    assert half == 10 and events[:half] == events[half:], events
    assert events[:2] == [("j1", 0), ("j2", 0)] and events[2:4] == [("j1", 250), ("j2", 250)]


def test_model_exchange_error_status_is_reported_alike(monkeypatch):
    asking_fmus(monkeypatch, fail_at=300)
    sc = load(EXAMPLE)
    messages = []
    for engine in ("python", "kernel"):  # a session each: the fake counts its calls per instance
        with prepare(sc) as session, pytest.raises(DesignerError) as info:
            session.trace(duration=1.0, engine=engine)
        messages.append(str(info.value))
    assert messages[0] == messages[1]
    assert "FMU j1: fmi2CompletedIntegratorStep returned Error at t = 0.3 s" in messages[0]


def test_public_run_says_which_engine_ran(tmp_path):
    import designer.cosim

    sc = n_link(tmp_path, 2, "gauss-seidel")
    fast = designer.cosim.run(sc)
    slow = designer.cosim.run(sc, engine="python")
    assert (fast.engine, slow.engine) == ("kernel", "python")
    assert fast.summary()["engine"] == "kernel" and np.array_equal(fast.values, slow.values)


def test_skipping_the_constraint_stage_changes_no_bit(monkeypatch):
    import mujoco

    from designer.cosim import robot as robot_module

    sc = load(EXAMPLE)
    spec = load_spec(sc.model, sc.lengths, sc.masses)
    assert robot_module.constraint_free(spec.compile())
    spec.joints[0].limited = mujoco.mjtLimited.mjLIMITED_TRUE
    spec.joints[0].range = [-1.0, 1.0]
    assert not robot_module.constraint_free(spec.compile())
    fast = both(sc, duration=2.0)[1]
    monkeypatch.setattr(robot_module, "constraint_free", lambda model: False)
    full = both(sc, duration=2.0)[1]
    assert np.array_equal(fast.values, full.values)


def test_runs_in_threads_agree_and_mujoco_keeps_its_clock():
    import ctypes
    from concurrent.futures import ThreadPoolExecutor

    from designer.cosim.kernel_build import mujoco_paths

    hook = ctypes.c_void_p.in_dll(ctypes.CDLL(str(mujoco_paths()[1])), "mjcb_time")
    before = hook.value
    sc = load(EXAMPLE)

    def one(_):
        with prepare(sc) as session:  # a session per thread: its own FMU instances and MjData
            return session.trace(duration=2.0, engine="kernel").values

    with ThreadPoolExecutor(3) as pool:
        results = list(pool.map(one, range(3)))
    with prepare(replace(sc, algorithm="jacobi")) as session, pytest.raises(DesignerError, match="diverged"):
        session.trace(step=5e-3, duration=1.0, engine="kernel")
    assert all(np.array_equal(results[0], r) for r in results[1:])
    assert hook.value == before


def test_each_fmu_keeps_its_own_log_and_closes_after_an_error():
    from designer.cosim.fmu import _LOGS, FmuSystem

    sc = load(EXAMPLE)
    with prepare(sc) as session:
        first, second = (session.systems[j] for j in ("j1", "j2"))
        assert isinstance(first, FmuSystem)
        with pytest.raises(DesignerError, match=r"(?s)FMU j1: fmi2SetReal returned Error.*not a finite"):
            first.set(np.array([np.nan, 0.0]))
        assert len(first.log) == 1 and not second.log
    assert not _LOGS
