"""Co-simulation with robots as people have them, from installed packages and run from their own
folder: a flexible joint owns its joint (the robot's own servo on it is taken out, and said), the
robot's integrator is kept (or its change said), and `--validate` compares like with like under
MuJoCo's implicit integrators, at the model's own step."""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest
from robot_packages import linked_folder, package_dir

from designer import DesignerError, cosim

mujoco = pytest.importorskip("mujoco")

#: gymnasium-robotics' Adroit hammer (11 meshes, 9 textures, 44 tendons, 2 ms Euler): its arm joint
#: ARRx is held by the robot's own servo A_ARRx (general, kp 200 against gain 500)
ADROIT = """
[simulation]
duration = 1.0
step = 2e-3
{integrator}
[robot]
model = "adroit_hammer.xml"
[joints.ARRx]
coefficients = {{ k = 224934, c = 4773.24 }}
reference = {{ type = "step", amplitude = 0.2, at = 0.1 }}
[validation]
duration = 0.3
steps = [2e-3, 1e-3, 5e-4]
"""


@pytest.fixture
def adroit(tmp_path, monkeypatch):
    """The Adroit hand's folder of links, as the current folder; writes a scenario there."""
    source = package_dir("gymnasium_robotics", "envs/assets/adroit_hand")
    if source is None or not source.is_dir():
        pytest.skip("gymnasium-robotics is not installed")
    monkeypatch.chdir(linked_folder(source, tmp_path / "adroit_hand"))

    def scenario(integrator: str = "") -> Path:
        path = Path(f"flex{len(integrator)}.toml")
        path.write_text(textwrap.dedent(ADROIT.format(integrator=integrator)))
        return path

    return scenario


def test_the_flexible_joint_alone_drives_its_link(adroit):
    """Before: the robot's servo A_ARRx stayed on ARRx and held the link at 0.142 rad while the motor
    stood at 0.2 rad (0.058 rad short, against a 225 N.m/rad flexure). Now it is taken out, said, and
    the link follows its motor, the flexure bent the other way by the hand's weight."""
    with cosim.prepare(cosim.load(adroit())) as session:
        result = session.run()
        robot = session.master.systems["robot"]
        dof = robot.model.joint("ARRx").dofadr[0]
        assert robot.model.nu == 25  # of the hand's 26 actuators
        assert robot.data.qfrc_actuator[dof] == 0.0  # no actuator of the robot acts on the link
    (note,) = [n for n in result.notes if "A_ARRx" in n]
    assert "drove joint 'ARRx'" in note and "removed" in note and "kp 200" in note
    s = result.column("robot.ARRx.s")
    # the hand's weight deflects the flexure beyond the motor (0.040 rad); the servo held it short
    assert result.column("robot.ARRx.motor")[-1] == 0.2 and 0 < s[-1] < 0.05


def test_validate_at_the_models_own_step_under_implicitfast(adroit, capsys):
    """`designer cosim --validate` as typed in the robot's folder. Before: under implicitfast the
    in-engine reference took the flexure's damping implicitly and the co-simulation (a force set each
    step) explicitly: same-step differences of 1e-3 rad, FAIL (exit 1). The reference now computes the
    same explicit force: they agree to round-off, and the errors against RK4 still halve with the step.
    The notes print with their brackets (rich read '[joints.ARRx]' as markup and dropped it)."""
    from clitools import run_inprocess

    code, out, err = run_inprocess(
        ["cosim", adroit('integrator = "implicitfast"'), "-o", "out", "--validate"], capsys
    )
    text = " ".join(out.split())
    assert code == 0 and "validation: pass" in text, out + err
    assert "under implicitfast: a force set each step, as co-simulated" in text
    assert "integrator: the robot's euler -> implicitfast" in text
    assert "keep_host = true in [joints.ARRx]" in text and "'A_ARRx' (a servo, kp 200)" in text


def test_the_robots_own_integrator_is_kept(tmp_path):
    """A robot whose <option> says implicitfast runs with implicitfast unless the scenario names one
    (before: Euler, silently)."""
    (tmp_path / "arm.xml").write_text(
        '<mujoco><option integrator="implicitfast" timestep="0.002"/><worldbody><body name="l">'
        '<joint name="j1" type="hinge" axis="0 1 0"/><geom type="capsule" fromto="0 0 0 0.2 0 0" '
        'size="0.01" mass="0.1"/></body></worldbody></mujoco>'
    )
    base = '[simulation]\nduration = 0.1\nstep = 2e-3\nINTEGRATOR\n[robot]\nmodel = "arm.xml"\n[joints.j1]\n'
    base += (
        'coefficients = { k = 330, c = 0.83 }\nreference = { type = "step", amplitude = 0.1, at = 0.02 }\n'
    )
    (tmp_path / "own.toml").write_text(base.replace("INTEGRATOR", ""))
    (tmp_path / "euler.toml").write_text(base.replace("INTEGRATOR", 'integrator = "euler"'))
    with cosim.prepare(cosim.load(tmp_path / "own.toml")) as session:
        model = session.master.systems["robot"].model
        assert model.opt.integrator == mujoco.mjtIntegrator.mjINT_IMPLICITFAST
        assert not [n for n in session.run().notes if n.startswith("integrator")]
    with cosim.prepare(cosim.load(tmp_path / "euler.toml")) as session:
        assert session.master.systems["robot"].model.opt.integrator == mujoco.mjtIntegrator.mjINT_EULER
        assert "integrator: the robot's implicitfast -> euler" in " | ".join(session.run().notes)


def test_an_actuator_through_a_tendon_on_the_joint_is_refused(tmp_path):
    (tmp_path / "arm.xml").write_text(
        '<mujoco><worldbody><body name="a"><joint name="j1" type="hinge" axis="0 1 0"/>'
        '<geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.01" mass="0.1"/><body name="b" pos="0.2 0 0">'
        '<joint name="j2" type="hinge" axis="0 1 0"/><geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.01"'
        ' mass="0.1"/></body></body></worldbody><tendon><fixed name="t"><joint joint="j1" coef="1"/>'
        '<joint joint="j2" coef="1"/></fixed></tendon><actuator><motor name="m" tendon="t"/></actuator>'
        "</mujoco>"
    )
    (tmp_path / "s.toml").write_text(
        '[simulation]\nduration = 0.1\nstep = 1e-3\n[robot]\nmodel = "arm.xml"\n[joints.j1]\n'
        "coefficients = { k = 330, c = 0.83 }\n"
    )
    with pytest.raises(DesignerError, match="actuator 'm' drives joint 'j1' through tendon 't'") as refused:
        cosim.run(cosim.load(tmp_path / "s.toml"))
    assert "\n" not in str(refused.value)


def test_a_ros_urdf_robot_with_its_package_folder(tmp_path, monkeypatch):
    """example-robot-data's UR5 (meshes named package://example-robot-data/...) from its own folder:
    MuJoCo loads it once the scenario names the package's folder; without it, one line says how."""
    from robot_packages import example_robot_data

    share = example_robot_data()
    monkeypatch.chdir(linked_folder(share / "robots" / "ur_description", tmp_path / "ur") / "urdf")
    scenario = (
        '[simulation]\nduration = 0.2\nstep = 1e-3\n[robot]\nmodel = "ur5_robot.urdf"\nPACKAGES\n'
        "[joints.elbow_joint]\ncoefficients = { k = 224934, c = 4773.24 }\n"
        'reference = { type = "step", amplitude = 0.3, at = 0.05 }\n'
    )
    Path("bare.toml").write_text(scenario.replace("PACKAGES", ""))
    with pytest.raises(DesignerError, match=r'package_paths = \{ example-robot-data = "DIR" \}') as refused:
        cosim.load("bare.toml")
    assert "\n" not in str(refused.value)
    Path("ur5.toml").write_text(
        scenario.replace("PACKAGES", f'package_paths = {{ example-robot-data = "{share}" }}')
    )
    with cosim.prepare(cosim.load("ur5.toml")) as session:
        result = session.run()
        assert session.master.systems["robot"].model.nmesh == 7
    assert abs(result.column("robot.elbow_joint.s")[-1]) < 0.05  # the forearm follows its motor


def test_a_joint_name_that_is_no_identifier(tmp_path):
    """gymnasium-robotics' Franka names its joints 'robot:panda0_joint4': the joint FMU's model name is
    made an identifier (it was refused: "joint name 'joint_robot:j1' is not an identifier")."""
    (tmp_path / "arm.xml").write_text(
        '<mujoco><worldbody><body name="l"><joint name="robot:j1" type="hinge" axis="0 1 0"/>'
        '<geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.01" mass="0.1"/></body></worldbody></mujoco>'
    )
    (tmp_path / "s.toml").write_text(
        '[simulation]\nduration = 0.05\nstep = 1e-3\n[robot]\nmodel = "arm.xml"\n[joints."robot:j1"]\n'
        "coefficients = { k = 330, c = 0.83 }\n"
    )
    result = cosim.run(cosim.load(tmp_path / "s.toml"))
    assert len(result.column("robot.robot:j1.q")) == 51
