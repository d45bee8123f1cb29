"""Export a Joint as OpenUSD (UsdPhysics): standalone, or as a layer over the user's robot.

The flexure is a joint's drive (`UsdPhysics.DriveAPI`, instance "angular" on a revolute joint,
"linear" on a prismatic one): stiffness k and damping c about targetPosition, the rest. A drive is
what Isaac Sim (PhysX) and Newton read as the joint's spring-damper; UsdPhysics has no passive joint
spring. Angular drives are per degree (stiffness N.m/deg, damping N.m.s/deg, target in degrees),
linear ones in the stage's units (see `units.usd_factor`); drive values are 32-bit floats, so they hold
k and c to about 6e-8 relative.

The flexure's moving inertia and its friction (none) go into the PhysX joint attributes
`physxJoint:armature` and `physxJoint:jointFriction` (PhysxJointAPI). usd-core has no PhysxSchema
module, so they are authored by their schema names, as PhysX's own converters write them: Isaac Sim
reads them, Newton reads the armature when given its PhysX schema resolver, other readers ignore them.

Written and read with usd-core (`pxr`), no USDA text by hand. Into a robot: `usd_host` (parallel),
`usd_series`, `usd_layer` (the layer over the robot and its check).
"""

from __future__ import annotations

import json
from pathlib import Path

from .. import units
from ..errors import DesignerError, path_argument
from ..files import atomic_path, check_suffix
from ..joint import Joint, check_joint
from . import robot
from .usd_drive import ARMATURE, FRICTION, set_drive
from .usd_host import into_parallel
from .usd_series import into_series

SUFFIXES = (".usda", ".usd", ".usdc")
FORMS = ("parallel", "series")
#: the UsdPhysics joint axis token of each channel (as `robot.AXIS_VECTORS`: phi x, theta y, psi z)
AXIS_TOKENS = {"x": "X", "y": "Y", "z": "Z", "phi": "X", "theta": "Y", "psi": "Z"}
#: who reads which value of the exported joint
READERS = (
    "the drive (stiffness, damping, targetPosition) is read by Isaac Sim / PhysX and Newton; "
    f"{ARMATURE} and {FRICTION} by Isaac Sim (Newton reads the armature with its PhysX schema resolver, "
    "newton.usd.SchemaResolverPhysx); they are authored by name with PhysxJointAPI applied by name, as "
    "usd-core has no PhysxSchema module",
)


def _body(stage, path: str, s: robot.Sphere):
    """A rigid body at the stage origin with the sphere's mass and inertia stated (MassAPI)."""
    from pxr import Gf, UsdGeom, UsdPhysics

    prim = UsdGeom.Xform.Define(stage, path).GetPrim()
    UsdPhysics.RigidBodyAPI.Apply(prim)
    mass = UsdPhysics.MassAPI.Apply(prim)
    mass.CreateMassAttr(s.mass)
    mass.CreateDiagonalInertiaAttr(Gf.Vec3f(s.inertia, s.inertia, s.inertia))
    mass.CreateCenterOfMassAttr(Gf.Vec3f(0, 0, 0))
    prim.SetDocumentation(s.basis)
    return prim


def _joint(stage, path: str, a: str, body0: str, body1: str, note: str):
    """A revolute or prismatic joint on axis `a` between two bodies whose frames coincide."""
    from pxr import UsdPhysics

    kind = UsdPhysics.RevoluteJoint if units.is_rotational(a) else UsdPhysics.PrismaticJoint
    joint = kind.Define(stage, path)
    joint.CreateAxisAttr(AXIS_TOKENS[a])
    joint.CreateBody0Rel().SetTargets([body0])
    joint.CreateBody1Rel().SetTargets([body1])
    joint.GetPrim().SetDocumentation(note)
    return joint.GetPrim()


def _stage(joint: Joint, notes: list[str]):
    """An in-memory stage in SI (1 m, 1 kg per unit, z up) with the articulation root `/<name>`, its
    base body (the flexure's clamped part) fixed to the world; returns the layer, stage and base."""
    from pxr import Sdf, Usd, UsdGeom, UsdPhysics

    layer = Sdf.Layer.CreateAnonymous(".usda")
    stage = Usd.Stage.Open(layer)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    UsdPhysics.SetStageKilogramsPerUnit(stage, 1.0)
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    root = UsdGeom.Xform.Define(stage, f"/{joint.name}").GetPrim()
    stage.SetDefaultPrim(root)
    UsdPhysics.ArticulationRootAPI.Apply(root)
    text = json.dumps(joint.to_dict(), sort_keys=True, default=str)
    layer.documentation = "\n".join([f"flexjoint designer: {text}", *notes])
    return layer, stage, f"/{joint.name}"


def parallel_stage(joint: Joint):
    """The joint as a chain: a base fixed to the world, then per axis a link on a revolute or prismatic
    joint whose drive is the axis' spring-damper (rest 0). Returns (layer, advice).

    The joint must carry masses (see `robot.with_masses`).
    """
    from pxr import UsdPhysics

    bodies, advice = robot.chain(joint)
    layer, stage, root = _stage(joint, ["each joint's drive is the flexure's spring-damper, rest 0"])
    base = f"{root}/{joint.name}_base"
    _body(stage, base, bodies[next(iter(joint.axes))])
    UsdPhysics.FixedJoint.Define(stage, f"{root}/{joint.name}_fixed").CreateBody1Rel().SetTargets([base])
    parent = base
    for a, ac in joint.axes.items():
        si, name = ac.si(), f"{joint.name}_{a}"
        link = f"{root}/{name}_link"
        _body(stage, link, bodies[a])
        prim = _joint(stage, f"{root}/{name}", a, parent, link, advice[name].text())
        rot = units.is_rotational(a)
        set_drive(prim, rot, {"k": si["k"], "c": si["c"], "r": 0.0, "m": 0.0, "friction": 0.0}, (1.0, 1.0))
        parent = link
    return layer, advice


def series_stage(joint: Joint, a: str, *, motor_inertia: float | None, motor_bandwidth: float | None):
    """Motor -> flexure -> link on axis `a` (see `robot.series_drive`): the motor joint's drive is its
    critically damped position servo (stiffness kp, damping kv, targetPosition the motor's command),
    its armature the motor's reflected inertia; the flexure joint's drive the flexure.
    Returns (layer, advice)."""
    from pxr import UsdPhysics

    series = robot.series_drive(joint, a, motor_inertia=motor_inertia, motor_bandwidth=motor_bandwidth)
    servo, n, rot = series.servo, joint.name, units.is_rotational(a)
    layer, stage, root = _stage(
        joint,
        [
            f"series elastic: motor -> flexure -> link; the targetPosition of {n}_motor's drive is the "
            f"motor's command ({units.usd_unit('r', rot)})",
            f"servo at {servo.bandwidth:.4g} Hz, critically damped: kp = {servo.kp:.4g}, "
            f"kv = {servo.kv:.4g} (SI)",
        ],
    )
    base, rotor, link = f"{root}/{n}_base", f"{root}/{n}_motor_rotor", f"{root}/{n}_{a}_link"
    _body(stage, base, series.link)
    UsdPhysics.FixedJoint.Define(stage, f"{root}/{n}_fixed").CreateBody1Rel().SetTargets([base])
    _body(stage, rotor, series.link)
    _body(stage, link, series.link)
    motor = _joint(stage, f"{root}/{n}_motor", a, base, rotor, series.advice[f"{n}_motor"].text())
    set_drive(
        motor,
        rot,
        {"k": servo.kp, "c": servo.kv, "r": 0.0, "m": servo.motor_inertia, "friction": 0.0},
        (1.0, 1.0),
    )
    flex = _joint(stage, f"{root}/{n}_{a}", a, rotor, link, series.advice[f"{n}_{a}"].text())
    si = joint.axes[a].si()
    set_drive(flex, rot, {"k": si["k"], "c": si["c"], "r": 0.0, "m": 0.0, "friction": 0.0}, (1.0, 1.0))
    return layer, series.advice


def export_usd(
    joint: Joint,
    path: str | Path,
    *,
    into: str | Path | None = None,
    joint_name: str | None = None,
    axis: str | None = None,
    form: str = "parallel",
    rest: float | None = None,
    motor_inertia: float | None = None,
    motor_bandwidth: float | None = None,
    allow_outside_range: bool = False,
) -> robot.RobotExport:
    """Write `joint` as OpenUSD at `path` (.usda text, .usd or .usdc binary) and return the path, the
    stated step advice and notes.

    Standalone (`into` None): form "parallel" is a chain of links, one per axis, each on a joint whose
    drive is the spring-damper; "series" is motor -> flexure -> link on one axis (see `series_stage`).
    With `into` (a USD robot) and `joint_name` (the joint prim's name or path): a layer that has the
    robot as its sublayer (by its path relative to `path`'s folder); in parallel it changes only that
    revolute or prismatic joint's drive and PhysX attributes (see `usd_host.into_parallel`), in series
    it inserts a motor joint and rotor before it (see `usd_series.into_series`); the robot's file is
    not written. `rest` (rad or m): in parallel None keeps the host's drive target when inside the
    joint's limits; in series it is the flexure's (default 0).

    Raises:
        DesignerError: a wrong suffix, unknown form, missing mass, a rest on a standalone joint, or an
            `into` problem.
    """
    path = check_suffix(path, SUFFIXES, what="a USD")
    check_joint(joint)
    if form not in FORMS:
        raise DesignerError(f"form={form!r} is not a form", f"use one of: {', '.join(FORMS)}")
    if into is not None:
        joint_name = robot.robot_joint_name(joint_name)
        into = path_argument(into, "into", what="a USD robot")
        if form == "series":
            advice, notes = into_series(
                joint,
                into,
                path,
                joint_name=joint_name,
                axis=axis,
                rest=0.0 if rest is None else rest,
                motor_inertia=motor_inertia,
                motor_bandwidth=motor_bandwidth,
            )
        else:
            advice, notes = into_parallel(
                joint,
                into,
                path,
                joint_name=joint_name,
                axis=axis,
                rest=rest,
                allow_outside_range=allow_outside_range,
            )
        return robot.RobotExport(path, advice, notes + READERS)
    if rest not in (None, 0.0):
        raise DesignerError(
            f"rest={rest:g} is for exports into a robot (into=...)",
            "leave rest at 0 (the drive's targetPosition), or export into the robot",
        )
    joint = robot.with_masses(joint)
    if form == "series":
        layer, advice = series_stage(
            joint, robot.pick_axis(joint, axis), motor_inertia=motor_inertia, motor_bandwidth=motor_bandwidth
        )
    else:
        layer, advice = parallel_stage(joint)
    with atomic_path(path) as tmp:
        if not layer.Export(str(tmp)):
            raise RuntimeError(f"usd-core could not write {tmp}")
    return robot.RobotExport(path, advice, READERS)
