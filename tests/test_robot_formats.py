"""MJCF, URDF and SDF exports checked in the engines that load them: MuJoCo, pybullet, Drake.

References the exporters did not write: the closed-form step response of m q'' + c q' + k q = F,
MuJoCo's own stepping (for the stated stable timesteps), and the co-simulation's in-engine reference
(designer/cosim/robot.py) for the series form.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from designer.errors import DesignerError
from designer.export.mjcf import export_mjcf
from designer.export.stability import step_advice
from designer.export.urdf import export_sdf, export_urdf
from designer.joint import Joint
from designer.validate.export import step_response

mujoco = pytest.importorskip("mujoco")

#: rig units: k N.mm/rad, c N.mm.s/rad, m kg.m^2 -> SI k 0.05 N.m/rad, c 5e-4 N.m.s/rad, J 1e-5 kg.m^2
THETA = {"theta": {"k": 50.0, "c": 0.5, "m": 1e-5}}
HOST = """<mujoco model="host">
  <compiler angle="degree"/>
  <option timestep="0.001"/>
  <default><joint damping="0.01"/></default>
  <worldbody>
    <body name="upper" pos="0 0 0.2" euler="0 30 0">
      <joint name="shoulder" type="hinge" axis="0 1 0" range="-90 90" springref="10"/>
      <geom type="capsule" fromto="0 0 0 0.1 0 0" size="0.01" mass="0.05"/>
      <body name="lower" pos="0.1 0 0">
        <joint name="elbow" type="hinge" axis="0 1 0" range="-120 120"/>
        <geom type="capsule" fromto="0 0 0 0.08 0 0" size="0.008" mass="0.03"/>
      </body>
    </body>
  </worldbody>
  <actuator><position joint="shoulder" kp="5" ctrlrange="-90 90"/></actuator>
</mujoco>
"""


def run_mujoco(model, steps, load=0.0, q0=0.0):
    """Step a one-dof model under a constant generalized force; the joint angle after each step."""
    data = mujoco.MjData(model)
    data.qpos[0] = q0
    out = np.empty(steps)
    for i in range(steps):
        data.qfrc_applied[0] = load
        mujoco.mj_step(model, data)
        out[i] = data.qpos[0]
    return out, data.warning[mujoco.mjtWarning.mjWARN_BADQACC].number


@pytest.mark.parametrize("c", [0.0, 0.5, 20.0])
def test_stated_timesteps_bound_mujoco_stepping(tmp_path, c):
    """Just below each stated limit MuJoCo stays bounded, just above it diverges (all three integrators)."""
    joint = Joint.from_coefficients({"theta": {"k": 50.0, "c": c, "m": 1e-5}})
    out = export_mjcf(joint, tmp_path / "j.xml")
    advice = out.advice["FlexJoint_theta"]
    for integrator, h in advice.max_timestep.items():
        for factor, stable in ((0.97, True), (1.03, False)):
            spec = mujoco.MjSpec.from_file(str(out.path))
            spec.option.timestep = h * factor
            spec.option.integrator = getattr(mujoco.mjtIntegrator, f"mjINT_{integrator.upper()}")
            q, bad = run_mujoco(spec.compile(), 3000, q0=1.0)
            grew = bad > 0 or np.max(np.abs(q[-200:])) > 100.0
            assert grew != stable, (integrator, factor, h)


def test_snippet_has_nothing_global_and_steps_with_the_stated_k_and_c(tmp_path):
    joint = Joint.from_coefficients(THETA)
    out = export_mjcf(joint, tmp_path / "flex.xml")
    text = out.path.read_text()
    root = ET.fromstring(text)
    assert [e.tag for e in root] == ["worldbody"], "only a worldbody: no compiler, option or default"
    # included into a degree-based host, every host range stays in degrees
    (tmp_path / "host.xml").write_text(HOST)
    (tmp_path / "both.xml").write_text(
        HOST.replace("</worldbody>", '</worldbody>\n<include file="flex.xml"/>')
    )
    host = mujoco.MjModel.from_xml_path(str(tmp_path / "host.xml"))
    both = mujoco.MjModel.from_xml_path(str(tmp_path / "both.xml"))
    assert np.array_equal(both.jnt_range[:2], host.jnt_range)
    assert np.allclose(np.degrees(host.jnt_range[0]), [-90, 90])
    flex = both.joint("FlexJoint_theta")
    assert flex.stiffness[0] == 0.05 and both.dof_damping[flex.dofadr[0]] == 5e-4
    # alone: a torque step against the closed form with the stated k, c and link inertia
    spec = mujoco.MjSpec.from_file(str(out.path))
    spec.option.timestep, spec.option.gravity = 1e-5, [0, 0, 0]
    q, _ = run_mujoco(spec.compile(), 20000, load=0.01)
    t = 1e-5 * np.arange(1, 20001)
    ref = step_response(1e-5, 5e-4, 0.05, 0.01, t)
    assert np.max(np.abs(q - ref)) < 2e-3 * 0.2
    assert out.advice["FlexJoint_theta"].natural_frequency == pytest.approx(
        math.sqrt(0.05 / 1e-5) / 2 / math.pi
    )
    assert "natural frequency 11.25 Hz" in text and "RK4" in text


def test_into_a_degree_robot_keeps_every_host_unit(tmp_path):
    host_path = tmp_path / "robot.xml"
    host_path.write_text(HOST)
    joint = Joint.from_coefficients(THETA)
    out = export_mjcf(
        joint, tmp_path / "robot_flex.xml", into=host_path, joint_name="elbow", rest=math.radians(10)
    )
    text = out.path.read_text()
    changed = [(a, b) for a, b in zip(HOST.splitlines(), text.splitlines(), strict=True) if a != b]
    assert len(changed) == 1 and '<joint name="elbow"' in changed[0][1], "only the joint's tag changes"
    assert 'springref="10.0"' in changed[0][1] and 'range="-120 120"' in changed[0][1]
    host = mujoco.MjModel.from_xml_path(str(host_path))
    flex = mujoco.MjModel.from_xml_path(str(out.path))
    assert np.array_equal(flex.jnt_range, host.jnt_range) and np.array_equal(flex.body_quat, host.body_quat)
    j = flex.joint("elbow")
    assert j.stiffness[0] == 0.05 and flex.dof_damping[j.dofadr[0]] == 5e-4
    assert flex.dof_armature[j.dofadr[0]] == 1e-5 and flex.qpos_spring[j.qposadr[0]] == pytest.approx(
        0.174533, 1e-6
    )
    assert flex.dof_damping[0] == host.dof_damping[0] == 0.01
    # stepped: a torque on the elbow settles at springref + tau / k
    flex.opt.gravity[:] = 0
    data = mujoco.MjData(flex)
    for _ in range(6000):
        data.qfrc_applied[j.dofadr[0]] = 1e-3
        mujoco.mj_step(flex, data)
    assert data.qpos[j.qposadr[0]] == pytest.approx(math.radians(10) + 1e-3 / 0.05, rel=1e-3)
    with pytest.raises(DesignerError, match="joint_name='wrist'"):
        export_mjcf(joint, tmp_path / "x.xml", into=host_path, joint_name="wrist")
    slide = Joint.from_coefficients({"x": {"k": 0.8, "c": 2e-3, "m": 0.01}})
    with pytest.raises(DesignerError, match="axis"):
        export_mjcf(slide, tmp_path / "x.xml", into=host_path, joint_name="elbow")


def test_series_form_matches_the_cosimulation_reference(tmp_path):
    """The series form converges on the co-simulation's ideal-motor reference as its servo stiffens."""
    from designer.cosim.references import Sine
    from designer.cosim.robot import Robot, SpringDamper

    joint = Joint.from_coefficients(THETA)
    # a smooth motor move from rest: 0.5 rad, 2 Hz
    h, n, motor = 1e-4, 10000, Sine(amplitude=0.25, frequency=2.0, offset=0.25, phase=-math.pi / 2)
    # the reference: the link alone on an absolute hinge, the flexure torque computed in-engine
    ref_spec = mujoco.MjSpec.from_file(str(export_mjcf(joint, tmp_path / "link.xml").path))
    ref_spec.joint("FlexJoint_theta").stiffness = [0, 0, 0]
    ref_spec.joint("FlexJoint_theta").damping = [0, 0, 0]
    ref_spec.option.gravity = [0, 0, 0]
    ref = Robot(
        ref_spec, {"FlexJoint_theta": motor}, h, in_engine={"FlexJoint_theta": SpringDamper(0.05, 5e-4)}
    )
    q, deflection = np.empty(n), np.empty(n)
    for i in range(n):
        ref.do_step(h)
        q[i], deflection[i] = ref.data.qpos[0], ref.data.qpos[0] - motor((i + 1) * h)[0]
    errors = []
    for bandwidth in (None, 2000.0):
        out = export_mjcf(joint, tmp_path / "sea.xml", form="series", motor_bandwidth=bandwidth)
        assert set(out.advice) == {"FlexJoint_theta", "FlexJoint_motor"}
        spec = mujoco.MjSpec.from_file(str(out.path))
        spec.option.timestep, spec.option.gravity = h, [0, 0, 0]
        model = spec.compile()
        data = mujoco.MjData(model)
        link = np.empty(n)
        for i in range(n):
            data.ctrl[0] = motor((i + 1) * h)[0]
            mujoco.mj_step(model, data)
            link[i] = data.qpos[0] + data.qpos[1]  # absolute link angle = motor + flexure deflection
        errors.append(np.max(np.abs(link - q)))
    # measured: 8.8e-3 rad with the default servo (112 Hz), 2.0e-4 rad at 2 kHz; peak deflection 9.7e-3 rad
    assert errors[0] < 1.0 * np.max(np.abs(deflection)) and errors[1] < 0.03 * np.max(np.abs(deflection))


def test_series_into_a_robot_inserts_a_motor_and_holds_the_link_by_the_flexure(tmp_path):
    host_path = tmp_path / "robot.xml"
    host_path.write_text(HOST)
    out = export_mjcf(
        Joint.from_coefficients(THETA),
        tmp_path / "sea.xml",
        into=host_path,
        joint_name="elbow",
        form="series",
    )
    assert set(out.advice) == {"elbow", "elbow_motor"}
    text = out.path.read_text()
    assert 'name="elbow_motor" pos="0.1 0 0"' in text and '<compiler angle="degree"/>' in text
    host, sea = (mujoco.MjModel.from_xml_path(str(p)) for p in (host_path, out.path))
    assert np.array_equal(sea.joint("elbow_motor").range, host.joint("elbow").range)  # still +/-120 deg
    assert sea.joint("elbow").limited[0] == 0 and sea.joint("elbow").stiffness[0] == 0.05
    # a torque on the link, the servo holding the motor at 0: the flexure alone deflects tau / k
    sea.opt.gravity[:] = 0
    data = mujoco.MjData(sea)
    flex = sea.joint("elbow").dofadr[0]
    for _ in range(4000):
        data.qfrc_applied[flex] = 1e-3
        mujoco.mj_step(sea, data)
    assert data.qpos[sea.joint("elbow").qposadr[0]] == pytest.approx(1e-3 / 0.05, rel=1e-3)
    # an actuator already on the joint moves to the motor instead of a new servo
    (tmp_path / "robot2.xml").write_text(
        HOST.replace("</actuator>", '<motor name="m" joint="elbow"/></actuator>')
    )
    out = export_mjcf(
        Joint.from_coefficients(THETA),
        tmp_path / "sea2.xml",
        into=tmp_path / "robot2.xml",
        joint_name="elbow",
        form="series",
    )
    assert set(out.advice) == {"elbow"} and '<motor name="m" joint="elbow_motor"/>' in out.path.read_text()


@pytest.mark.parametrize("model, joint_name", [("humanoid.xml", "left_hip_z"), ("ant.xml", "hip_3")])
def test_into_robots_others_wrote(tmp_path, model, joint_name):
    """Hosts with default classes, degrees, several joints in a body and motors (pybullet's copies)."""
    import shutil

    pybullet_data = pytest.importorskip("pybullet_data")
    host = tmp_path / model
    shutil.copy(f"{pybullet_data.getDataPath()}/mjcf/{model}", host)
    joint = Joint.from_coefficients(THETA)
    for form in ("parallel", "series"):
        out = export_mjcf(joint, tmp_path / f"{form}.xml", into=host, joint_name=joint_name, form=form)
        assert set(out.advice) == {joint_name}, "the host's motor moves to the motor joint: no servo added"
        model = mujoco.MjModel.from_xml_path(str(out.path))
        assert model.joint(joint_name).stiffness[0] == 0.05
    assert f'joint="{joint_name}_motor"' in out.path.read_text()


def test_urdf_loads_in_mujoco_with_real_links_and_the_gazebo_spring(tmp_path):
    joint = Joint.from_coefficients(THETA)
    out = export_urdf(joint, tmp_path / "j.urdf")
    root = ET.parse(out.path).getroot()
    gz = root.find("gazebo[@reference='FlexJoint_theta']")
    k, rest = float(gz.find("springStiffness").text), float(gz.find("springReference").text)
    assert (k, rest) == (0.05, 0.0)
    masses = {
        link.get("name"): float(link.find("inertial/mass").get("value"))
        for link in root.iter("link")
        if link.find("inertial") is not None
    }
    assert set(masses) == {"FlexJoint_base", "FlexJoint_theta_link"}, "world alone has no inertial"
    assert min(masses.values()) > 1e-3, "no link of mass 0 (Gazebo's converter drops it and all after it)"
    assert root.find("joint[@name='FlexJoint_fixed']/parent").get("link") == "world"
    from designer.export.urdf_inertia import moved_inertia

    assert moved_inertia(root, "FlexJoint_theta") == pytest.approx(out.advice["FlexJoint_theta"].inertia)
    spec = mujoco.MjSpec.from_file(str(out.path))
    spec.joint("FlexJoint_theta").stiffness = [k, 0, 0]  # MuJoCo reads no URDF spring
    spec.option.timestep = 1e-4
    q, _ = run_mujoco(spec.compile(), 5000, load=0.01)
    ref = step_response(1e-5, 5e-4, 0.05, 0.01, 1e-4 * np.arange(1, 5001))
    assert np.max(np.abs(q - ref)) < 5e-3 * 0.2


def test_urdf_steps_in_pybullet_with_default_flags(tmp_path):
    p = pytest.importorskip("pybullet")
    out = export_urdf(Joint.from_coefficients(THETA), tmp_path / "j.urdf")
    gz = ET.parse(out.path).getroot().find("gazebo/springStiffness")
    k = float(gz.text)
    client = p.connect(p.DIRECT)
    try:
        body = p.loadURDF(str(out.path), useFixedBase=True, physicsClientId=client)
        names = [p.getJointInfo(body, i, physicsClientId=client)[1] for i in range(p.getNumJoints(body))]
        j = names.index(b"FlexJoint_theta")  # after FlexJoint_fixed (world -> base)
        info = p.getDynamicsInfo(body, j, physicsClientId=client)
        mass = 1e-5 / (0.85 * 0.024) ** 2  # m / (gamma L)^2 at the middle tested length
        assert info[0] == pytest.approx(mass, rel=1e-9) and info[2] == pytest.approx((1e-5,) * 3)
        p.setTimeStep(1e-4, physicsClientId=client)
        # pybullet's default velocity motor would hold the joint; URDF damping it applies itself
        p.setJointMotorControl2(body, j, p.VELOCITY_CONTROL, force=0, physicsClientId=client)
        q = np.empty(5000)
        for i in range(5000):
            s = p.getJointState(body, j, physicsClientId=client)[0]
            p.setJointMotorControl2(body, j, p.TORQUE_CONTROL, force=0.01 - k * s, physicsClientId=client)
            p.stepSimulation(physicsClientId=client)
            q[i] = p.getJointState(body, j, physicsClientId=client)[0]
    finally:
        p.disconnect(client)
    ref = step_response(1e-5, 5e-4, 0.05, 0.01, 1e-4 * np.arange(1, 5001))
    assert np.max(np.abs(q - ref)) < 1e-2 * 0.2


def test_urdf_into_a_robot_sets_damping_and_the_spring_extension(tmp_path):
    host = tmp_path / "arm.urdf"
    host.write_text(
        '<robot name="arm"><link name="base"/><link name="l1"><inertial><mass value="0.1"/>'
        '<inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial></link>'
        '<joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 1 0"/>'
        '<limit lower="-1.5" upper="1.5" effort="5" velocity="3"/></joint></robot>'
    )
    out = export_urdf(Joint.from_coefficients(THETA), tmp_path / "arm_flex.urdf", into=host, joint_name="j1")
    root = ET.parse(out.path).getroot()
    assert root.find("joint/dynamics").get("damping") == "0.0005"
    assert root.find("gazebo[@reference='j1']/springStiffness").text == "0.05"
    assert root.find("joint/limit").get("upper") == "1.5"
    assert mujoco.MjModel.from_xml_path(str(out.path)).dof_damping[0] == 5e-4
    assert out.advice["j1"].inertia == pytest.approx(1e-4)  # l1's inertia about y, from its <inertial>


def test_urdf_into_a_robot_others_wrote_loads_in_pybullet(tmp_path):
    """Franka Panda (pybullet's copy, meshes beside it): text edits only (damping, Gazebo and Drake
    extensions, Drake's namespace on <robot>), pybullet reads the damping."""
    import difflib
    import shutil

    p = pytest.importorskip("pybullet")
    pybullet_data = pytest.importorskip("pybullet_data")
    folder = shutil.copytree(f"{pybullet_data.getDataPath()}/franka_panda", tmp_path / "panda")
    out = export_urdf(
        Joint.from_coefficients(THETA),
        folder / "flex.urdf",
        into=folder / "panda.urdf",
        joint_name="panda_joint4",
    )
    before, after = (f.read_text().splitlines() for f in (folder / "panda.urdf", out.path))
    robot_tag = next(line for line in before if line.lstrip().startswith("<robot"))
    declared = robot_tag.replace(">", ' xmlns:drake="http://drake.mit.edu">', 1)
    added = [line[2:].strip() for line in difflib.ndiff(before, after) if line.startswith("+ ")]
    assert added[0] == declared.strip() and added[1] == '<dynamics damping="0.0005"/>'
    assert "<springStiffness>0.05</springStiffness>" in added and "<drake:linear_bushing_rpy>" in added
    removed = [line[2:] for line in difflib.ndiff(before, after) if line.startswith("- ")]
    assert all(not line.strip() or line == robot_tag for line in removed), "nothing of the host is lost"
    client = p.connect(p.DIRECT)
    try:
        body = p.loadURDF(str(out.path), useFixedBase=True, physicsClientId=client)
        names = [
            p.getJointInfo(body, i, physicsClientId=client)[1]
            for i in range(p.getNumJoints(body, physicsClientId=client))
        ]
        info = p.getJointInfo(body, names.index(b"panda_joint4"), physicsClientId=client)
        # the advice's inertia against pybullet's mass matrix, the links' inertia as the file states it
        body = p.loadURDF(
            str(out.path), useFixedBase=True, flags=p.URDF_USE_INERTIA_FROM_FILE, physicsClientId=client
        )
        movable = [
            n
            for i, n in enumerate(names)
            if p.getJointInfo(body, i, physicsClientId=client)[2] != p.JOINT_FIXED
        ]
        mass_matrix = np.array(p.calculateMassMatrix(body, [0.0] * len(movable), physicsClientId=client))
    finally:
        p.disconnect(client)
    assert info[6] == 5e-4  # jointDamping
    k = movable.index(b"panda_joint4")
    assert out.advice["panda_joint4"].inertia == pytest.approx(mass_matrix[k, k], rel=1e-12)


def test_urdf_spring_reaches_drake_through_its_bushing(tmp_path):
    """A standalone URDF chain (hinge then slide, rest 0.2): Drake's joint forces are -k (q - rest)."""
    pytest.importorskip("pydrake", reason="pydrake (Drake) is not installed: pip install drake")
    from test_robot_hosts import drake_joint_torque

    joint = Joint.from_coefficients({**THETA, "x": {"k": 0.8, "c": 2e-3, "m": 0.01}})
    out = export_urdf(joint, tmp_path / "j.urdf", rest=0.2)
    for name, k, positions in (
        ("FlexJoint_theta", 0.05, [-2.8, 0.2, 3.0]),
        ("FlexJoint_x", 800.0, [0.1, 0.2, 0.25]),
    ):
        got = drake_joint_torque(out.path, name, positions, prismatic=name.endswith("x"))
        assert got == pytest.approx([-k * (q - 0.2) for q in positions], rel=1e-9, abs=1e-15), name


def test_sdf_spring_becomes_a_drake_revolute_spring(tmp_path):
    out = export_sdf(Joint.from_coefficients(THETA), tmp_path / "j.sdf")
    dyn = ET.parse(out.path).getroot().find("model/joint[@name='FlexJoint_theta']/axis/dynamics")
    assert [dyn.find(t).text for t in ("spring_stiffness", "spring_reference", "damping")] == [
        "0.05",
        "0",
        "0.0005",
    ]
    plant_module = pytest.importorskip("pydrake.multibody.plant")
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.tree import ForceElementIndex, RevoluteSpring

    plant = plant_module.MultibodyPlant(0.0)
    Parser(plant).AddModels(str(out.path))
    plant.Finalize()
    elements = [plant.get_force_element(ForceElementIndex(i)) for i in range(plant.num_force_elements())]
    springs = [e for e in elements if isinstance(e, RevoluteSpring)]
    assert len(springs) == 1 and springs[0].default_stiffness() == 0.05
    assert springs[0].default_nominal_angle() == 0.0
    assert plant.GetJointByName("FlexJoint_theta").default_damping() == 5e-4
    body = plant.GetBodyByName("FlexJoint_theta_link")
    assert body.default_rotational_inertia().get_moments()[1] == pytest.approx(1e-5)


def test_robot_writers_refuse_other_suffixes_naming_path(tmp_path):
    joint = Joint.from_coefficients(THETA)
    from designer import export_fmu

    for writer, bad in (
        (export_mjcf, "j.urdf"),
        (export_urdf, "j.xml"),
        (export_sdf, "j.urdf"),
        (export_fmu, "j.zip"),
    ):
        with pytest.raises(DesignerError, match="path="):
            writer(joint, tmp_path / bad)
    with pytest.raises(DesignerError, match="rest=0.1 is for exports into a robot"):
        export_mjcf(joint, tmp_path / "j.xml", rest=0.1)  # a snippet's springref would read as degrees
    text = export_urdf(joint, tmp_path / "j.urdf", rest=0.1).path.read_text()
    assert "<springReference>0.1</springReference>" in text
    with pytest.raises(DesignerError, match="m for every axis"):
        export_urdf(Joint.from_coefficients({"theta": {"k": 50.0, "c": 0.5}}), tmp_path / "j.urdf")


def test_step_advice_closed_forms():
    undamped = step_advice(4.0, 0.0, 1.0)
    assert undamped.natural_frequency == pytest.approx(1 / math.pi)
    assert undamped.max_timestep["Euler"] == pytest.approx(1.0)  # 2 / omega
    assert undamped.max_timestep["RK4"] == pytest.approx(math.sqrt(2), rel=1e-6)  # 2 sqrt(2) / omega
    overdamped = step_advice(1.0, 1e3, 1.0)  # fast root -1e3: RK4's real-axis limit 2.785 / 1e3
    assert overdamped.max_timestep["RK4"] == pytest.approx(2.785293563 / (1e3 - 1e-3), rel=1e-6)


def test_cli_mjcf_into_urdf_and_sdf(tmp_path, monkeypatch, capsys):
    """The sub-commands in-process through the installed entry point (one interpreter: the suite's budget)."""
    import json
    import sys

    from designer_cli.main import main

    (tmp_path / "robot.xml").write_text(HOST)
    monkeypatch.chdir(tmp_path)

    def run(*args):
        monkeypatch.setattr(sys, "argv", ["designer", "export", *args])
        with pytest.raises(SystemExit) as exit_:
            main()
        out = capsys.readouterr()
        return exit_.value.code or 0, out.out, out.err

    joint = ["--k", "50", "--c", "0.5", "--m", "1e-5", "--axis", "theta"]
    code, out, err = run(
        "mjcf", *joint, "--into", "robot.xml", "--joint", "elbow", "-o", "robot_flex.xml", "--json"
    )
    assert code == 0, err
    advice = json.loads(out)["advice"]["elbow"]
    assert set(advice["max_stable_timestep_s"]) == {"Euler", "implicitfast", "RK4"}
    assert 'range="-120 120"' in (tmp_path / "robot_flex.xml").read_text()
    code, out, _ = run("mjcf", *joint, "--form", "series", "-o", "sea.xml")
    assert code == 0 and "natural frequency" in out and "FlexJoint_motor" in out
    assert run("urdf", *joint, "-o", "j.urdf")[0] == 0 and run("sdf", *joint, "-o", "j.sdf")[0] == 0
    code, _, err = run("mjcf", *joint, "--into", "robot.xml", "--joint", "wrist", "-o", "x.xml")
    assert code == 2 and "elbow" in err and "Traceback" not in err


@pytest.mark.parametrize(
    "robot, joint", [("xarm/xarm6_robot.urdf", "joint3"), ("a1/a1.urdf", "FR_lower_joint")]
)
def test_urdf_into_a_ros_robot_with_transmissions(tmp_path, robot, joint):
    """pybullet_data's xArm6 and Unitree A1 name every joint again in a <transmission>: the robot-level
    <joint> is the one edited (it used to be refused as '2 found'), and nothing else changes."""
    import subprocess
    from pathlib import Path

    from clitools import CLI
    from lxml import etree

    pybullet_data = pytest.importorskip("pybullet_data")
    host = Path(pybullet_data.getDataPath()) / robot
    out = tmp_path / "flex.urdf"
    code = subprocess.run(
        [
            *CLI,
            "export",
            "urdf",
            "--axis",
            "theta",
            "--k",
            "330",
            "--c",
            "0.83",
            "--into",
            str(host),
            "--joint",
            joint,
            "-o",
            str(out),
        ],
        capture_output=True,
        text=True,
    )
    assert code.returncode == 0, code.stderr
    before, after = etree.parse(str(host)).getroot(), etree.parse(str(out)).getroot()
    edited = after.xpath("/robot/joint[@name=$n]/dynamics", n=joint)[0]
    assert float(edited.get("damping")) == pytest.approx(0.83e-3)
    gazebo = after.xpath("/robot/gazebo[@reference=$n]/springStiffness", n=joint)[0]
    assert float(gazebo.text) == pytest.approx(0.33)
    for j_before, j_after in zip(before.iter("joint"), after.iter("joint"), strict=True):
        if not (j_after.get("name") == joint and j_after.getparent() is after):
            # exclusive c14n: the namespaces declared on <robot> (Drake's is added) are not the joint's
            c14n = {"method": "c14n", "exclusive": True}
            assert etree.tostring(j_before, **c14n) == etree.tostring(j_after, **c14n)


TENDON_HOST = """<mujoco model="knees">
  <worldbody>
    <body name="thigh">
      <joint name="hip" type="hinge" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.03"/>
      <body name="shin" pos="0 0 -0.3">
        <joint name="knee" type="hinge" axis="0 1 0" springref="0"/>
        <geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.03"/>
      </body>
    </body>
  </worldbody>
  <tendon>
    <fixed name="coupling" stiffness="1">
      <joint joint="hip" coef="1"/>
      <joint joint="knee" coef="-1"/>
    </fixed>
  </tendon>
</mujoco>
"""


def test_into_a_joint_of_a_fixed_tendon_with_a_new_rest(tmp_path):
    """A new springref moves MuJoCo's derived tendon_lengthspring: the edit's own consequence, not a
    forbidden change (gymnasium's humanoid knees and mujoco's hipy_0 ended as exit 3 'a bug')."""
    host_path = tmp_path / "knees.xml"
    host_path.write_text(TENDON_HOST)
    out = export_mjcf(
        Joint.from_coefficients(THETA),
        tmp_path / "knees_flex.xml",
        into=host_path,
        joint_name="knee",
        rest=0.3,
    )
    flex, host = mujoco.MjModel.from_xml_path(str(out.path)), mujoco.MjModel.from_xml_path(str(host_path))
    assert flex.qpos_spring[flex.joint("knee").qposadr[0]] == pytest.approx(0.3)
    assert np.array_equal(flex.tendon_stiffness, host.tendon_stiffness)
    assert not np.array_equal(flex.tendon_lengthspring, host.tendon_lengthspring)  # derived from the rest


@pytest.mark.parametrize("rest", [0.0, 0.2])
def test_series_into_keeps_every_keyframe_pose(tmp_path, rest):
    """The inserted motor joint would shift every later qpos entry of a <key> (MuJoCo pads a short key
    silently): each key gets the motor at the host's angle less the rest, the flexure at its rest."""
    keyed = HOST.replace(
        "</mujoco>",
        '<keyframe><key name="bent" qpos="0.3 -0.7" qvel="0.1 0.2" ctrl="0.25"/>'
        '<key name="still" qpos="-0.2 0.5"/></keyframe>\n</mujoco>',
    )
    host_path = tmp_path / "keyed.xml"
    host_path.write_text(keyed)
    out = export_mjcf(
        Joint.from_coefficients(THETA),
        tmp_path / "sea.xml",
        into=host_path,
        joint_name="elbow",
        form="series",
        rest=rest,
    )
    host, sea = (mujoco.MjModel.from_xml_path(str(p)) for p in (host_path, out.path))
    assert sea.nkey == host.nkey == 2 and sea.nq == host.nq + 1
    for k in range(host.nkey):
        poses = []
        for m in (host, sea):
            d = mujoco.MjData(m)
            mujoco.mj_resetDataKeyframe(m, d, k)
            mujoco.mj_kinematics(m, d)
            poses.append({b: (d.body(b).xpos.copy(), d.body(b).xquat.copy()) for b in ("upper", "lower")})
        for b in ("upper", "lower"):
            np.testing.assert_allclose(poses[1][b][0], poses[0][b][0], atol=1e-12)
            np.testing.assert_allclose(poses[1][b][1], poses[0][b][1], atol=1e-12)
        assert sea.key_qpos[k][sea.joint("elbow").qposadr[0]] == pytest.approx(rest)
    assert sea.key_ctrl[0][-1] == pytest.approx(-0.7 - rest)  # the added servo holds the motor there
    short = HOST.replace("</mujoco>", '<keyframe><key name="short" qpos="0.3"/></keyframe>\n</mujoco>')
    (tmp_path / "short.xml").write_text(short)
    with pytest.raises(DesignerError, match="gives 1 of the robot's 2 qpos values"):
        export_mjcf(
            Joint.from_coefficients(THETA),
            tmp_path / "s.xml",
            into=tmp_path / "short.xml",
            joint_name="elbow",
            form="series",
        )


def test_parallel_into_keeps_the_hosts_springref_and_armature_and_says_what_changed(tmp_path):
    """reacher-like host: armature 1 and springref 30 deg stay unless asked; a rest outside the range
    is refused; every changed host value is listed old -> new."""
    host = HOST.replace(
        '<joint name="elbow" type="hinge" axis="0 1 0" range="-120 120"/>',
        '<joint name="elbow" type="hinge" axis="0 1 0" range="-120 120" armature="1" springref="30"/>',
    )
    host_path = tmp_path / "robot.xml"
    host_path.write_text(host)
    joint = Joint.from_coefficients(THETA)
    out = export_mjcf(joint, tmp_path / "flex.xml", into=host_path, joint_name="elbow")
    flex = mujoco.MjModel.from_xml_path(str(out.path))
    j = flex.joint("elbow")
    assert flex.dof_armature[j.dofadr[0]] == 1.0 and flex.qpos_spring[j.qposadr[0]] == pytest.approx(
        math.radians(30)
    )
    assert j.stiffness[0] == 0.05
    text = "\n".join(out.notes)
    assert "springref kept" in text and "armature kept" in text and "stiffness: 0 -> 0.05" in text
    with pytest.raises(DesignerError, match="outside the range"):
        export_mjcf(joint, tmp_path / "far.xml", into=host_path, joint_name="elbow", rest=math.radians(150))
    far = export_mjcf(
        joint,
        tmp_path / "far.xml",
        into=host_path,
        joint_name="elbow",
        rest=math.radians(150),
        allow_outside_range=True,
    )
    assert "springref: 0.5236 -> 2.618 (SI)" in "\n".join(far.notes)
