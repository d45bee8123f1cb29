"""What an export into a robot does with the host's own values, checked by stepping MuJoCo:
a spring rest outside the joint's range (MJCF and URDF alike), `dampratio` actuators whose damping
MuJoCo derives from the mass matrix, and, in series, which joint carries the host's friction, spring
and damping."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from robot_packages import example_robot_data, package_dir

from designer.errors import DesignerError
from designer.export.mjcf import export_mjcf
from designer.export.urdf import export_urdf
from designer.joint import Joint
from designer.validate.export import gain_changes, other_joint_changes, pose_changes

mujoco = pytest.importorskip("mujoco")

#: SI: k 0.5 N.m/rad, c 0.01 N.m.s/rad, J 1e-5 kg.m^2
JOINT = Joint.from_coefficients({"theta": {"k": 500.0, "c": 10.0, "m": 1e-5}})
SI = JOINT.axes["theta"].si()

#: a Panda-like arm: joint4's range excludes 0 (MuJoCo's default springref), the home keyframe
#: bends it, and position servos hold the home pose
PANDA_LIKE = """<mujoco model="arm">
  <compiler angle="radian"/>
  <option timestep="0.001"/>
  <worldbody>
    <body name="upper">
      <joint name="joint1" type="hinge" axis="0 0 1" range="-2.9 2.9" damping="1"/>
      <geom type="capsule" fromto="0 0 0 0 0 0.3" size="0.04" mass="2"/>
      <body name="fore" pos="0 0 0.3">
        <joint name="joint4" type="hinge" axis="0 1 0" range="-3.0718 -0.0698" damping="1"/>
        <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03" mass="1.5"/>
      </body>
    </body>
  </worldbody>
  <actuator>
    <position name="a1" joint="joint1" kp="300" kv="20"/>
    <position name="a4" joint="joint4" kp="300" kv="20"/>
  </actuator>
  <keyframe>
    <key name="home" qpos="0 -1.571" ctrl="0 -1.571"/>
  </keyframe>
</mujoco>
"""


def _held_from_home(path: Path, seconds: float = 3.0) -> float:
    """joint4's angle after `seconds` from the home keyframe under the robot's own servos."""
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    mujoco.mj_step(model, data, nstep=round(seconds / model.opt.timestep))
    return float(data.qpos[model.joint("joint4").qposadr[0]])


def test_parallel_rest_outside_the_range_takes_the_keyframe_and_says_so(tmp_path):
    """Before: the host's springref 0 (outside [-3.07, -0.07]) was kept silently and the edited arm,
    reset to home under its own servos, drifted off its pose."""
    host = tmp_path / "arm.xml"
    host.write_text(PANDA_LIKE)
    assert _held_from_home(host) == pytest.approx(-1.571, abs=1e-3)
    # 50 N.m/rad, a sixth of the servo's stiffness: a spring resting at 0 pulls joint4 0.23 rad off (measured)
    stiff = Joint.from_coefficients({"theta": {"k": 5e4, "c": 100.0, "m": 1e-5}})
    out = export_mjcf(stiff, tmp_path / "flex.xml", into=host, joint_name="joint4")
    model = mujoco.MjModel.from_xml_path(str(out.path))
    assert model.qpos_spring[model.joint("joint4").qposadr[0]] == -1.571
    text = " | ".join(out.notes)
    assert "outside the joint's range [-3.072, -0.0698] rad" in text
    assert "the keyframe 'home' pose's -1.571 rad" in text and "springref: 0 -> -1.571 (SI)" in text
    # the stiff flexure no longer pulls the joint off the pose its servo holds
    assert _held_from_home(out.path) == pytest.approx(-1.571, abs=1e-3)
    # without a keyframe inside the range: the range's value nearest the host's springref
    bare = tmp_path / "bare.xml"
    bare.write_text(PANDA_LIKE.replace('"0 -1.571"', '"0 -3.2"'))
    out = export_mjcf(JOINT, tmp_path / "flex2.xml", into=bare, joint_name="joint4")
    assert "the range's nearest value -0.0698 rad" in " | ".join(out.notes)
    model = mujoco.MjModel.from_xml_path(str(out.path))
    assert model.qpos_spring[model.joint("joint4").qposadr[0]] == -0.0698


def test_ant_ankle_rest_moves_inside_its_range(tmp_path):
    """gymnasium's ant (angles in degrees, no keyframe): ankle_1's range [30, 70] deg excludes its
    springref 0; the rest becomes 30 deg, written in degrees, and nothing else of the ant changes."""
    folder = package_dir("gymnasium", "envs/mujoco/assets")
    if folder is None:
        pytest.skip("gymnasium is not installed")
    source = folder / "ant.xml"
    host = tmp_path / "ant.xml"
    host.write_bytes(source.read_bytes())
    before = mujoco.MjModel.from_xml_path(str(host))
    out = export_mjcf(JOINT, tmp_path / "flex.xml", into=host, joint_name="ankle_1")
    after = mujoco.MjModel.from_xml_path(str(out.path))
    assert after.qpos_spring[after.joint("ankle_1").qposadr[0]] == pytest.approx(math.radians(30), rel=1e-12)
    assert "the range's nearest value 0.5236 rad" in " | ".join(out.notes)
    assert other_joint_changes(before, after, "ankle_1") == [] and pose_changes(before, after) == []


def _panda_urdf() -> Path:
    return example_robot_data() / "robots/panda_description/urdf/panda.urdf"


def test_urdf_rest_checked_against_the_joint_limits_as_mjcf(tmp_path):
    """Before: URDF --into never looked at <limit>: rest 3 on panda_joint4 (-3.07..-0.07) was written."""
    host = _panda_urdf()
    with pytest.raises(DesignerError, match=r"rest=3 rad is outside the range \[-3.072, -0.0698\] rad") as no:
        export_urdf(JOINT, tmp_path / "p.urdf", into=host, joint_name="panda_joint4", rest=3.0)
    assert "\n" not in str(no.value) and not (tmp_path / "p.urdf").exists()
    out = export_urdf(JOINT, tmp_path / "p.urdf", into=host, joint_name="panda_joint4")
    text = " | ".join(out.notes)
    assert "springReference: the host's 0 rad lies outside the joint's range [-3.072, -0.0698] rad" in text
    assert "<springReference>-0.0698</springReference>" in out.path.read_text()
    out = export_urdf(
        JOINT, tmp_path / "q.urdf", into=host, joint_name="panda_joint4", rest=3.0, allow_outside_range=True
    )
    assert "<springReference>3.0</springReference>" in out.path.read_text()
    out = export_urdf(JOINT, tmp_path / "r.urdf", into=host, joint_name="panda_joint4", rest=-1.0)
    assert "<springReference>-1.0</springReference>" in out.path.read_text()


#: a G1-like leg: position servos whose damping MuJoCo derives from dampratio (a class default and
#: one on the element), a general actuator with dampratio in its bias, joints without armature
DAMPRATIO_HOST = """<mujoco model="leg">
  <compiler angle="radian"/>
  <default>
    <position kp="80" dampratio="1"/>
  </default>
  <worldbody>
    <body name="thigh">
      <joint name="hip" type="hinge" axis="0 1 0" range="-1.5 1.5"/>
      <geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.04" mass="3"/>
      <body name="shin" pos="0 0 -0.3">
        <joint name="knee" type="hinge" axis="0 1 0" range="0 2.5"/>
        <geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.03" mass="2"/>
        <body name="foot" pos="0 0 -0.3">
          <joint name="ankle" type="hinge" axis="0 1 0" range="-0.8 0.8"/>
          <geom type="box" size="0.08 0.03 0.02" mass="0.5"/>
        </body>
      </body>
    </body>
  </worldbody>
  <actuator>
    <position name="hip_servo" joint="hip"/>
    <position name="knee_servo" joint="knee" kp="120" dampratio="0.7"/>
    <general name="ankle_servo" joint="ankle" biastype="affine" gainprm="40" biasprm="0 -40 1"/>
  </actuator>
</mujoco>
"""


@pytest.mark.parametrize("form", ["parallel", "series"])
def test_dampratio_actuators_keep_the_gains_the_host_compiled(tmp_path, form):
    """Before: series moved the knee servo's damping gain (the motor body changes the mass matrix MuJoCo
    derives it from) and printed nothing; parallel into a joint without armature was an internal
    error (actuator_biasprm)."""
    host = tmp_path / "leg.xml"
    host.write_text(DAMPRATIO_HOST)
    before = mujoco.MjModel.from_xml_path(str(host))
    out = export_mjcf(JOINT, tmp_path / f"{form}.xml", into=host, joint_name="knee", form=form)
    after = mujoco.MjModel.from_xml_path(str(out.path))
    assert gain_changes(before, after) == []
    for name in ("hip_servo", "knee_servo", "ankle_servo"):
        assert np.array_equal(before.actuator(name).biasprm, after.actuator(name).biasprm), name
    text = " | ".join(out.notes)
    kv = -before.actuator("knee_servo").biasprm[2]
    assert "3 actuator(s) with dampratio keep the damping gain the host compiled" in text
    assert f"knee_servo dampratio 0.7 -> kv {kv:.4g}" in text
    if form == "series":  # the knee servo now drives the motor joint
        assert after.actuator("knee_servo").trnid[0] == after.joint("knee_motor").id
    assert other_joint_changes(before, after, "knee") == [] and pose_changes(before, after) == []


#: an Apollo/Cassie-like knee: drive friction 7.7 N.m, a 1500 N.m/rad spring, damping 1, a stiff servo
KNEE_HOST = """<mujoco model="knee">
  <compiler angle="radian"/>
  <option timestep="0.0005" gravity="0 0 0"/>
  <worldbody>
    <body name="shin">
      <joint name="knee" type="hinge" axis="0 1 0" range="-2 0.2" frictionloss="7.7" stiffness="1500"
             springref="-0.5" damping="1"/>
      <geom type="capsule" fromto="0 0 0 0 0 -0.4" size="0.03" mass="2"/>
    </body>
  </worldbody>
  <actuator>
    <position name="knee_servo" joint="knee" kp="3000" kv="60"/>
  </actuator>
</mujoco>
"""


def test_series_puts_the_drive_friction_and_spring_on_the_motor_and_says_so(tmp_path):
    """Before: the flexure kept the host's 7.7 N.m frictionloss (a 5 N.m load deflected it 0.0284 rad in
    2 s, not 5 / k = 0.0293) and the motor the 1500 N.m/rad spring, while the notes said 'stiffness 1500
    -> 170.6' of the flexure. Now the flexure is only the flexure: a static load deflects it by load / k."""
    host = tmp_path / "knee.xml"
    host.write_text(KNEE_HOST)
    flex = Joint.from_coefficients({"theta": {"k": 170600.0, "c": 2000.0, "m": 1e-4}})
    k = flex.axes["theta"].si()["k"]
    out = export_mjcf(flex, tmp_path / "sea.xml", into=host, joint_name="knee", form="series", rest=0.0)
    model = mujoco.MjModel.from_xml_path(str(out.path))
    knee, motor = model.joint("knee"), model.joint("knee_motor")
    assert (knee.frictionloss[0], knee.stiffness[0]) == (0.0, k)
    assert (motor.frictionloss[0], motor.stiffness[0], motor.damping[0]) == (7.7, 1500.0, 1.0)
    assert motor.qpos_spring[0] == -0.5
    text = " | ".join(out.notes)
    assert "knee is now the flexure (SI): stiffness 170.6, damping 2, armature 0.0001" in text
    assert "frictionloss 0; nothing of the host joint's own" in text
    assert (
        "knee_motor, the drive, carries the host joint's (SI): stiffness 1500 about springref -0.5 rad, "
        "damping 1, frictionloss 7.7" in text
    )
    # 5 N.m on the link, the servo holding the motor at the spring's rest: the flexure deflects 5 / k
    data = mujoco.MjData(model)
    data.qpos[motor.qposadr[0]] = -0.5
    data.ctrl[model.actuator("knee_servo").id] = -0.5
    data.xfrc_applied[model.body("shin").id, 3:] = [0.0, 5.0, 0.0]  # torque about the joint axis y
    mujoco.mj_step(model, data, nstep=4000)
    assert data.qpos[knee.qposadr[0]] == pytest.approx(5.0 / k, rel=1e-3)


def test_mjcf_into_a_urdf_says_what_to_do(tmp_path):
    """MuJoCo loads a URDF, so the export got as far as 'joint not written in the file (an <include>)'."""
    host = tmp_path / "arm.urdf"
    inertia = '<inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/>'
    inertial = f'<inertial><mass value="1"/>{inertia}</inertial>'
    host.write_text(
        f'<robot name="arm"><link name="a">{inertial}</link><link name="b">{inertial}</link>'
        '<joint name="j" type="continuous"><parent link="a"/><child link="b"/></joint></robot>'
    )
    with pytest.raises(DesignerError, match="is a URDF: .*export urdf with into='arm.urdf'") as refused:
        export_mjcf(JOINT, tmp_path / "out.xml", into=host, joint_name="j")
    assert "\n" not in str(refused.value) and not (tmp_path / "out.xml").exists()


def test_mjcf_into_a_ros_urdf_is_refused_as_a_urdf_not_for_its_meshes():
    """A ROS URDF's meshes are package:// URIs MuJoCo cannot open: the refusal must still be the one
    that says what to do (it was 'MuJoCo cannot load ... package:/...stl', give an MJCF file)."""
    host = example_robot_data() / "robots/ur_description/urdf/ur5_robot.urdf"
    with pytest.raises(DesignerError, match="is a URDF: .*export urdf with into='ur5_robot.urdf'"):
        export_mjcf(JOINT, Path("/nonexistent/out.xml"), into=host, joint_name="elbow_joint")
