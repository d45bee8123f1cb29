"""Exports into robots nobody here wrote, taken from installed packages (none copied into the repository).

MJCF hosts: gymnasium's MuJoCo assets, dm_control's suite, mujoco's own test model. URDF hosts:
pybullet_data's xArm6, Unitree A1, Franka Panda, KUKA iiwa and R2D2. For each export: it runs or is
refused with a one-line reason; the edited joint's k, c and rest are exact in SI in every engine that
reads them; every other body's pose (at the reference pose and at every keyframe) and every other
joint's numbers are unchanged; every host value the export changed is in its notes.

The comparisons here are written from the compiled models (MuJoCo's and pybullet's own readings of
both files), not from the exporter's self-check.
"""

from __future__ import annotations

import math
import os
import shutil
from pathlib import Path

import numpy as np
import pytest
from robot_packages import example_robot_data, linked_folder, package_dir

from designer.errors import DesignerError
from designer.export.mjcf import export_mjcf
from designer.export.urdf import export_urdf
from designer.joint import Joint
from designer.validate.export import gain_changes, joint_numbers, other_joint_changes, pose_changes

mujoco = pytest.importorskip("mujoco")

#: SI: k 0.05 N.m/rad, c 5e-4 N.m.s/rad, J 1e-5 kg.m^2; x: k 800 N/m, c 2 N.s/m, m 0.01 kg
JOINT = Joint.from_coefficients(
    {"theta": {"k": 50.0, "c": 0.5, "m": 1e-5}, "x": {"k": 0.8, "c": 2e-3, "m": 0.01}}
)
SI = {"theta": JOINT.axes["theta"].si(), "x": JOINT.axes["x"].si()}


#: (package, folder in it, file): every MJCF model these packages ship that has a hinge or slide joint
MJCF_FOLDERS = {
    "gymnasium": ("gymnasium", "envs/mujoco/assets"),
    "dm_control": ("dm_control", "suite"),
    "mujoco": ("mujoco", "testdata"),
}
#: joints worth a case of their own beyond each model's first and last (why, in the comment)
EXTRA = {
    ("gymnasium", "humanoid.xml"): ["right_knee"],  # coupled by a fixed tendon
    ("gymnasium", "reacher.xml"): ["joint1"],  # host armature 1
    ("gymnasium", "half_cheetah.xml"): ["bshin"],  # host spring k 180
    ("gymnasium", "ant.xml"): ["ankle_1"],  # range [30, 70] deg
    ("mujoco", "model.xml"): ["hipy_0", "slider"],  # tendon; a joint-limit sensor
    ("dm_control", "dog.xml"): ["Ca_1_extend"],  # springdamper: k and c derived from the mass matrix
}
#: models too large to try every joint's neighbours: only first, last and EXTRA
REFUSALS = {
    # (package, file, joint, form): what the one-line reason must say
    ("mujoco", "model.xml", "slider", "series"): "reads the limit of robot joint 'slider'",
}


def _mjcf_cases() -> list:
    cases = []
    for package, (module, sub) in MJCF_FOLDERS.items():
        folder = package_dir(module, sub)
        if folder is None:
            cases.append(
                pytest.param(package, None, marks=pytest.mark.skip(reason=f"{module} is not installed"))
            )
            continue
        for path in sorted(folder.glob("*.xml")):
            if path.name in ("msh.xml",) or "<worldbody" not in path.read_text(errors="replace"):
                continue
            cases.append(pytest.param(package, path, id=f"{package}-{path.stem}"))
    return cases


@pytest.fixture(scope="module")
def copies(tmp_path_factory):
    """Each package's model folder copied once (outputs go beside the host so its includes resolve)."""
    made: dict[Path, Path] = {}

    def copy(path: Path) -> Path:
        if path.parent not in made:
            target = tmp_path_factory.mktemp("host") / path.parent.name
            shutil.copytree(path.parent, target, ignore=shutil.ignore_patterns("*.py", "__pycache__"))
            made[path.parent] = target
        return made[path.parent] / path.name

    return copy


def _joints(spec, package: str, name: str) -> list[str]:
    kinds = (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE)
    have = [j.name for j in spec.joints if j.type in kinds and j.name]
    picked = [*have[:1], *have[-1:], *EXTRA.get((package, name), [])]
    return list(dict.fromkeys(picked))


def _same_poses(before, after) -> None:
    """Every host body where it was, at the reference pose and at each keyframe (same keys, in order)."""
    assert pose_changes(before, after) == []


def _check_parallel(before, after, name: str, si: dict, notes: tuple[str, ...]) -> None:
    old, new = joint_numbers(before, name), joint_numbers(after, name)
    assert new["stiffness"][0] == si["k"] and new["damping"][0] == si["c"]
    lo, hi = old["range"] if old["limited"][0] else (-np.inf, np.inf)
    if lo <= old["springref"][0] <= hi:
        assert new["springref"][0] == pytest.approx(old["springref"][0], rel=1e-12, abs=1e-15)
    else:  # a host rest outside the range moves inside it, stated
        assert lo - 1e-12 <= new["springref"][0] <= hi + 1e-12
    expected_armature = old["armature"][0] if old["armature"][0] > 0 else si["m"]
    assert new["armature"][0] == expected_armature
    for field in ("frictionloss", "ref", "range", "limited", "axis", "pos"):
        assert np.array_equal(old[field], new[field]), field
    text = " | ".join(notes)
    for field in ("stiffness", "damping", "armature"):
        if new[field][0] != old[field][0]:
            assert f"{field}: {old[field][0]:.4g} -> {new[field][0]:.4g}" in text, (field, text)
    assert "springref kept" in text or "lies outside the joint's range" in text
    if old["armature"][0] > 0:
        assert "armature kept" in text


def _check_series(before, after, name: str, si: dict, notes: tuple[str, ...]) -> None:
    old, new, motor = (
        joint_numbers(before, name),
        joint_numbers(after, name),
        joint_numbers(after, f"{name}_motor"),
    )
    assert new["stiffness"][0] == si["k"] and new["damping"][0] == si["c"] and new["armature"][0] == si["m"]
    assert new["springref"][0] == 0.0 and new["limited"][0] == 0 and new["frictionloss"][0] == 0
    # the motor joint is the drive: the host joint's range, spring, friction (and damping, plus an
    # added servo's derivative gain)
    for field in ("range", "limited", "axis", "ref", "stiffness", "springref", "frictionloss"):
        assert np.array_equal(old[field], motor[field]), field
    text = " | ".join(notes)
    assert f"{name} is now the flexure (SI): stiffness {si['k']:.4g}, damping {si['c']:.4g}" in text
    drive = (
        f"{name}_motor, the drive, carries the host joint's (SI): stiffness {old['stiffness'][0]:.4g} about "
        f"springref {old['springref'][0]:.4g}"
    )
    assert drive in text and f"frictionloss {old['frictionloss'][0]:.4g}" in text
    assert motor["damping"][0] >= old["damping"][0]
    if "servo's derivative gain" not in text:
        assert motor["damping"][0] == old["damping"][0]
    if before.nkey:
        assert f"{before.nkey} keyframe(s) extended" in text
    if old["limited"][0]:
        assert f"moved to {name}_motor" in text


@pytest.mark.parametrize("package, path", _mjcf_cases())
def test_mjcf_into_every_model_the_packages_ship(copies, package, path):
    host = copies(path)
    spec = mujoco.MjSpec.from_file(str(host))
    before = mujoco.MjModel.from_xml_path(str(host))
    tried = 0
    for name in _joints(spec, package, path.name):
        hinge = spec.joint(name).type == mujoco.mjtJoint.mjJNT_HINGE
        axis = "theta" if hinge else "x"
        for form in ("parallel", "series"):
            out_path = host.parent / f"{host.stem}_{name}_{form}.xml"
            reason = REFUSALS.get((package, path.name, name, form))
            if reason is not None:
                with pytest.raises(DesignerError, match=reason) as refused:
                    export_mjcf(JOINT, out_path, into=host, joint_name=name, form=form, axis=axis)
                assert "\n" not in str(refused.value) and not out_path.exists()
                continue
            out = export_mjcf(JOINT, out_path, into=host, joint_name=name, form=form, axis=axis)
            after = mujoco.MjModel.from_xml_path(str(out.path))
            check = _check_parallel if form == "parallel" else _check_series
            check(before, after, name, SI[axis], out.notes)
            assert "qpos0" in out.advice[name].basis
            if spec.joint(name).springdamper[0] > 0:
                assert any(n.startswith("springdamper (time constant") for n in out.notes), out.notes
            if form == "series" and any(j.springdamper[0] > 0 and j.name != name for j in spec.joints):
                assert any("keep their compiled stiffness and damping" in n for n in out.notes), out.notes
            assert other_joint_changes(before, after, name) == [] and gain_changes(before, after) == []
            _same_poses(before, after)
            tried += 1
    assert tried or before.njnt == 0


def test_mjcf_into_refuses_a_rest_outside_the_range_and_takes_one_inside(copies):
    folder = package_dir("gymnasium", "envs/mujoco/assets")
    if folder is None:
        pytest.skip("gymnasium is not installed")
    host = copies(folder / "ant.xml")
    with pytest.raises(DesignerError, match=r"outside the range \[0.5236, 1.222\] rad") as refused:
        export_mjcf(JOINT, host.parent / "a.xml", into=host, joint_name="ankle_1", rest=0.0)
    assert "\n" not in str(refused.value)
    out = export_mjcf(JOINT, host.parent / "a.xml", into=host, joint_name="ankle_1", rest=math.radians(40))
    after = mujoco.MjModel.from_xml_path(str(out.path))
    assert after.qpos_spring[after.joint("ankle_1").qposadr[0]] == pytest.approx(math.radians(40), rel=1e-12)
    assert any(n.startswith("springref: 0 -> 0.6981") for n in out.notes), out.notes


#: pybullet_data robots and a joint of each (ROS transmissions in xArm6 and A1)
URDF_ROBOTS = [
    ("xarm/xarm6_robot.urdf", "joint3"),
    ("a1/a1.urdf", "FR_lower_joint"),
    ("franka_panda/panda.urdf", "panda_joint4"),
    ("franka_panda/panda.urdf", "panda_finger_joint1"),
    ("kuka_iiwa/model.urdf", "lbr_iiwa_joint_4"),
    ("r2d2.urdf", "head_swivel"),
]


def _bullet_state(p, client, robot: int) -> dict:
    """pybullet's reading of a robot: per joint its info (damping apart), per link dynamics and pose."""
    p.resetBasePositionAndOrientation(robot, [0, 0, 0], [0, 0, 0, 1], physicsClientId=client)
    out = {}
    for j in range(p.getNumJoints(robot, physicsClientId=client)):
        info = p.getJointInfo(robot, j, physicsClientId=client)
        name = info[1].decode()
        link = p.getLinkState(robot, j, computeForwardKinematics=True, physicsClientId=client)
        out[name] = {
            "info": info[:6] + info[7:],
            "damping": info[6],
            "dynamics": p.getDynamicsInfo(robot, j, physicsClientId=client)[:4],
            "pose": np.array([*link[4], *link[5]]),
        }
    return out


@pytest.mark.parametrize("file, name", URDF_ROBOTS)
def test_urdf_into_pybullet_data_robots(tmp_path, file, name):
    pybullet_data = pytest.importorskip("pybullet_data")
    import pybullet as p
    from lxml import etree

    host = Path(pybullet_data.getDataPath()) / file
    root = etree.parse(str(host)).getroot()
    prismatic = root.xpath("/robot/joint[@name=$n]", n=name)[0].get("type") == "prismatic"
    axis = "x" if prismatic else "theta"
    si = SI[axis]
    # beside the host's folder (its meshes resolve), in a copy so nothing is written into site-packages
    folder = tmp_path / "robot"
    shutil.copytree(
        host.parent, folder, ignore=shutil.ignore_patterns("*.py", "__pycache__"), dirs_exist_ok=True
    )
    out = export_urdf(JOINT, folder / "flex.urdf", into=folder / host.name, joint_name=name, axis=axis)
    edited = etree.parse(str(out.path)).getroot()
    gz = edited.xpath("/robot/gazebo[@reference=$n]", n=name)
    assert len(gz) == 1
    limit = root.xpath("/robot/joint[@name=$n]/limit", n=name)
    span = (float(limit[0].get("lower", 0)), float(limit[0].get("upper", 0))) if limit else (-np.inf, np.inf)
    rest = min(max(0.0, span[0]), span[1])  # no host springReference: 0, or the limits' nearest value
    assert (
        float(gz[0].findtext("springStiffness")) == si["k"]
        and float(gz[0].findtext("springReference")) == rest
    )
    if name in out.advice:  # the links the joint moves state their inertia
        assert "flags=p.URDF_USE_INERTIA_FROM_FILE" in out.advice[name].text()
    text = " | ".join(out.notes)
    assert "damping: " in text and f"-> {si['c']:.4g} (SI)" in text and "MuJoCo and pybullet" in text
    client = p.connect(p.DIRECT)
    try:
        flags = p.URDF_USE_INERTIA_FROM_FILE
        states = [
            _bullet_state(
                p, client, p.loadURDF(str(f), useFixedBase=True, flags=flags, physicsClientId=client)
            )
            for f in (folder / host.name, out.path)
        ]
    finally:
        p.disconnect(client)
    before, after = states
    assert after[name]["damping"] == si["c"]
    # MuJoCo reads URDF damping too: where it loads the robot, the joint and nothing else changes
    try:
        host_mj = mujoco.MjModel.from_xml_path(str(folder / host.name))
    except ValueError:  # package:// mesh paths (xArm6, Panda), which MuJoCo does not resolve
        host_mj = None
    if host_mj is not None:
        out_mj = mujoco.MjModel.from_xml_path(str(out.path))
        assert joint_numbers(out_mj, name)["damping"][0] == si["c"]
        assert other_joint_changes(host_mj, out_mj, name) == [] and pose_changes(host_mj, out_mj) == []
    assert before.keys() == after.keys()
    for joint, old in before.items():
        new = after[joint]
        assert old["info"] == new["info"] and old["dynamics"] == new["dynamics"], joint
        assert np.allclose(old["pose"], new["pose"], atol=1e-12), joint
        if joint != name:
            assert old["damping"] == new["damping"], joint


def drake_joint_torque(path: Path, name: str, positions: list[float], *, prismatic: bool) -> list[float]:
    """Drake's generalized force on joint `name` of URDF `path` (gravity off, at rest) at each position
    of that joint, every other joint at its default: the joint's spring as Drake reads it."""
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import MultibodyPlant
    from pydrake.multibody.tree import MultibodyForces

    plant = MultibodyPlant(0.0)
    parser = Parser(plant)
    parser.package_map().PopulateFromFolder(str(path.parent))
    parser.AddModels(str(path))
    plant.mutable_gravity_field().set_gravity_vector([0.0, 0.0, 0.0])
    plant.Finalize()
    context = plant.CreateDefaultContext()
    joint = plant.GetJointByName(name)
    out = []
    for q in positions:
        joint.set_translation(context, q) if prismatic else joint.set_angle(context, q)
        forces = MultibodyForces(plant)
        plant.CalcForceElementsContribution(context, forces)
        out.append(float(plant.CalcGeneralizedForces(context, forces)[joint.velocity_start()]))
    return out


@pytest.mark.parametrize("file, name", URDF_ROBOTS)
def test_urdf_into_pybullet_data_robots_gives_drake_the_spring(tmp_path, file, name):
    """Drake reads the spring from the export's bushing: -k (q - rest) on the joint, exactly."""
    pybullet_data = pytest.importorskip("pybullet_data")
    pytest.importorskip("pydrake", reason="pydrake (Drake) is not installed: pip install drake")
    host = Path(pybullet_data.getDataPath()) / file
    folder = tmp_path / "robot"
    shutil.copytree(
        host.parent, folder, ignore=shutil.ignore_patterns("*.py", "__pycache__"), dirs_exist_ok=True
    )
    prismatic = "finger" in name
    axis, rest, span = ("x", 0.01, 0.02) if prismatic else ("theta", 0.3, 1.0)
    from lxml import etree

    limit = etree.parse(str(host)).getroot().xpath("/robot/joint[@name=$n]/limit", n=name)
    if limit and not float(limit[0].get("lower", 0)) <= rest <= float(limit[0].get("upper", 0)):
        rest = (float(limit[0].get("lower", 0)) + float(limit[0].get("upper", 0))) / 2  # inside, as required
    try:
        drake_joint_torque(folder / host.name, name, [0.0], prismatic=prismatic)
    except (
        RuntimeError
    ) as exc:  # the robot as shipped does not load in Drake (xArm6: repeated actuator names)
        pytest.skip(f"Drake does not load {file} as shipped: {str(exc)[:120]}")
    out = export_urdf(
        JOINT, folder / "flex.urdf", into=folder / host.name, joint_name=name, axis=axis, rest=rest
    )
    positions = [rest - 0.5 * span, rest, rest + 0.2 * span]
    got = drake_joint_torque(out.path, name, positions, prismatic=prismatic)
    want = [-SI[axis]["k"] * (q - rest) for q in positions]
    assert got == pytest.approx(want, rel=1e-9, abs=1e-15)


@pytest.mark.parametrize(
    "package, sub, file, name",
    [
        ("gymnasium", "envs/mujoco/assets", "humanoid.xml", "right_knee"),
        ("mujoco", "testdata", "model.xml", "hipy_0"),
    ],
)
def test_a_new_rest_on_a_joint_a_fixed_tendon_couples(copies, package, sub, file, name):
    """MuJoCo derives the tendon's spring length from the new springref: the export runs (it exited 3
    before), the rest is exact, and nothing else of the host changes."""
    folder = package_dir(package, sub)
    if folder is None:
        pytest.skip(f"{package} is not installed")
    host = copies(folder / file)
    before = mujoco.MjModel.from_xml_path(str(host))
    lo, hi = before.joint(name).range if before.joint(name).limited[0] else (-1.0, 1.0)
    rest = 0.3 * lo + 0.7 * hi
    out = export_mjcf(JOINT, host.parent / f"{name}_rest.xml", into=host, joint_name=name, rest=rest)
    after = mujoco.MjModel.from_xml_path(str(out.path))
    assert joint_numbers(after, name)["springref"][0] == pytest.approx(rest, rel=1e-12)
    assert other_joint_changes(before, after, name) == [] and pose_changes(before, after) == []
    assert any(n.startswith("springref: ") for n in out.notes), out.notes


#: mesh-bearing robots of the installed packages: (package, folder linked whole, model in it, joint)
MESH_HOSTS = [
    # 11 meshes, 9 textures, 44 tendons; the arm joint that carries the hand
    ("gymnasium_robotics", "envs/assets", "adroit_hand/adroit_hammer.xml", "ARRx"),
    # 5 meshes (Kinova Jaco), a motor armature of 2 on the joint
    ("dm_control", "third_party/kinova", "jaco_arm.xml", "joint_4"),
]


def _asset_files(model) -> list[str]:
    """Each mesh and texture file a compiled model read, as the absolute path it resolved to."""
    paths = bytes(model.paths)
    out = []
    for adr in (*model.mesh_pathadr, *model.tex_pathadr):
        if adr >= 0:
            out.append(os.path.abspath(paths[adr : paths.index(b"\0", adr)].decode()))
    return out


@pytest.mark.parametrize("package, sub, model, name", MESH_HOSTS)
@pytest.mark.parametrize("form", ["parallel", "series"])
def test_mesh_robots_from_their_own_folder_with_relative_paths(
    tmp_path, monkeypatch, package, sub, model, name, form
):
    """As a user types it: in the robot's folder, relative --into and -o. MuJoCo stores asset file names
    as the file was opened, so a check of the compiled model's name offsets saw 'a change' on every host
    with two or more meshes (exit 3); what the assets mean is compared instead."""
    source = package_dir(package, sub)
    if source is None or not source.is_dir():
        pytest.skip(f"{package} is not installed")
    folder = linked_folder(source, tmp_path / "robot") / Path(model).parent
    monkeypatch.chdir(folder)
    host = Path(Path(model).name)
    before = mujoco.MjModel.from_xml_path(str(host))
    assert before.nmesh >= 2
    out = export_mjcf(JOINT, Path(f"flex_{form}.xml"), into=host, joint_name=name, axis="theta", form=form)
    assert out.path == Path(f"flex_{form}.xml") and out.path.is_file()
    after = mujoco.MjModel.from_xml_path(str(out.path))
    (_check_parallel if form == "parallel" else _check_series)(before, after, name, SI["theta"], out.notes)
    for field in ("mesh_vert", "mesh_face", "mesh_normal", "tex_data", "geom_dataid"):
        assert np.array_equal(getattr(before, field), getattr(after, field)), field
    assert _asset_files(before) == _asset_files(after)
    assert other_joint_changes(before, after, name) == [] and pose_changes(before, after) == []
    assert gain_changes(before, after) == []


def test_cli_into_a_mesh_robot_from_its_folder(tmp_path, monkeypatch, capsys):
    """The command line the issue typed, in the robot's folder: exit 0 (it was 3)."""
    from clitools import run_inprocess

    source = package_dir("dm_control", "third_party/kinova")
    if source is None:
        pytest.skip("dm_control is not installed")
    monkeypatch.chdir(linked_folder(source, tmp_path / "kinova"))
    args = [
        "export",
        "mjcf",
        "--into",
        "jaco_arm.xml",
        "--joint",
        "joint_4",
        "--k",
        "224934",
        "--c",
        "4773.24",
    ]
    code, out, err = run_inprocess([*args, "--m", "1e-05", "--axis", "theta", "-o", "jaco_flex.xml"], capsys)
    assert code == 0, err
    assert Path("jaco_flex.xml").is_file() and "stiffness: 0 -> 224.9 (SI)" in out


#: example-robot-data URDFs (ROS package:// meshes, Collada visuals MuJoCo discards) and a joint each
ERD_ROBOTS = [
    ("robots/ur_description", "urdf/ur5_robot.urdf", "elbow_joint"),
    ("robots/panda_description", "urdf/panda.urdf", "panda_joint4"),
]


@pytest.mark.parametrize("sub, file, name", ERD_ROBOTS)
def test_urdf_into_ros_robots_from_their_folder_checked_in_mujoco(tmp_path, monkeypatch, sub, file, name):
    """From the robot's folder with relative paths: MuJoCo, which reads URDF damping, resolves the
    package:// meshes against the folder given for the package and sees only that damping change;
    without it the export says how to give it."""
    from designer.export.urdf_packages import mujoco_urdf

    share = example_robot_data()
    folder = linked_folder(share / sub, tmp_path / "robot") / Path(file).parent
    monkeypatch.chdir(folder)
    host = Path(Path(file).name)
    packages = {"example-robot-data": share}
    with pytest.raises(ValueError, match="package:/example-robot-data"):
        mujoco.MjModel.from_xml_path(str(host))  # what MuJoCo does with the file as shipped
    out = export_urdf(
        JOINT, Path("flex.urdf"), into=host, joint_name=name, axis="theta", package_paths=packages
    )
    assert any(n.startswith(f"checked in MuJoCo: {name} damping 0.0005 (SI)") for n in out.notes), out.notes
    before, after = mujoco_urdf(host, packages), mujoco_urdf(out.path, packages)
    assert before.nmesh >= 2 and np.array_equal(before.mesh_vert, after.mesh_vert)
    assert joint_numbers(after, name)["damping"][0] == SI["theta"]["c"]
    assert other_joint_changes(before, after, name) == [] and pose_changes(before, after) == []
    unchecked = export_urdf(JOINT, Path("flex2.urdf"), into=host, joint_name=name, axis="theta")
    said = [n for n in unchecked.notes if n.startswith("not checked in MuJoCo")]
    assert said and "package_paths={'example-robot-data': 'DIR'}" in said[0]


def test_cli_package_path(tmp_path, monkeypatch, capsys):
    """--package-path NAME=DIR on the command line; a malformed one is one line, exit 2."""
    from clitools import run_inprocess

    share = example_robot_data()
    monkeypatch.chdir(linked_folder(share / "robots/ur_description", tmp_path / "ur") / "urdf")
    args = ["export", "urdf", "--into", "ur5_robot.urdf", "--joint", "elbow_joint", "--k", "22", "--c", "0.5"]
    args += ["--axis", "theta", "-o", "ur5_flex.urdf"]
    code, out, err = run_inprocess([*args, "--package-path", f"example-robot-data={share}"], capsys)
    assert code == 0 and "checked in MuJoCo: elbow_joint damping 0.0005 (SI)" in out, err
    code, out, _ = run_inprocess(args, capsys)
    assert code == 0 and "--package-path example-robot-data=DIR" in out
    code, _, err = run_inprocess([*args, "--package-path", "example-robot-data"], capsys)
    assert code == 2 and "is not NAME=DIR" in err and "Traceback" not in err
