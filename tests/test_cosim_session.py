"""A prepared co-simulation Session: set-up once, runs that equal fresh ones, everything freed on
every path; the kernel contract (no private names read by kernel.py) and the one spring-damper law."""

import ast
import os
import tempfile
import textwrap
import threading
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from designer import cosim
from designer.cosim import prepare
from designer.cosim.fmu import _LOGS
from designer.errors import DesignerError

ROOT = Path(__file__).resolve().parent.parent
EXAMPLE = ROOT / "examples" / "two_link_arm.toml"
RIG = ROOT / "examples" / "rig.toml"


@pytest.fixture
def scratch(tmp_path, monkeypatch):
    """The temporary folder this process (and processes it starts) uses, empty."""
    folder = tmp_path / "tmp"
    folder.mkdir()
    monkeypatch.setenv("TMPDIR", str(folder))
    monkeypatch.setattr(tempfile, "tempdir", None)  # re-read TMPDIR
    return folder


def short(path=EXAMPLE, duration=0.2):
    sc = cosim.load(path)
    return replace(sc, duration=duration, validation_duration=duration)


def with_k(sc, joint, k):
    src = sc.joints[joint]
    return replace(sc, joints=sc.joints | {joint: replace(src, parameters={"theta.k": k})})


def test_runs_of_a_session_equal_fresh_runs_bit_for_bit(scratch):
    sc = short()
    with prepare(sc) as session:
        assert [p.name for p in scratch.iterdir()] != []  # the session's folder, while it lives
        first = session.run()
        stiff = session.run({"j1": {"theta.k": 0.5}})
        again = session.run()
        python = session.run({"j1": {"theta.k": 0.5}}, engine="python")
    assert (first.engine, python.engine) == ("kernel", "python")
    assert np.array_equal(first.values, again.values)  # the reset gives back the same start
    fresh = cosim.run(sc)
    assert np.array_equal(first.values, fresh.values) and first.laws == fresh.laws
    assert np.array_equal(stiff.values, cosim.run(with_k(sc, "j1", 0.5)).values)
    assert np.array_equal(stiff.values, python.values)
    assert not np.array_equal(first.values, stiff.values)
    assert stiff.laws["j1"]["k"] == 0.5 and first.laws["j1"]["k"] != 0.5
    assert list(scratch.iterdir()) == [] and not _LOGS


def test_a_rig_session_runs_each_case_as_a_fresh_run(scratch):
    sc = short(RIG, duration=2.0)
    with prepare(sc) as session:
        first = session.run()
        other = session.run({"rig": {"theta.k": 0.2, "theta.c": 5e-4}})
        again = session.run()
    assert np.array_equal(first.values, again.values)
    src = replace(sc.rig_joint, parameters={"theta.k": 0.2, "theta.c": 5e-4})
    assert np.array_equal(other.values, cosim.run(replace(sc, rig_joint=src)).values)
    assert other.metrics["rig"]["coefficients_si"]["k"] == 0.2
    assert list(scratch.iterdir()) == []


def test_duration_and_validation_in_a_session():
    sc = short(duration=0.4)
    with prepare(sc) as session:
        half = session.run(duration=0.2)
        checked = session.run(validate=True)
    assert half.time[-1] == pytest.approx(0.2) and len(half.time) == 201
    assert checked.validation["max_error"] < 1e-9
    assert np.array_equal(checked.values[:201], half.values)


@pytest.mark.parametrize(
    "parameters, message",
    [
        ({"j9": {"theta.k": 1.0}}, "'j9', which is not a joint"),
        ({"j1": {"theta.stiffness": 1.0}}, "'theta.stiffness', not a parameter of axis theta"),
        ({"j1": {"x.k": 1.0}}, "'x.k', not a parameter of axis theta"),
        ({"j1": {"theta.k": float("nan")}}, "is not a finite number"),
        ({"j1": {"theta.k": "stiff"}}, "is not a finite number"),
    ],
)
def test_bad_parameters_are_refused_naming_them(parameters, message):
    with prepare(short()) as session:
        with pytest.raises(DesignerError, match=message):
            session.run(parameters)
        session.run()  # still usable


def test_a_refused_case_is_one_line_and_the_session_goes_on(scratch):
    with prepare(short()) as session:
        with pytest.raises(DesignerError) as info:
            session.run({"j2": {"theta.k": -1.0}})
        assert "\n" not in info.value.problem
        assert info.value.problem.startswith("joint j2: the FMU refused to start with theta.k = -1")
        assert "must not be negative" in info.value.problem  # the FMU's own log line
        assert session.run().laws["j2"]["k"] > 0  # the next case resets the refused instance
    assert list(scratch.iterdir()) == [] and not _LOGS


def test_prepare_failing_halfway_frees_what_it_built(scratch):
    """j1's FMU is instantiated, then j2's refuses its parameters: j1 is freed, the folder removed."""
    sc = with_k(short(), "j2", -5.0)
    with pytest.raises(DesignerError, match="joint j2: the FMU refused to start with theta.k = -5"):
        prepare(sc)
    assert list(scratch.iterdir()) == [] and not _LOGS


def test_a_model_mujoco_cannot_compile_is_one_line_after_the_fmus_were_built(tmp_path, scratch):
    """MuJoCo parses the model but cannot compile it (a missing mesh): the FMUs, instantiated
    first, are freed and the folder removed."""
    xml = tmp_path / "robot.xml"
    xml.write_text(
        '<mujoco><worldbody><body name="b"><joint name="j1" type="hinge" axis="0 1 0"/>'
        '<geom type="mesh" mesh="nosuch"/></body></worldbody></mujoco>'
    )
    sc = short()
    sc = replace(sc, model=xml, joints={"j1": sc.joints["j1"]}, motors={})
    with pytest.raises(DesignerError) as info:
        prepare(sc)
    assert info.value.problem.startswith("MuJoCo cannot compile the robot model: Error: mesh 'nosuch'")
    assert "\n" not in info.value.problem
    assert list(scratch.iterdir()) == [] and not _LOGS


def test_a_closed_session_refuses_to_run(scratch):
    session = prepare(short())
    session.close()
    session.close()  # idempotent
    with pytest.raises(DesignerError, match="the session is closed"):
        session.run()
    assert list(scratch.iterdir()) == []


def test_construction_stores_and_check_validates():
    """Building a Scenario reads no file (so dataclasses.replace is free); check() and prepare do."""
    sc = replace(short(), model=Path("/no/such/robot.xml"))  # no error: only stored
    with pytest.raises(DesignerError, match="robot model /no/such/robot.xml does not exist"):
        prepare(sc)
    src = cosim.JointSource(fmu=Path("/no/such.fmu"))
    with pytest.raises(DesignerError, match="does not exist"):
        src.check()


def test_prepare_reads_each_file_once_and_unpacks_only_what_loads(tmp_path, scratch, monkeypatch):
    """A loaded scenario with a joint FMU file and a joint exported on the fly: prepare parses the MJCF
    once and reads no model description again (load read the file's; the exported one is read from
    its folder); the session's folder holds binaries/ and resources/ (and the exported joint's
    modelDescription.xml), no sources."""
    import fmpy

    from designer.cosim import robot, robot_scenario
    from designer.export.fmu import export_fmu

    sc = short()
    path = export_fmu(sc.joints["j1"].joint, tmp_path / "j1.fmu")
    sc = replace(sc, joints=sc.joints | {"j1": cosim.JointSource(fmu=path)}).check()
    reads, parses = [], []
    real_read, real_spec = fmpy.read_model_description, robot.load_spec
    monkeypatch.setattr(fmpy, "read_model_description", lambda *a, **k: reads.append(a) or real_read(*a, **k))
    monkeypatch.setattr(robot_scenario, "load_spec", lambda *a: parses.append(a) or real_spec(*a))
    monkeypatch.setattr(robot, "load_spec", lambda *a: parses.append(a) or real_spec(*a))
    with prepare(sc) as s:
        (folder,) = scratch.iterdir()
        assert sorted(p.name for p in (folder / "j1").iterdir()) == ["binaries", "resources"]
        assert sorted(p.name for p in (folder / "j2").iterdir()) == [
            "binaries",
            "modelDescription.xml",
            "resources",
        ]
        assert [Path(a[0]).name for a in reads] == ["j2"]  # the exported joint's, from its folder
        assert len(parses) == 1
        s.run()
        s.run({"j1": {"theta.k": 0.4}})
        assert len(reads) == 1 and len(parses) == 1  # runs read nothing
    with prepare(replace(sc, duration=0.1)):  # a changed scenario is checked again
        assert len(parses) == 3
    assert list(scratch.iterdir()) == []


def _resources(folder: Path) -> dict[str, int]:
    return {
        "open files": len(os.listdir("/proc/self/fd")),
        "threads": threading.active_count(),
        "OS threads": len(os.listdir("/proc/self/task")),
        "temporary entries": sum(1 for _ in folder.rglob("*")),
    }


def _rss_mb() -> float:
    pages = int(Path("/proc/self/statm").read_text().split()[1])
    return pages * os.sysconf("SC_PAGE_SIZE") / 2**20


@pytest.mark.skipif(not Path("/proc/self/fd").is_dir(), reason="needs Linux's /proc to count")
def test_a_thousand_runs_hold_files_threads_folders_and_memory(scratch):
    """1000 cases of 50 steps through one Session: open files, threads and temporary entries are the
    same after 10, 100 and 1000 runs, and memory does not grow from 100 to 1000 runs."""
    sc = short(duration=0.05)
    ks = np.linspace(0.2, 0.5, 1000)
    seen, rss = {}, {}
    with prepare(sc) as session:
        for i, k in enumerate(ks, start=1):
            result = session.run({"j1": {"theta.k": float(k)}, "j2": {"theta.c": 1e-3 * float(k)}})
            if i in (10, 100, 1000):
                seen[i] = _resources(scratch)
                rss[i] = _rss_mb()
        assert result.laws["j1"]["k"] == ks[-1]
    print(f"RSS after 100 runs {rss[100]:.1f} MB, after 1000 {rss[1000]:.1f} MB")
    assert seen[10] == seen[100] == seen[1000], seen
    assert rss[1000] - rss[100] < 2.0, rss  # MB: what 900 leaked results of 51 x 10 floats would exceed
    assert list(scratch.iterdir()) == []


def test_kernel_reads_no_private_name_of_another_class():
    """kernel.py binds systems through their public `binding()` only: no `x._name` unless x is self,
    and no dispatch on system types."""
    source = (ROOT / "designer" / "cosim" / "kernel.py").read_text()
    tree = ast.parse(source)
    private = [
        (node.lineno, ast.unparse(node))
        for node in ast.walk(tree)
        if isinstance(node, ast.Attribute)
        and node.attr.startswith("_")
        and not node.attr.startswith("__")
        and not (isinstance(node.value, ast.Name) and node.value.id == "self")
    ]
    assert private == []
    calls = [n.func.id for n in ast.walk(tree) if isinstance(n, ast.Call) and isinstance(n.func, ast.Name)]
    assert "isinstance" not in calls


def test_the_scan_finds_a_private_access():
    """The scan above can fail: the same walk flags `system._steps`."""
    tree = ast.parse("def f(system):\n    return system._steps + self._ok\n")
    found = [
        n.attr
        for n in ast.walk(tree)
        if isinstance(n, ast.Attribute)
        and n.attr.startswith("_")
        and not (isinstance(n.value, ast.Name) and n.value.id == "self")
    ]
    assert found == ["_steps"]


def test_a_system_the_kernel_cannot_bind_is_named():
    from designer.cosim import kernel
    from designer.cosim.master import Master

    class Hold:
        inputs, outputs, feedthrough = [], ["x"], False

        def get(self):
            return np.zeros(1)

        def set(self, values):
            pass

        def do_step(self, h):
            pass

        def reset(self):
            pass

    with pytest.raises(DesignerError, match="cannot run system hold"):
        kernel.bind(Master({"hold": Hold()}, []))


def test_a_system_struct_of_the_wrong_size_is_refused(monkeypatch):
    """The kernel checks each system's own struct (its binding's mirror) against the C's size."""
    import ctypes

    from designer.cosim import kernel
    from designer.cosim.robot import Robot

    real = Robot.binding

    def short_struct(self):
        b = real(self)
        b.struct = (ctypes.c_char * 8)()
        return b

    monkeypatch.setattr(Robot, "binding", short_struct)
    with prepare(short()) as session:
        with pytest.raises(DesignerError, match=r"struct for system robot \(\d+ bytes\) does not match"):
            session.run(engine="kernel")
        assert session.run().engine == "python"  # auto falls back
    assert kernel.library() is not None


def test_in_engine_law_is_the_one_definition():
    """MuJoCo's actuator force equals SpringDamper.torque at every step (the Python robot), the
    kernel computes the same bits, and the sweeps' rollout controls are SpringDamper.control."""
    from designer.cosim import kernel
    from designer.cosim.master import Master
    from designer.cosim.robot import SpringDamper
    from designer.cosim.robot_scenario import robot_reference, robot_system
    from designer.sweep.cases import Case
    from designer.sweep.engine import rollout_traces

    sc = replace(short(duration=0.5), motors={"j1": cosim.Sine(0.4, 1.5), "j2": cosim.Sine(0.3, 2.0)})
    sc = sc.check()
    laws = {"j1": SpringDamper(0.4, 9e-4, 0.02), "j2": SpringDamper(0.25, 6e-4, 0.0)}
    robot = robot_system(sc, sc.step, in_engine=laws)
    for _ in range(300):
        out = robot.get()
        robot.do_step(sc.step)
        for i, (j, law) in enumerate(laws.items()):
            s, v = out[robot.outputs.index(f"{j}.s")], out[robot.outputs.index(f"{j}.v")]
            assert robot.data.actuator_force[robot.actuators[i]] == pytest.approx(law.torque(s, v), rel=1e-12)
    as_dict = {j: {"k": v.k, "c": v.c, "offset": v.offset} for j, v in laws.items()}
    python = Master({"robot": robot_system(sc, sc.step, in_engine=laws)}, []).run(sc.duration, sc.step)
    compiled = robot_reference(sc, as_dict, sc.step, sc.duration, sc.integrator)
    assert compiled.engine == "kernel" and kernel.library() is not None
    assert np.array_equal(python.values, compiled.values)
    # the sweep engine: rig-unit coefficients (N.mm/rad, N.mm.s/rad), no offset in this scenario
    plain = {"j1": SpringDamper(0.4, 9e-4), "j2": SpringDamper(0.25, 6e-4)}
    case = Case(0, {j: {"k": v.k * 1e3, "c": v.c * 1e3} for j, v in plain.items()})
    fast = rollout_traces(sc, [case])[0]
    slow = Master({"robot": robot_system(sc, sc.step, in_engine=plain)}, []).run(sc.duration, sc.step)
    for j in plain:
        np.testing.assert_allclose(
            fast.column(f"robot.{j}.q"), slow.column(f"robot.{j}.q"), rtol=0, atol=1e-12
        )


NEGATIVE = """
[simulation]
duration = 0.1
step = 1e-3
[robot]
model = "arm"
[joints.j1]
axis = "theta"
coefficients = { k = 330, c = 0.83 }
parameters = { "theta.k" = -5.0 }
[joints.j2]
axis = "theta"
coefficients = { k = 330, c = 0.83 }
"""


def test_negative_k_in_a_scenario_names_joint_and_parameter_and_leaves_nothing(tmp_path, scratch):
    """The FMU refuses the override: one DesignerError naming joint and parameter with the FMU's
    log line, and neither the joints' files nor their unpacked archives stay in the temporary folder."""
    (tmp_path / "neg.toml").write_text(textwrap.dedent(NEGATIVE))
    with pytest.raises(DesignerError) as err:
        cosim.run(cosim.load(tmp_path / "neg.toml"))
    assert err.value.problem.startswith("joint j1: the FMU refused to start with theta.k = -5 (")
    assert "must not be negative" in err.value.problem and "\n" not in err.value.problem
    assert list(scratch.iterdir()) == [] and not _LOGS


def test_cli_negative_k_is_one_line_exit_2_and_leaves_nothing(tmp_path):
    import subprocess
    import sys

    scratch = tmp_path / "tmp"
    scratch.mkdir()
    (tmp_path / "neg.toml").write_text(textwrap.dedent(NEGATIVE))
    env = os.environ | {"TMPDIR": str(scratch)}
    script = Path(sys.executable).parent / "designer"
    proc = subprocess.run(
        [str(script), "cosim", "neg.toml", "-o", "out"], cwd=tmp_path, env=env, capture_output=True, text=True
    )
    assert proc.returncode == 2, proc.stderr
    lines = (proc.stdout + proc.stderr).strip().splitlines()
    assert len(lines) == 1, lines
    assert "joint j1" in lines[0] and "theta.k = -5" in lines[0] and "Traceback" not in lines[0]
    assert list(scratch.iterdir()) == [] and not (tmp_path / "out").exists()
