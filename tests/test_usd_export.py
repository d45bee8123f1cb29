"""`export usd`: the joint in OpenUSD, read back with usd-core and simulated in Newton.

Hosts nobody here wrote: Newton's cart-pole (shipped in the newton wheel) and pybullet_data's KUKA iiwa
URDF converted to USD by urdf2any (Isaac Lab's importer defaults), each run from the robot's folder
with relative paths. The comparisons here flatten both stages with usd-core and compare every
property spec (value, time samples, metadata), not the exporter's own check. Newton (CPU, warp's CPU
device, Featherstone solver) loads the written files and a static load must deflect the flexure by
F / k within 1 %.
"""

from __future__ import annotations

import hashlib
import math
import os
import re
from pathlib import Path

import numpy as np
import pytest
from clitools import run_inprocess
from robot_packages import linked_folder, package_dir

from designer.errors import DesignerError
from designer.export import robot
from designer.export.usd import export_usd
from designer.joint import Joint

pxr = pytest.importorskip("pxr", reason="usd-core is not installed")
from pxr import Gf, Sdf, Usd, UsdGeom, UsdPhysics  # noqa: E402

#: rig units; SI: theta k 0.05 N.m/rad, c 5e-4 N.m.s/rad, J 1e-5 kg.m^2; x k 800 N/m, c 2 N.s/m, m 0.01 kg
JOINT = Joint.from_coefficients(
    {"theta": {"k": 50.0, "c": 0.5, "m": 1e-5}, "x": {"k": 0.8, "c": 2e-3, "m": 0.01}}
)


def f32(v: float) -> float:
    return float(np.float32(v))


def drive(stage, path: str, instance: str) -> dict:
    prim = stage.GetPrimAtPath(path)
    d = UsdPhysics.DriveAPI.Get(prim, instance)
    return {
        "k": d.GetStiffnessAttr().Get(),
        "c": d.GetDampingAttr().Get(),
        "rest": d.GetTargetPositionAttr().Get(),
        "armature": prim.GetAttribute("physxJoint:armature").Get(),
        "axis": prim.GetAttribute("physics:axis").Get(),
    }


def test_standalone_holds_k_c_in_usd_units(tmp_path):
    """Angular drive per degree, linear in N/m; axis tokens as MJCF's axes; .usdc is binary."""
    for name in ("flex.usda", "flex.usdc"):
        out = export_usd(JOINT, tmp_path / name)
        stage = Usd.Stage.Open(str(out.path))
        theta = drive(stage, "/FlexJoint/FlexJoint_theta", "angular")
        assert theta == {
            "k": f32(0.05 * math.pi / 180),
            "c": f32(5e-4 * math.pi / 180),
            "rest": 0.0,
            "armature": 0.0,
            "axis": "Y",
        }
        x = drive(stage, "/FlexJoint/FlexJoint_x", "linear")
        assert x == {"k": 800.0, "c": 2.0, "rest": 0.0, "armature": 0.0, "axis": "X"}
        assert (
            UsdGeom.GetStageMetersPerUnit(stage) == 1.0 and UsdPhysics.GetStageKilogramsPerUnit(stage) == 1.0
        )
        link = UsdPhysics.MassAPI(stage.GetPrimAtPath("/FlexJoint/FlexJoint_x_link"))
        assert link.GetMassAttr().Get() == f32(0.01)
    assert (tmp_path / "flex.usdc").read_bytes().startswith(b"PXR-USDC")
    assert out.advice["FlexJoint_theta"].natural_frequency > 0


def test_standalone_series_motor_servo_and_flexure(tmp_path):
    out = export_usd(JOINT, tmp_path / "sea.usda", form="series", axis="theta")
    stage = Usd.Stage.Open(str(out.path))
    motor = drive(stage, "/FlexJoint/FlexJoint_motor", "angular")
    flex = drive(stage, "/FlexJoint/FlexJoint_theta", "angular")
    assert flex["k"] == f32(0.05 * math.pi / 180)
    servo = robot.series_drive(robot.with_masses(JOINT), "theta").servo
    assert motor["k"] == f32(servo.kp * math.pi / 180) and motor["c"] == f32(servo.kv * math.pi / 180)
    assert motor["armature"] == f32(servo.motor_inertia) and flex["armature"] == 0.0
    # the motor holds at its target under its servo: a load on the link deflects the flexure by F / k
    rest, k, q = newton_static(out.path, "FlexJoint_theta", 1e-3, 2.0)
    assert q - rest == pytest.approx(1e-3 / 0.05, rel=0.01)


def _centimetre_robot(folder: Path) -> Path:
    """A two-joint robot in centimetres (metersPerUnit 0.01), limits and a motor drive on the slider."""
    stage = Usd.Stage.CreateNew(str(folder / "cm_robot.usda"))
    UsdGeom.SetStageMetersPerUnit(stage, 0.01)
    UsdPhysics.SetStageKilogramsPerUnit(stage, 1.0)
    root = UsdGeom.Xform.Define(stage, "/robot").GetPrim()
    stage.SetDefaultPrim(root)
    for body in ("base", "carriage", "arm"):
        prim = UsdGeom.Xform.Define(stage, f"/robot/{body}").GetPrim()
        UsdPhysics.RigidBodyAPI.Apply(prim)
        m = UsdPhysics.MassAPI.Apply(prim)
        m.CreateMassAttr(2.0)
        m.CreateDiagonalInertiaAttr(Gf.Vec3f(100.0, 100.0, 100.0))  # kg.cm^2
    slide = UsdPhysics.PrismaticJoint.Define(stage, "/robot/slide")
    slide.CreateAxisAttr("X")
    slide.CreateBody0Rel().SetTargets(["/robot/base"])
    slide.CreateBody1Rel().SetTargets(["/robot/carriage"])
    slide.CreateLowerLimitAttr(-10.0)  # cm
    slide.CreateUpperLimitAttr(10.0)
    motor = UsdPhysics.DriveAPI.Apply(slide.GetPrim(), "linear")
    motor.CreateStiffnessAttr(1000.0)
    motor.CreateTargetPositionAttr(5.0)  # 5 cm
    hinge = UsdPhysics.RevoluteJoint.Define(stage, "/robot/hinge")
    hinge.CreateAxisAttr("Z")
    hinge.CreateBody0Rel().SetTargets(["/robot/carriage"])
    hinge.CreateBody1Rel().SetTargets(["/robot/arm"])
    stage.GetRootLayer().Save()
    return folder / "cm_robot.usda"


def test_into_centimetre_stage_converts_units(tmp_path, monkeypatch):
    """Prismatic: k per kg-unit (N/m here), rest in centimetres; revolute: per degree and per cm^2."""
    monkeypatch.chdir(tmp_path)
    host = _centimetre_robot(tmp_path)
    before = host.read_bytes()
    out = export_usd(
        JOINT, Path("cm_slide.usda"), into="cm_robot.usda", joint_name="slide", axis="x", rest=0.02
    )
    got = drive(Usd.Stage.Open(str(out.path)), "/robot/slide", "linear")
    assert got["k"] == 800.0 and got["c"] == 2.0
    assert got["rest"] == f32(2.0) and got["armature"] == f32(0.01)  # 0.02 m = 2 cm
    assert any(n.startswith("stiffness: 1000 -> 800 (SI)") for n in out.notes), out.notes
    out = export_usd(
        JOINT, Path("cm_hinge.usda"), into="cm_robot.usda", joint_name="/robot/hinge", axis="theta"
    )
    got = drive(Usd.Stage.Open(str(out.path)), "/robot/hinge", "angular")
    assert got["k"] == f32(0.05 * math.pi / 180 / 1e-4)  # N.m/deg in kg.cm^2/s^2 units
    assert got["armature"] == f32(1e-5 / 1e-4)
    # the arm (2 kg, 100 kg.cm^2 = 0.01 kg.m^2 about its centre, on the axis) and the armature
    assert out.advice["hinge"].inertia == pytest.approx(0.01 + 1e-5, rel=1e-6)
    assert host.read_bytes() == before
    with pytest.raises(DesignerError, match="outside the range"):
        export_usd(JOINT, Path("x.usda"), into="cm_robot.usda", joint_name="slide", axis="x", rest=0.2)


def _plain(info: dict) -> dict:
    """Spec info with list ops (targets, references, payloads) as their items: their repr is an address."""
    fields = (
        "explicitItems",
        "prependedItems",
        "appendedItems",
        "deletedItems",
        "orderedItems",
        "addedItems",
    )
    return {
        k: tuple(list(getattr(v, f)) for f in fields) if hasattr(v, "GetAddedOrExplicitItems") else v
        for k, v in info.items()
    }


def _flat_specs(stage) -> dict:
    """Every spec of the flattened stage, as text: path -> (default, time samples, info) for a property,
    (type, specifier, info) for a prim. Flatten writes instanced content as /Flattened_Prototype_N in an
    order of its own, so those are renamed in the order of their content."""
    layer = stage.Flatten()
    specs = {}

    def visit(path):
        spec = layer.GetObjectAtPath(path)
        if isinstance(spec, Sdf.PropertySpec):
            info = _plain(
                {k: spec.GetInfo(k) for k in spec.ListInfoKeys() if k not in ("default", "timeSamples")}
            )
            samples = {t: layer.QueryTimeSample(path, t) for t in layer.ListTimeSamplesForPath(path)}
            specs[str(path)] = repr((spec.default if hasattr(spec, "default") else None, samples, info))
        elif isinstance(spec, Sdf.PrimSpec):
            # Flatten documents the layer it came from; the joint's schemas are compared in drive()
            skip = {"apiSchemas", "documentation"} if path == Sdf.Path.absoluteRootPath else {"apiSchemas"}
            info = _plain({k: spec.GetInfo(k) for k in spec.ListInfoKeys() if k not in skip})
            specs[str(path)] = repr((spec.typeName, spec.specifier, info))

    layer.Traverse(Sdf.Path.absoluteRootPath, visit)
    prototypes = sorted({p.split("/")[1] for p in specs if p.startswith("/Flattened_Prototype_")})
    content = {
        n: repr(sorted((p[len(n) + 1 :], v) for p, v in specs.items() if p.startswith(f"/{n}")))
        for n in prototypes
    }
    names = {n: f"Prototype{i}" for i, n in enumerate(sorted(prototypes, key=content.get))}
    pattern = re.compile(r"Flattened_Prototype_\d+")
    return {
        pattern.sub(lambda m: names[m.group(0)], p): pattern.sub(lambda m: names[m.group(0)], v)
        for p, v in specs.items()
    }


def _unchanged_but(host_stage, flex_stage, joint_path: str, added: tuple[str, ...] = ()) -> set[str]:
    """The flattened property paths that differ between the two stages: must all be on the joint (or
    in the `added` prims, which the host must not have)."""
    a, b = _flat_specs(host_stage), _flat_specs(flex_stage)
    differ = {p for p in set(a) | set(b) if a.get(p) != b.get(p)}
    new = {p for p in differ if p in added or p.startswith(tuple(f"{n}." for n in added))}
    assert not any(p in a for p in new)
    differ -= new
    assert all(p.startswith(joint_path + ".") for p in differ), sorted(differ)[:10]
    for key in ("metersPerUnit", "kilogramsPerUnit", "upAxis"):
        assert host_stage.GetMetadata(key) == flex_stage.GetMetadata(key)
    assert host_stage.GetDefaultPrim().GetPath() == flex_stage.GetDefaultPrim().GetPath()
    return differ


#: per file given to `newton_static`, the armature Newton read on the joint (physxJoint:armature)
ARMATURES: dict[str, float] = {}


def newton_static(path: Path, joint: str, load: float, seconds: float) -> tuple[float, float, float]:
    """Newton's reading of `path` (PhysX attributes too) and its joint's coordinate after `seconds` of a
    constant generalised load (N or N.m), no gravity, 1 ms steps: (rest, k, coordinate). A robot joint
    without a drive is held by a servo added here (100 N.m/rad or N/m, damping 1), as the step advice
    holds the other joints: a free joint would trade momentum with the flexure for ever."""
    newton = pytest.importorskip("newton", reason="newton is not installed")
    pytest.importorskip("newton_usd_schemas", reason="newton-usd-schemas is not installed")
    import warp as wp

    wp.config.quiet = True
    builder = newton.ModelBuilder(gravity=(0.0, 0.0, 0.0))
    resolvers = [newton.usd.SchemaResolverNewton(), newton.usd.SchemaResolverPhysx()]
    builder.add_usd(str(path), schema_resolvers=resolvers)
    model = builder.finalize(device="cpu")
    j = [i for i, label in enumerate(model.joint_label) if label.rsplit("/", 1)[-1] == joint]
    assert len(j) == 1, list(model.joint_label)
    dof, q = int(model.joint_qd_start.numpy()[j[0]]), int(model.joint_q_start.numpy()[j[0]])
    ke, kd = model.joint_target_ke.numpy(), model.joint_target_kd.numpy()
    free = (ke == 0) & (np.arange(len(ke)) != dof)
    ke[free], kd[free] = 100.0, 1.0
    model.joint_target_ke.assign(ke)
    model.joint_target_kd.assign(kd)
    solver = newton.solvers.SolverFeatherstone(model)
    s0, s1, control = model.state(), model.state(), model.control()
    rest, k = float(control.joint_target_q.numpy()[dof]), float(model.joint_target_ke.numpy()[dof])
    ARMATURES[str(path)] = float(model.joint_armature.numpy()[dof])
    f = control.joint_f.numpy()
    f[dof] = load
    control.joint_f.assign(f)
    for _ in range(round(seconds / 1e-3)):
        s0.clear_forces()
        solver.step(s0, s1, control, None, 1e-3)
        s0, s1 = s1, s0
    return rest, k, float(s0.joint_q.numpy()[q])


def test_standalone_static_load_in_newton(tmp_path):
    out = export_usd(JOINT, tmp_path / "flex.usda")
    rest, k, q = newton_static(out.path, "FlexJoint_theta", 1e-3, 2.0)
    assert k == pytest.approx(0.05, rel=1e-6) and rest == 0.0
    assert q == pytest.approx(1e-3 / 0.05, rel=0.01)


def _sha(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


#: `export usd` into the cart-pole's rail: 800 N/m, 50 N.s/m (rig units)
CARTPOLE_ARGS = (
    "export",
    "usd",
    "--into",
    "cartpole.usda",
    "--joint",
    "railCartJoint",
    "--k",
    "0.8",
    "--c",
    "0.05",
)


def cartpole_here(tmp_path: Path, monkeypatch) -> Path:
    """Newton's cart-pole linked into a folder that becomes the current one; returns Newton's assets
    folder (pytest.skip without newton)."""
    assets = package_dir("newton", "examples/assets")
    if assets is None or not (assets / "cartpole.usda").is_file():
        pytest.skip("newton (its example assets) is not installed")
    folder = tmp_path / "assets"
    folder.mkdir()
    os.symlink(assets / "cartpole.usda", folder / "cartpole.usda")
    monkeypatch.chdir(folder)
    return assets


def test_into_newton_cartpole_from_its_folder(tmp_path, monkeypatch, capsys):
    """Newton's own cart-pole: the rail (prismatic, no drive) becomes the flexure, run as typed."""
    assets = cartpole_here(tmp_path, monkeypatch)
    host_hash = _sha(assets / "cartpole.usda")
    args = list(CARTPOLE_ARGS)
    code, out, err = run_inprocess([*args, "--m", "0.01", "--axis", "x", "-o", "cartpole_flex.usda"], capsys)
    assert code == 0, err
    assert "stiffness: none -> 800 (SI)" in out and "damping: none -> 50 (SI)" in out
    assert _sha(assets / "cartpole.usda") == host_hash
    assert Sdf.Layer.FindOrOpen("cartpole_flex.usda").subLayerPaths == ["cartpole.usda"]
    host, flex = Usd.Stage.Open("cartpole.usda"), Usd.Stage.Open("cartpole_flex.usda")
    differ = _unchanged_but(host, flex, "/cartPole/railCartJoint")
    assert "/cartPole/railCartJoint.drive:linear:physics:stiffness" in differ
    got = drive(flex, "/cartPole/railCartJoint", "linear")
    assert (got["k"], got["c"], got["rest"], got["armature"]) == (800.0, 50.0, 0.0, f32(0.01))
    # cart 1 kg and two 0.25 kg poles ride on the rail: 1.51 kg with the armature, zeta 0.74
    rest, k, q = newton_static(Path("cartpole_flex.usda"), "railCartJoint", 8.0, 5.0)
    assert k == 800.0 and q - rest == pytest.approx(8.0 / 800.0, rel=0.01)
    assert ARMATURES["cartpole_flex.usda"] == pytest.approx(0.01, rel=1e-7)


@pytest.fixture(scope="module")
def iiwa_usd(tmp_path_factory) -> Path:
    """pybullet_data's KUKA iiwa URDF converted by urdf2any (Isaac Lab's defaults, fixed base)."""
    pybullet_data = pytest.importorskip("pybullet_data")
    converter = pytest.importorskip("urdf2any.cli", reason="urdf2any is not installed")
    folder = linked_folder(
        Path(pybullet_data.getDataPath()) / "kuka_iiwa", tmp_path_factory.mktemp("r") / "iiwa"
    )
    assert converter.main(
        [str(folder / "model.urdf"), "-o", str(folder / "iiwa.usda"), "--preset", "isaaclab", "--fix-base"]
    ) in (0, None)
    return folder / "iiwa.usda"


def test_into_iiwa_converted_from_urdf(iiwa_usd, monkeypatch, capsys):
    """A motor's PD drive on joint 4 becomes the flexure; every other value as converted; Newton."""
    monkeypatch.chdir(iiwa_usd.parent)
    host_hash = _sha(iiwa_usd)
    # 50 N.m/rad, 10 N.m.s/rad; the host servos (100 N.m/rad, 1 N.m.s/rad) on the other joints ring for
    # seconds: 19.67e-3 rad at 3 s, 20.17e-3 at 6 s, 19.98e-3 at 10 s
    args = ["export", "usd", "--into", "iiwa.usda", "--joint", "lbr_iiwa_joint_4", "--k", "5e4", "--c", "1e4"]
    code, out, err = run_inprocess([*args, "--m", "1e-5", "--axis", "theta", "-o", "iiwa_flex.usda"], capsys)
    assert code == 0, err
    text = " ".join(out.split())
    assert "stiffness: 100 -> 50 (SI)" in text and "damping: 1 -> 10 (SI)" in text
    assert "maxForce kept at the host's 300 N.m" in text
    assert _sha(iiwa_usd) == host_hash
    host, flex = Usd.Stage.Open("iiwa.usda"), Usd.Stage.Open("iiwa_flex.usda")
    path = "/lbr_iiwa/joints/lbr_iiwa_joint_4"
    _unchanged_but(host, flex, path)
    got = drive(flex, path, "angular")
    assert got["k"] == f32(50 * math.pi / 180) and got["c"] == f32(10 * math.pi / 180)
    assert got["rest"] == 0.0 and got["armature"] == f32(1e-5) and got["axis"] == "Z"
    rest, k, q = newton_static(Path("iiwa_flex.usda"), "lbr_iiwa_joint_4", 1.0, 10.0)
    assert k == pytest.approx(50.0, rel=1e-6)
    assert q - rest == pytest.approx(1.0 / 50.0, rel=0.01)


def test_refusals_name_the_problem(iiwa_usd, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(iiwa_usd.parent)
    base = ["export", "usd", "--k", "5e4", "--c", "1e4", "--axis", "theta", "-o", str(tmp_path / "x.usda")]
    cases = {
        ("--into", "iiwa.usda", "--joint", "nope"): "is not a revolute or prismatic joint",
        ("--into", "model.urdf", "--joint", "lbr_iiwa_joint_4"): "is not a USD file",
        (
            "--into",
            "iiwa.usda",
            "--joint",
            "lbr_iiwa_joint_4",
            "--form",
            "series",
        ): "has no mass on axis theta",
        ("--into", "iiwa.usda", "--joint", "lbr_iiwa_joint_4", "--rest", "3"): "outside the range",
    }
    for extra, message in cases.items():
        code, out, err = run_inprocess([*base, *extra], capsys)
        assert code == 2 and message in " ".join(err.split()), err
        assert "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    assert not (tmp_path / "x.usda").exists()


def test_series_into_newton_cartpole(tmp_path, monkeypatch, capsys):
    """motor -> flexure -> cart on the rail: a servo added (the rail has no drive), the load on the cart
    deflects the flexure by F / k, every host value as it was but the flexure joint's."""
    cartpole_here(tmp_path, monkeypatch)
    args = list(CARTPOLE_ARGS)
    # Newton's Featherstone applies a drive's damping explicitly: at 1 ms the default motor (armature
    # 0.1 kg, servo damping 746 N.s/m on the 0.11 kg rotor: 6.8 x dt / m) diverged to NaN; a 1 kg motor holds
    args += ["--m", "0.01", "--axis", "x", "--form", "series", "--motor-inertia", "1", "-o", "sea.usda"]
    code, out, err = run_inprocess(args, capsys)
    assert code == 0, err
    assert "a servo at" in out and "the robot joint had no drive" in " ".join(out.split())
    host, flex = Usd.Stage.Open("cartpole.usda"), Usd.Stage.Open("sea.usda")
    motor, rotor = "/cartPole/railCartJoint_motor", "/cartPole/railCartJoint_motor_rotor"
    _unchanged_but(host, flex, "/cartPole/railCartJoint", (motor, rotor))
    joint = flex.GetPrimAtPath("/cartPole/railCartJoint")
    assert joint.GetRelationship("physics:body0").GetTargets() == [rotor]
    assert joint.GetAttribute("physics:upperLimit").Get() == math.inf
    m = flex.GetPrimAtPath(motor)
    assert m.GetAttribute("physics:upperLimit").Get() == 4.0 and m.GetAttribute("physics:axis").Get() == "Y"
    assert drive(flex, "/cartPole/railCartJoint", "linear")["k"] == 800.0
    rest, k, q = newton_static(Path("sea.usda"), "railCartJoint", 8.0, 5.0)
    assert k == 800.0 and q - rest == pytest.approx(8.0 / 800.0, rel=0.01)


def test_series_into_iiwa_keeps_the_motor_drive(iiwa_usd, tmp_path):
    """The converted PD drive (100 N.m/rad, 300 N.m) and the limits move to the motor joint."""
    out = export_usd(
        JOINT,
        iiwa_usd.parent / "sea.usda",
        into=iiwa_usd,
        joint_name="lbr_iiwa_joint_4",
        axis="theta",
        form="series",
    )
    stage = Usd.Stage.Open(str(out.path))
    path = "/lbr_iiwa/joints/lbr_iiwa_joint_4"
    _unchanged_but(
        Usd.Stage.Open(str(iiwa_usd)),
        stage,
        path,
        (path + "_motor", "/lbr_iiwa/lbr_iiwa_joint_4_motor_rotor"),
    )
    motor = drive(stage, path + "_motor", "angular")
    assert motor["k"] == f32(100 * math.pi / 180) and motor["armature"] == f32(1e-4)  # 10 x the flexure's
    m = stage.GetPrimAtPath(path + "_motor")
    assert m.GetAttribute("drive:angular:physics:maxForce").Get() == 300.0
    assert (m.GetAttribute("physics:lowerLimit").Get(), m.GetAttribute("physics:upperLimit").Get()) == (
        -120,
        120,
    )
    assert drive(stage, path, "angular")["k"] == f32(0.05 * math.pi / 180)
    assert "lbr_iiwa_joint_4_motor" in out.advice and "lbr_iiwa_joint_4" in out.advice


def test_layer_written_elsewhere_points_back_relatively(tmp_path, monkeypatch):
    """-o in another folder: the sublayer is the robot's path from there; moved together, it still opens."""
    robot_dir = tmp_path / "robot"
    robot_dir.mkdir()
    _centimetre_robot(robot_dir)
    (tmp_path / "out").mkdir()
    monkeypatch.chdir(robot_dir)
    out = export_usd(JOINT, Path("../out/flex.usda"), into="cm_robot.usda", joint_name="slide", axis="x")
    assert Sdf.Layer.FindOrOpen(str(out.path)).subLayerPaths == ["../robot/cm_robot.usda"]
    moved = tmp_path / "moved"
    moved.mkdir()
    os.rename(robot_dir, moved / "robot")
    os.rename(tmp_path / "out", moved / "out")
    stage = Usd.Stage.Open(str(moved / "out" / "flex.usda"))
    assert drive(stage, "/robot/slide", "linear")["k"] == 800.0
    assert stage.GetPrimAtPath("/robot/arm").IsValid() and UsdGeom.GetStageMetersPerUnit(stage) == 0.01


def _newton_asset_joints() -> list[tuple[str, str]]:
    """(asset file, joint path) for every revolute and prismatic joint of Newton's example assets."""
    assets = package_dir("newton", "examples/assets")
    if assets is None:
        return []
    out = []
    for f in sorted(assets.glob("*.usd*")):
        stage = Usd.Stage.Open(str(f))
        out += [
            (f.name, str(p.GetPath()))
            for p in stage.Traverse()
            if p.IsA(UsdPhysics.RevoluteJoint) or p.IsA(UsdPhysics.PrismaticJoint)
        ]
    return out


@pytest.mark.parametrize("form", ["parallel", "series"])
def test_every_joint_of_newtons_assets(tmp_path, form):
    """Each export into each joint of every asset Newton ships runs, or (series, a joint with no drive
    whose bodies state no mass to size a servo for) is refused with that reason; the layered stage
    differs from the robot only in that joint (and the motor's new prims)."""
    cases = _newton_asset_joints()
    if not cases:
        pytest.skip("newton (its example assets) is not installed")
    assets = package_dir("newton", "examples/assets")
    ran = refused = 0
    for i, (name, joint) in enumerate(cases):
        host = Usd.Stage.Open(str(assets / name))
        rot = host.GetPrimAtPath(joint).IsA(UsdPhysics.RevoluteJoint)
        out = tmp_path / f"flex{i}.usda"  # usd-core keeps an opened layer by its path while it is in use
        try:
            export_usd(
                JOINT, out, into=assets / name, joint_name=joint, axis="theta" if rot else "x", form=form
            )
        except DesignerError as exc:
            assert form == "series" and "has no drive to be the motor" in str(exc), (name, joint, exc)
            refused += 1
            continue
        ran += 1
        flex = Usd.Stage.Open(str(out))
        added = (
            f"{joint}_motor",
            f"{flex.GetPrimAtPath(joint).GetRelationship('physics:body0').GetTargets()[0]}",
        )
        _unchanged_but(host, flex, joint, added if form == "series" else ())
        got = drive(flex, joint, "angular" if rot else "linear")
        assert got["k"] == (f32(0.05 * math.pi / 180) if rot else 800.0), (name, joint)
    # 23 joints in 6 assets: all run in parallel; in series 6 joints without a drive are refused
    assert ran + refused == len(cases) >= 23 and refused <= (6 if form == "series" else 0), (ran, refused)


def test_the_exporters_check_sees_any_other_change(tmp_path):
    """usd_layer.stage_changes, the check every export runs before its file replaces the output, reports
    an attribute, a relationship and a prim changed outside the joint, and stage metadata."""
    from designer.export.usd_layer import over_layer, stage_changes

    host_path = _centimetre_robot(tmp_path)
    host = Usd.Stage.Open(str(host_path))
    layer, stage = over_layer(host, host_path, ".usda")
    stage.GetPrimAtPath("/robot/arm").GetAttribute("physics:mass").Set(3.0)
    stage.GetPrimAtPath("/robot/hinge").GetRelationship("physics:body1").SetTargets(["/robot/base"])
    stage.DefinePrim("/robot/extra")
    assert stage_changes(host, stage, {Sdf.Path("/robot/slide"): set()}) == ["prims: /robot/extra"]
    stage.RemovePrim("/robot/extra")
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    changes = stage_changes(host, stage, {Sdf.Path("/robot/slide"): set()})
    assert changes == [
        "stage metadata metersPerUnit",
        "/robot/arm: physics:mass",
        "/robot/hinge: physics:body1",
    ]
