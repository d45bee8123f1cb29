"""Make one joint of the user's MJCF robot a series-elastic joint: motor -> flexure -> link, a motor body
inserted before the joint's body. The file is restructured with lxml (same content; quoting and
whitespace inside tags normalised), compiled by MuJoCo from beside the output and checked against the
host's own compiled model before it replaces the output: every host body keeps its world pose at the
reference configuration and every other joint its numbers.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass
from functools import partial
from pathlib import Path

import numpy as np

from ..errors import DesignerError
from ..joint import Joint
from . import robot
from .mjcf_derived import dampratio_gains, freeze_springdampers, gains_into_tree, gains_note
from .mjcf_host import (
    MASS_MATRIX_BASIS,
    Host,
    check_joint,
    host_axis,
    mass_diagonal,
    open_host,
    springdamper_off,
    write_checked,
)
from .stability import StepAdvice, step_advice

#: body attributes that place a body in its parent's frame
_FRAME = ("pos", "quat", "euler", "axisangle", "xyaxes", "zaxis")


def _flexure(host: Host, joint: Joint, a: str, rest: float, notes: list[str]) -> dict[str, str]:
    """Set the joint element's stiffness, damping, armature (moving inertia, if known), springref and
    frictionloss 0 (the drive's friction is the motor joint's); return them as written."""
    si = joint.axes[a].si()
    values = {"stiffness": si["k"], "damping": si["c"], "springref": host.angle(rest), "frictionloss": 0.0}
    if si["m"] is not None:
        values["armature"] = si["m"]
    values = {attr: robot.num(v) for attr, v in values.items()}
    springdamper_off(host, host.element.get("name"), values, notes)
    for attr, v in values.items():
        host.element.set(attr, v)
    return values


@dataclass(frozen=True)
class Drive:
    """What the motor joint carries of the host joint (SI, as the host compiled them): its spring
    (stiffness about springref), damping, friction; `servo_kv` the added servo's derivative gain, which
    adds to the damping (0 when the host's actuators moved to the motor); `moved` those actuators."""

    stiffness: float
    springref: float
    damping: float
    frictionloss: float
    servo_kv: float
    moved: int


def _insert_motor(host: Host, joint_name: str, motor: robot.Sphere, servo: robot.Servo) -> Drive:
    """Put a motor body between the joint's body and its parent; return what its joint carries.

    The motor body (inertial `motor`) takes the link body's place and frame attributes; the link sits
    in it at the identity. The motor joint is a copy of the host joint (type, axis, range...) with the
    servo's armature; joints written before the host joint in its body move with it, so the joints
    still act in the host's order. The motor joint is the drive: it carries the host joint's spring,
    damping and friction as the host compiled them (written out: a class default or a springdamper
    cannot change them). Actuators on the host joint now drive the motor joint; without any, `servo`
    is added as a position actuator (its derivative gain added to the motor joint's damping).
    """
    from lxml import etree

    link = host.element.getparent()
    parent = link.getparent()
    body = etree.Element("body", name=f"{joint_name}_motor")
    # the link's childclass gave the host joint its defaults: the motor joint, its copy, needs it too
    for attr in (*_FRAME, "childclass"):
        if attr in link.attrib:
            body.set(attr, link.get(attr) if attr == "childclass" else link.attrib.pop(attr))
    parent.insert(parent.index(link), body)
    motor_joint = copy.deepcopy(host.element)
    motor_joint.set("name", f"{joint_name}_motor")
    motor_joint.set("armature", robot.num(servo.motor_inertia))
    j = host.model.joint(joint_name)
    own = {
        "stiffness": float(j.stiffness[0]),
        "damping": float(j.damping[0]),
        "frictionloss": float(j.frictionloss[0]),
    }
    for attr, value in own.items():
        motor_joint.set(attr, robot.num(value))
    if float(host.spec.joint(joint_name).springdamper[0]) > 0:
        motor_joint.set("springdamper", "0 0")
    comment = etree.Comment(f" flexjoint designer: the motor of series-elastic joint {joint_name} ")
    # joints before this one in its body act before it: they move to the motor body, in order
    before = []
    for e in link:
        if e is host.element:
            break
        if e.tag in ("joint", "freejoint"):
            before.append(e)
    for child in (comment, etree.fromstring(robot.inertial_xml(motor)), *before, motor_joint, link):
        body.append(child)
    body.tail, link.tail = link.tail, None
    etree.indent(body, space="  ", level=len(list(body.iterancestors())))
    root = host.tree.getroot()
    moved = root.xpath("//actuator/*[@joint=$n]", n=joint_name)
    for act in moved:
        act.set("joint", f"{joint_name}_motor")
    if not moved:
        motor_joint.set("damping", robot.num(own["damping"] + servo.kv))
        section = root.find("actuator")
        if section is None:
            section = etree.SubElement(root, "actuator")
        # ctrllimited stated: a host's actuator defaults may limit control to a range it never gave
        servo_xml = (
            f'<position name="{joint_name}_motor" joint="{joint_name}_motor" kp="{robot.num(servo.kp)}" '
            'ctrllimited="false"/>'
        )
        section.append(etree.fromstring(servo_xml))
    springref = float(host.model.qpos_spring[j.qposadr[0]])
    return Drive(
        own["stiffness"],
        springref,
        own["damping"],
        own["frictionloss"],
        0.0 if moved else servo.kv,
        len(moved),
    )


def _key_layout(host: Host, joint_name: str) -> dict[str, int]:
    """Where the host joint's entries sit in a keyframe's vectors (before the motor is inserted)."""
    j = host.model.joint(joint_name)
    return {"qpos": int(j.qposadr[0]), "qvel": int(j.dofadr[0]), "nq": host.model.nq, "nv": host.model.nv}


def _extend_keys(host: Host, joint_name: str, at: dict[str, int], rest: float, *, servo_added: bool) -> None:
    """Give every <key> the inserted motor joint, so a reset puts every body where the host had it.

    The motor takes the host joint's position less the flexure's `rest` deflection (their rotations
    about the same axis add up to the host's) and its velocity; the flexure starts at `rest`, still.
    An added servo's control holds the motor where the key puts it. A key whose qpos or qvel is not
    the host's full length (MuJoCo pads it) is refused: its meaning would change.
    """
    root = host.tree.getroot()
    servo_index = None
    if servo_added:
        acts = [e for section in root.iter("actuator") for e in section if isinstance(e.tag, str)]
        servo_index = [e.get("name") for e in acts].index(f"{joint_name}_motor")
    for key in root.iter("key"):
        vectors = {n: key.get(n).split() for n in ("qpos", "qvel", "ctrl") if key.get(n) is not None}
        for name, size in (("qpos", at["nq"]), ("qvel", at["nv"])):
            if name in vectors and len(vectors[name]) != size:
                raise DesignerError(
                    f"keyframe {key.get('name') or '(unnamed)'} gives {len(vectors[name])} of the robot's "
                    f"{size} {name} values",
                    f"write every key's {name} in full before the series edit inserts a motor joint",
                )
        host_q = (
            float(vectors["qpos"][at["qpos"]]) if "qpos" in vectors else float(host.model.qpos0[at["qpos"]])
        )
        if "qpos" in vectors:
            vectors["qpos"][at["qpos"]] = robot.num(host_q - rest)
            vectors["qpos"].insert(at["qpos"] + 1, robot.num(rest))
        if "qvel" in vectors:
            vectors["qvel"].insert(at["qvel"] + 1, "0")
        if servo_index is not None and "ctrl" in vectors:
            vectors["ctrl"].insert(servo_index, robot.num(host_q - rest))
        for name, values in vectors.items():
            key.set(name, " ".join(values))


def _compare_series(before, after, joint_name: str, k: float, c: float, servo_kv: float) -> None:
    """Raise unless every host body keeps its world pose and every host joint its numbers.

    MuJoCo numbers bodies and joints in the file's depth-first order, so the inserted motor body and
    joint shift the ids after them by one; the host joint is compared with the motor joint, which
    took over its type, axis, range, spring, friction and damping (plus an added servo's `servo_kv`);
    the flexure has no friction.
    """
    import mujoco

    def shifted(i: int, at: int) -> int:
        return i if i < at else i + 1

    data = [mujoco.MjData(m) for m in (before, after)]
    for m, d in zip((before, after), data, strict=True):
        mujoco.mj_kinematics(m, d)
    motor_body, motor_joint = after.body(f"{joint_name}_motor").id, after.joint(f"{joint_name}_motor").id
    changed = [
        before.body(i).name or f"body {i}"
        for i in range(before.nbody)
        if not (
            np.allclose(data[0].xpos[i], data[1].xpos[shifted(i, motor_body)], atol=1e-12)
            and np.allclose(data[0].xquat[i], data[1].xquat[shifted(i, motor_body)], atol=1e-12)
        )
    ]
    for i in range(before.njnt):
        mine, theirs = before.joint(i), after.joint(shifted(i, motor_joint + 1))
        fields = ("type", "range", "axis", "limited", "stiffness", "frictionloss", "qpos_spring")
        fields += ("damping",) if i == motor_joint else ("armature", "damping")
        same = all(np.array_equal(getattr(mine, f), getattr(theirs, f)) for f in fields[:-1])
        damping = mine.damping + servo_kv if i == motor_joint else mine.damping
        if not (same and np.array_equal(damping, theirs.damping)):
            changed.append(mine.name or f"joint {i}")
    if after.joint(joint_name).frictionloss[0] != 0:
        changed.append(f"{joint_name} (the flexure keeps a frictionloss)")
    if changed:
        raise RuntimeError(f"the series edit changed host bodies or joints: {', '.join(changed)}")
    check_joint(after, joint_name, k, c)


def _refuse_limit_sensors(host: Host, joint_name: str) -> None:
    """Refuse a series edit of a joint that a joint-limit sensor reads: the flexure has no limit."""
    import mujoco

    kinds = {mujoco.mjtSensor.mjSENS_JOINTLIMITPOS, mujoco.mjtSensor.mjSENS_JOINTLIMITVEL}
    kinds |= {mujoco.mjtSensor.mjSENS_JOINTLIMITFRC}
    readers = [
        s.name or s.type.name.removeprefix("mjSENS_").lower()
        for s in host.spec.sensors
        if s.type in kinds and s.objname == joint_name
    ]
    if readers:
        raise DesignerError(
            f"sensor {', '.join(readers)} reads the limit of robot joint '{joint_name}', which the series "
            "form moves to the motor joint (the flexure has no limit)",
            f"point the sensor at {joint_name}_motor in the robot first, or use form='parallel'",
        )


def _series_notes(host: Host, joint_name: str, si: dict, drive: Drive, rest: float) -> list[str]:
    """What the series edit did to the host's own values, one sentence each (SI): which joint carries
    each of them now."""
    j = host.model.joint(joint_name)
    adr = j.qposadr[0]
    unit = "rad" if host.hinge else "m"
    damping = f"damping {drive.damping:.4g}"
    if drive.servo_kv:
        total = drive.damping + drive.servo_kv
        damping += f" + the added servo's derivative gain {drive.servo_kv:.4g} = {total:.4g}"
    notes = [
        f"{joint_name} is now the flexure (SI): stiffness {si['k']:.4g}, damping {si['c']:.4g}, armature "
        f"{si['m']:.4g}, springref {rest:.4g} {unit}, frictionloss 0; nothing of the host joint's own",
        f"{joint_name}_motor, the drive, carries the host joint's (SI): stiffness {drive.stiffness:.4g} "
        f"about springref {drive.springref:.4g} {unit}, {damping}, frictionloss {drive.frictionloss:.4g}",
    ]
    if j.limited[0]:
        lo, hi = (float(v) for v in j.range)
        notes.append(f"range [{lo:.4g}, {hi:.4g}] {unit} moved to {joint_name}_motor; {joint_name} unlimited")
    if float(host.model.qpos0[adr]) != 0.0:
        notes.append(
            f"{joint_name}'s ref {float(host.model.qpos0[adr]):.4g} {unit} -> 0 (the motor keeps it)"
        )
    notes.append(
        f"{drive.moved} actuator(s) moved from {joint_name} to {joint_name}_motor"
        if drive.moved
        else f"position servo {joint_name}_motor added (no actuator drove {joint_name})"
    )
    keys = host.model.nkey
    if keys:
        notes.append(f"{keys} keyframe(s) extended with {joint_name}_motor (the host's angle less the rest)")
    return notes


def into_series(
    joint: Joint,
    host: str | Path,
    path: Path,
    *,
    joint_name: str,
    axis: str | None = None,
    rest: float = 0.0,
    motor_inertia: float | None = None,
    motor_bandwidth: float | None = None,
) -> tuple[dict[str, StepAdvice], tuple[str, ...]]:
    """Write a copy of MJCF `host` to `path` with motor -> flexure -> link at robot joint `joint_name`.

    A motor body `<joint_name>_motor` (carrying the flexure's clamped part) is inserted before the
    joint's body; its joint (a copy of the host joint, `<joint_name>_motor`) takes over the host's
    range and actuators, with armature `motor_inertia` (default: the host joint's armature if any, else
    10 x the flexure's moving inertia), and the host joint becomes the flexure (stiffness, damping,
    armature = its moving inertia, springref = `rest`, unlimited). With no actuator on the joint, a
    position servo is added (see `robot.Servo`). Sensors, tendons and
    equalities on `joint_name` now see the flexure's deflection. Returns the step advice of the flexure
    (motor held) and, when added, of the servo (flexure held), inertias from the mass matrix, and one
    note per host value the edit changed.

    Raises:
        DesignerError: as `into_parallel`, when the names `<joint_name>_motor` are taken, or when a
            joint-limit sensor reads the joint.
    """
    h = open_host(host, joint_name)
    a = host_axis(joint, axis, h, joint_name)
    taken = {e.name for e in (*h.spec.joints, *h.spec.bodies, *h.spec.actuators)}
    if f"{joint_name}_motor" in taken:
        raise DesignerError(f"the robot already has something named {joint_name}_motor", "rename it first")
    _refuse_limit_sensors(h, joint_name)
    full = robot.with_masses(joint)
    si, clamp = full.axes[a].si(), robot.links(full)[a]
    # the link as the flexure sees it: the host's inertia at the joint, less the armature the motor
    # keeps, plus the flexure's own moving inertia; the motor also turns the flexure's clamped part
    dof = h.model.joint(joint_name).dofadr[0]
    host_armature = float(h.model.dof_armature[dof])
    link = mass_diagonal(h.model)[dof] - host_armature + si["m"]
    if motor_inertia is None and host_armature > 0:
        motor_inertia = host_armature
    servo = robot.Servo.for_flexure(
        step_advice(si["k"], si["c"], link),
        carried=link + (clamp.inertia if h.hinge else clamp.mass),
        motor_inertia=motor_inertia,
        bandwidth=motor_bandwidth,
    )
    keys = _key_layout(h, joint_name)
    drive = _insert_motor(h, joint_name, clamp, servo)
    notes = _series_notes(h, joint_name, si, drive, rest)
    notes.append(
        f"{joint_name}_motor armature {servo.motor_inertia:.4g} (the motor's reflected inertia; the host "
        f"joint's was {host_armature:.4g})"
    )
    notes += freeze_springdampers(h, joint_name)
    gains = dampratio_gains(h)
    gains_into_tree(h, gains)
    notes += gains_note(gains, "the motor body")
    _extend_keys(h, joint_name, keys, rest, servo_added=not drive.moved)
    _flexure(h, joint, a, rest, notes)
    for attr, value in (("ref", "0"), ("limited", "false")):
        h.element.set(attr, value)
    check = partial(
        _compare_series, h.model, joint_name=joint_name, k=si["k"], c=si["c"], servo_kv=drive.servo_kv
    )
    after = write_checked(h, path, check)
    diag = mass_diagonal(after)
    flex_dof, motor_dof = after.joint(joint_name).dofadr[0], after.joint(f"{joint_name}_motor").dofadr[0]
    held = {"basis": MASS_MATRIX_BASIS.replace("the other joints held", "the motor and other joints held")}
    advice = {joint_name: step_advice(si["k"], si["c"], diag[flex_dof], **held)}
    if not drive.moved:
        held = {
            "basis": MASS_MATRIX_BASIS.replace("the other joints held", "the flexure and other joints held")
        }
        advice[f"{joint_name}_motor"] = step_advice(servo.kp, servo.kv, diag[motor_dof], **held)
    return advice, tuple(notes)
