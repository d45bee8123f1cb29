"""Make one joint of the user's USD robot a series-elastic joint, as a layer over the robot:
motor -> flexure -> link, a motor rotor body inserted between the joint's two bodies.

As in MJCF (`mjcf_series`), the robot joint keeps its name and becomes the flexure (its drive the
flexure's k, c and rest, its armature the flexure's moving inertia, unlimited, no friction), now
between the rotor and the joint's body1 (its body1 frame as the robot gives it); a new joint
`<joint>_motor` of the same kind and axis carries what acts in the real drive: the robot joint's
body0 frame, limits, drive (the motor's gains, target and maxForce) and friction, with armature
`motor_inertia` (default the robot joint's armature, else 10 x the flexure's moving inertia). With no
drive on the robot joint, a critically damped position servo is added (see `robot.Servo`). The rotor
(the flexure's clamped part, as in MJCF) sits where the joint frame is on body0 at the robot's
authored pose, beside body1 in the prim tree. Every other prim and value is checked unchanged.
"""

from __future__ import annotations

import math
from pathlib import Path

from .. import units
from ..errors import DesignerError
from ..joint import Joint
from . import robot
from .stability import StepAdvice, step_advice
from .usd_drive import ARMATURE, FRICTION, drive_instance, set_drive
from .usd_host import INERTIA_BASIS, UsdHost, check_drive, host_axis, host_values, open_host
from .usd_inertia import moved_inertia
from .usd_layer import over_layer, stage_changes, write_over

#: the joint-frame attributes of a UsdPhysics joint on each side
FRAME0 = ("physics:localPos0", "physics:localRot0")
FRAME1 = ("physics:localPos1", "physics:localRot1")


def _rotor(stage, host: UsdHost, path, clamp: robot.Sphere) -> None:
    """The rotor body at `path`: placed at the joint frame on body0's side, the clamped part's mass."""
    from pxr import Gf, Usd, UsdGeom, UsdPhysics

    joint = UsdPhysics.Joint(host.joint)
    body0 = joint.GetBody0Rel().GetTargets()
    rot = joint.GetLocalRot0Attr().Get()
    frame = Gf.Matrix4d().SetTransform(
        Gf.Rotation(Gf.Quatd(rot.GetReal(), Gf.Vec3d(rot.GetImaginary()))),
        Gf.Vec3d(joint.GetLocalPos0Attr().Get()),
    )
    at = Usd.TimeCode.Default()
    if body0:
        frame = frame * UsdGeom.Xformable(host.stage.GetPrimAtPath(body0[0])).ComputeLocalToWorldTransform(at)
    parent = host.stage.GetPrimAtPath(path.GetParentPath())
    if parent.IsA(UsdGeom.Xformable):
        frame = frame * UsdGeom.Xformable(parent).ComputeLocalToWorldTransform(at).GetInverse()
    prim = UsdGeom.Xform.Define(stage, path)
    prim.MakeMatrixXform().Set(frame)
    UsdPhysics.RigidBodyAPI.Apply(prim.GetPrim())
    mass = UsdPhysics.MassAPI.Apply(prim.GetPrim())
    meters, kilograms = host.units
    mass.CreateMassAttr(clamp.mass / kilograms)
    i = clamp.inertia / (kilograms * meters**2)
    mass.CreateDiagonalInertiaAttr(Gf.Vec3f(i, i, i))
    mass.CreateCenterOfMassAttr(Gf.Vec3f(0, 0, 0))
    prim.GetPrim().SetDocumentation("the motor's rotor carrying the flexure's clamped part: " + clamp.basis)


def _motor_joint(stage, host: UsdHost, path, rotor, drive: dict[str, float], kind: str | None) -> None:
    """The motor joint: the robot joint's kind, axis, body0 frame and limits, body1 the rotor, and the
    `drive` values (SI; the drive's type `kind` when the robot gives one)."""
    src = host.joint
    prim = stage.DefinePrim(path, src.GetTypeName())
    for name in ("physics:axis", "physics:lowerLimit", "physics:upperLimit", *FRAME0):
        attr = src.GetAttribute(name)
        if attr.HasAuthoredValue():
            prim.CreateAttribute(name, attr.GetTypeName(), custom=False).Set(attr.Get())
    body0 = src.GetRelationship("physics:body0").GetTargets()
    prim.CreateRelationship("physics:body0", custom=False).SetTargets(body0)
    prim.CreateRelationship("physics:body1", custom=False).SetTargets([rotor])
    set_drive(prim, host.rotational, drive, host.units)
    if kind is not None:
        prim.GetAttribute(f"drive:{drive_instance(host.rotational)}:physics:type").Set(kind)


def _motor_drive(
    h: UsdHost,
    old: dict,
    si: dict,
    link: float,
    rotor: float,
    missing: str | None,
    motor_inertia: float | None,
    motor_bandwidth: float | None,
) -> tuple[dict[str, float], robot.Servo | None]:
    """The motor joint's drive values (SI): the robot joint's drive, or, when it has none, a servo for
    the `link` (what the flexure moves) and the `rotor`; armature `motor_inertia`, else the robot's,
    else 10 x the flexure's moving inertia."""
    name = h.joint.GetName()
    armature = motor_inertia if motor_inertia is not None else (old["m"] or 10 * si["m"])
    servo = None
    if old["k"] is None:
        if missing:
            raise DesignerError(
                f"robot joint '{name}' has no drive to be the motor, and body {missing} states no mass to "
                "size a servo for",
                "give the joint a drive (the motor's gains) in the robot, or state the bodies' masses",
            )
        flex = step_advice(si["k"], si["c"], link)
        servo = robot.Servo.for_flexure(
            flex, carried=link + rotor, motor_inertia=armature, bandwidth=motor_bandwidth
        )
        drive = {"k": servo.kp, "c": servo.kv, "r": 0.0}
    else:
        drive = {q: old[q] for q in ("k", "c", "r", "F") if old[q] is not None}
    drive["m"] = armature
    if old["friction"]:
        drive["friction"] = old["friction"]
    return drive, servo


def into_series(
    joint: Joint,
    host: Path,
    path: Path,
    *,
    joint_name: str,
    axis: str | None = None,
    rest: float = 0.0,
    motor_inertia: float | None = None,
    motor_bandwidth: float | None = None,
) -> tuple[dict[str, StepAdvice], tuple[str, ...]]:
    """Write at `path` a layer over USD robot `host` with motor -> flexure -> link at joint `joint_name`
    (see the module's description). Returns the step advice of the flexure (motor held) and of the
    motor (flexure held), inertias from the bodies' MassAPI, and one note per robot value moved.

    Raises:
        DesignerError: as `into_parallel`; the names `<joint>_motor` or `<joint>_motor_rotor` taken; a
            joint without body1; bodies that state no mass when a servo must be sized for them.
    """
    from pxr import Gf, UsdPhysics

    h = open_host(host, joint_name)
    a = host_axis(joint, axis, h, joint_name)
    name, rot = h.joint.GetName(), h.rotational
    body1 = UsdPhysics.Joint(h.joint).GetBody1Rel().GetTargets()
    if not body1:
        raise DesignerError(f"robot joint '{name}' has no body1", "give a joint that moves a body")
    motor_path = h.joint.GetPath().GetParentPath().AppendChild(f"{name}_motor")
    rotor_path = body1[0].GetParentPath().AppendChild(f"{name}_motor_rotor")
    for p in (motor_path, rotor_path):
        if h.stage.GetPrimAtPath(p):
            raise DesignerError(f"the robot already has a prim {p}", "rename it first")
    full = robot.with_masses(joint)
    si, clamp = full.axes[a].si(), robot.links(full)[a]
    old = host_values(h)
    moved, missing = moved_inertia(h.stage, h.joint, rot)
    link = moved + si["m"]
    rotor = clamp.inertia if rot else clamp.mass
    drive, servo = _motor_drive(h, old, si, link, rotor, missing, motor_inertia, motor_bandwidth)
    layer, stage = over_layer(h.stage, h.path, path.suffix)
    _rotor(stage, h, rotor_path, clamp)
    _motor_joint(stage, h, motor_path, rotor_path, drive, old["type"])
    flex = stage.GetPrimAtPath(h.joint.GetPath())
    flex.GetRelationship("physics:body0").SetTargets([rotor_path])
    flex.GetAttribute(FRAME0[0]).Set(Gf.Vec3f(0, 0, 0))
    flex.GetAttribute(FRAME0[1]).Set(Gf.Quatf(1, 0, 0, 0))
    flex.GetAttribute("physics:lowerLimit").Set(-math.inf)
    flex.GetAttribute("physics:upperLimit").Set(math.inf)
    values = {"k": si["k"], "c": si["c"], "r": rest, "F": math.inf, "m": si["m"], "friction": 0.0}
    set_drive(flex, rot, values, h.units)
    flex.GetAttribute(f"drive:{drive_instance(rot)}:physics:type").Set("force")
    del stage, flex
    edited = {h.joint.GetPath(): {*layer.GetPrimAtPath(h.joint.GetPath()).properties.keys()}}

    def check(after) -> None:
        changes = stage_changes(h.stage, after, edited, frozenset({motor_path, rotor_path}))
        if changes:
            raise RuntimeError(f"the series layer changes more than the joint: {'; '.join(changes)}")
        check_drive(after.GetPrimAtPath(h.joint.GetPath()), rot, h.units, values)
        check_drive(after.GetPrimAtPath(motor_path), rot, h.units, drive)

    write_over(layer, h.path, path, check)
    return _advice(h, name, si, link, drive, clamp, missing), _notes(h, name, old, drive, servo, rest)


def _advice(
    h: UsdHost, name: str, si: dict, link: float, motor: dict, clamp: robot.Sphere, missing: str | None
) -> dict[str, StepAdvice]:
    """The flexure's advice (the link, motor held) and the motor's (flexure held), when masses are known."""
    if missing:
        return {}
    advice = {name: step_advice(si["k"], si["c"], link, basis=INERTIA_BASIS + ", the motor held")}
    if motor.get("k"):
        carried = link + motor["m"] + (clamp.inertia if h.rotational else clamp.mass)
        advice[f"{name}_motor"] = step_advice(
            motor["k"], motor.get("c", 0.0), carried, basis=INERTIA_BASIS + ", the rotor's, the flexure held"
        )
    return advice


def _notes(
    h: UsdHost, name: str, old: dict, motor: dict, servo: robot.Servo | None, rest: float
) -> tuple[str, ...]:
    """Where each robot value went (SI)."""
    unit = "rad" if h.rotational else "m"
    notes = [
        f"series elastic: {name}_motor (the robot joint's body0 frame, limits and drive) -> rotor "
        f"{name}_motor_rotor -> {name} (the flexure, unlimited, rest {rest:.4g} {unit}) -> its body1",
        f"{name}_motor armature {motor['m']:.4g} (the motor's reflected inertia; {ARMATURE} on the robot "
        f"joint was {0 if old['m'] is None else old['m']:.4g})",
    ]
    if servo is None:
        k, c = motor.get("k", 0.0), motor.get("c", 0.0)
        notes.append(f"{name}_motor drive: the robot joint's, stiffness {k:.4g}, damping {c:.4g} (SI)")
    else:
        notes.append(
            f"{name}_motor drive: a servo at {servo.bandwidth:.4g} Hz, critically damped, "
            f"kp = {servo.kp:.4g}, kv = {servo.kv:.4g} (SI): the robot joint had no drive"
        )
    if "friction" in motor:
        notes.append(f"{FRICTION} {motor['friction']:.4g} moved to {name}_motor (the flexure has none)")
    return (
        *notes,
        f"targetPosition of {name}_motor's drive: the motor's command ({units.usd_unit('r', h.rotational)})",
    )
