"""Make one joint of the user's MJCF robot a flexible joint: in parallel (the joint itself becomes the
spring-damper) or in series (motor -> flexure -> link: a motor body is inserted before the link).

In parallel only the joint's start tag changes in the file's text (every other byte stays as
written); in series the file is restructured with lxml (same content; quoting and whitespace inside
tags normalised). Values go in the host's angle unit. The edited file is compiled by MuJoCo
from beside the output (relative asset paths must still resolve) and checked against the host's own
compiled model before it replaces the output: in parallel, only that joint's numbers and what MuJoCo
derives from the mass matrix may differ; in series, every host body keeps its world pose at the
reference configuration and every other joint its numbers.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass
from functools import partial
from pathlib import Path

import numpy as np

from .. import units
from ..errors import DesignerError
from ..files import atomic_path
from ..joint import Joint
from . import robot, xmltext
from .stability import StepAdvice, step_advice

#: compiled-model arrays that follow from the mass matrix, so they change with a joint's armature
#: (tendon_lengthspring follows the springref of the joints a fixed tendon couples, unless the host
#: gives the tendon's springlength, which the edit does not touch)
_DERIVED = {
    "actuator_acc0",
    "body_invweight0",
    "dof_M0",
    "dof_invweight0",
    "tendon_invweight0",
    "tendon_lengthspring",
}
#: where a compiled model keeps its asset files' names (offsets into its `paths` string): MuJoCo stores
#: them as the file was opened (a relative host, an absolute temporary file), so they differ with the
#: same files; what the assets mean (mesh_vert, mesh_face, tex_data, hfield_data, skin_vert...) is compared
_ASSET_NAMES = {"hfield_pathadr", "mesh_pathadr", "skin_pathadr", "tex_pathadr"}
#: compiled-model arrays the parallel edit sets, per joint, degree of freedom or qpos entry
_EDITED = {"jnt_stiffness": "jnt", "dof_damping": "dof", "dof_armature": "dof", "qpos_spring": "qpos"}
#: what the advice's inertia is when it comes from the compiled robot
MASS_MATRIX_BASIS = (
    "about the joint axis: MuJoCo's joint-space inertia (armature included) at the reference pose qpos0, "
    "the other joints held"
)
#: body attributes that place a body in its parent's frame
_FRAME = ("pos", "quat", "euler", "axisangle", "xyaxes", "zaxis")


@dataclass
class _Host:
    """The robot as loaded: its file, compiled model, spec, lxml tree and the joint's element."""

    path: Path
    model: object
    spec: object
    tree: object
    element: object
    hinge: bool

    def angle(self, value: float) -> float:
        """An SI angle (rad) or length (m) in the host's unit for this joint."""
        return math.degrees(value) if self.hinge and self.spec.compiler.degree else value

    def bytes(self) -> bytes:
        """The edited tree as a file (lxml normalises quoting and whitespace inside tags)."""
        from lxml import etree

        raw = self.path.read_bytes()
        data = etree.tostring(self.tree, xml_declaration=raw.lstrip().startswith(b"<?xml"), encoding="utf-8")
        return data + b"\n" if raw.endswith(b"\n") else data


def _open(host: str | Path, joint_name: str) -> _Host:
    """Load the host robot and find its hinge or slide joint `joint_name` in the file itself.

    Raises:
        DesignerError: no such file, not loadable by MuJoCo, no such joint, or one from an include.
    """
    import mujoco
    from lxml import etree

    host = Path(host)
    if not host.is_file():
        raise DesignerError(f"into={str(host)!r} does not exist", "give the path of the robot's MJCF file")
    try:
        model = mujoco.MjModel.from_xml_path(str(host))
        spec = mujoco.MjSpec.from_file(str(host))
    except ValueError as exc:
        raise DesignerError(f"MuJoCo cannot load into={str(host)!r}: {exc}", "give an MJCF file") from None
    kinds = (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE)
    have = [j.name for j in spec.joints if j.type in kinds and j.name]
    if joint_name not in have:
        raise DesignerError(
            f"joint_name={joint_name!r}: the robot has no hinge or slide joint of that name",
            f"its hinge and slide joints are: {', '.join(have) or 'none'}",
        )
    tree = etree.parse(str(host))
    found = tree.getroot().xpath("//worldbody//body/joint[@name=$n]", n=joint_name)
    if len(found) != 1:
        raise DesignerError(
            f"joint '{joint_name}' is not written in {host} itself (it comes from an <include>d file)",
            "give the file that defines the joint as into=",
        )
    hinge = spec.joint(joint_name).type == mujoco.mjtJoint.mjJNT_HINGE
    return _Host(host, model, spec, tree, found[0], hinge)


def _axis(joint: Joint, axis: str | None, host: _Host, joint_name: str) -> str:
    a = robot.pick_axis(joint, axis, host.hinge)
    if units.is_rotational(a) != host.hinge:
        raise DesignerError(
            f"axis={a!r} is {'rotational' if units.is_rotational(a) else 'translational'} but robot joint "
            f"'{joint_name}' is a {'hinge' if host.hinge else 'slide'}",
            "give an axis of the same kind as the robot joint",
        )
    return a


def _write_checked(host: _Host, path: Path, check, data: bytes | None = None) -> object:
    """Write `data` (default: the edited tree) beside `path`, compile it there, run `check(model)`,
    then rename it to `path`."""
    import mujoco

    with atomic_path(path) as tmp:
        tmp.write_bytes(host.bytes() if data is None else data)
        try:
            after = mujoco.MjModel.from_xml_path(str(tmp))
        except ValueError as exc:
            raise DesignerError(
                f"the edited robot does not load from {path.parent}: {exc}",
                "write path= into the robot's folder so its relative file names still resolve",
            ) from None
        check(after)
    return after


def _mass_diagonal(model) -> np.ndarray:
    """The joint-space inertia matrix's diagonal at the reference pose (kg.m^2 or kg per dof)."""
    import mujoco

    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    full = np.zeros((model.nv, model.nv))
    try:
        mujoco.mj_fullM(model, data, full)  # MuJoCo 4
    except TypeError:
        mujoco.mj_fullM(model, full, data.qM)  # MuJoCo 3
    return np.diag(full)


def _compare_parallel(before, after, joint_name: str, k: float, c: float) -> None:
    """Raise if compiling the edited model changed anything but the joint and its mass-matrix terms."""
    j = after.joint(joint_name)
    index = {"jnt": j.id, "dof": j.dofadr[0], "qpos": j.qposadr[0]}
    changed = []
    for name in dir(before):
        a = getattr(before, name)
        if name.startswith("_") or not isinstance(a, np.ndarray) or name in _DERIVED | _ASSET_NAMES:
            continue
        b = getattr(after, name)
        if a.shape == b.shape and name in _EDITED:
            a, b = np.delete(a, index[_EDITED[name]], axis=0), np.delete(b, index[_EDITED[name]], axis=0)
        if a.shape != b.shape or not np.array_equal(a, b, equal_nan=True):
            changed.append(name)
    changed += [g for g in ("opt", "vis") if repr(getattr(before, g)) != repr(getattr(after, g))]
    _check_joint(after, joint_name, k, c)
    if changed:
        raise RuntimeError(f"editing one joint changed the compiled model's {', '.join(changed)}")


def _springdamper_off(host: _Host, joint_name: str, values: dict[str, str], notes: list[str]) -> None:
    """Add springdamper="0 0" to `values` (and say so) when the host joint has one: MuJoCo would
    otherwise compute stiffness and damping from it and ignore the flexure's."""
    timeconst, ratio = (float(v) for v in host.spec.joint(joint_name).springdamper)
    if timeconst > 0:
        values["springdamper"] = "0 0"
        notes.append(
            f"springdamper (time constant {timeconst:.4g} s, damping ratio {ratio:.4g}) -> 0 0: MuJoCo would "
            "derive stiffness and damping from it in place of the flexure's"
        )


def _check_joint(after, joint_name: str, k: float, c: float) -> None:
    """Raise unless MuJoCo compiled the edited joint with exactly stiffness `k` and damping `c`."""
    j = after.joint(joint_name)
    got = (float(j.stiffness[0]), float(after.dof_damping[j.dofadr[0]]))
    if got != (k, c):
        raise RuntimeError(f"joint {joint_name} compiled with stiffness, damping {got}, not {(k, c)}")


def _flexure(host: _Host, joint: Joint, a: str, rest: float, notes: list[str]) -> dict[str, str]:
    """Set the joint element's stiffness, damping, armature (moving inertia, if known) and springref;
    return them as written."""
    si = joint.axes[a].si()
    values = {"stiffness": si["k"], "damping": si["c"], "springref": host.angle(rest)}
    if si["m"] is not None:
        values["armature"] = si["m"]
    values = {attr: robot.num(v) for attr, v in values.items()}
    _springdamper_off(host, host.element.get("name"), values, notes)
    for attr, v in values.items():
        host.element.set(attr, v)
    return values


def _retag(text: str, joint_name: str, values: dict[str, str]) -> str:
    """`text` with only the start tag of joint `joint_name` changed: `values` set, all else as written."""
    m = xmltext.find_one(text, "joint", "name", joint_name)
    return text[: m.start()] + xmltext.set_attributes(m.group(0), values) + text[m.end() :]


def into_parallel(
    joint: Joint,
    host: str | Path,
    path: Path,
    *,
    joint_name: str,
    axis: str | None = None,
    rest: float | None = None,
    allow_outside_range: bool = False,
) -> tuple[dict[str, StepAdvice], tuple[str, ...]]:
    """Write a copy of MJCF `host` to `path` with robot joint `joint_name` made this flexible joint.

    Sets stiffness and damping; springref to `rest` (SI, the joint's qpos, written in the host's
    angle unit; None keeps the host's); armature to the axis' moving mass only where the host has
    none (a host armature, the motor's reflected inertia, is kept). Returns the step advice for the
    joint (inertia from the compiled model's mass matrix, other joints held, at the reference pose)
    and one note per host value changed or kept (old -> new, SI).

    Raises:
        DesignerError: no such host file or joint, a ball or free joint, an axis of the wrong kind, a
            rest outside a limited joint's range (unless `allow_outside_range`).
    """
    h = _open(host, joint_name)
    a = _axis(joint, axis, h, joint_name)
    values, notes = _parallel_values(h, joint, a, joint_name, rest, allow_outside_range)
    for attr, v in values.items():
        h.element.set(attr, v)
    raw = h.path.read_bytes()
    encoding = h.tree.docinfo.encoding or "utf-8"
    text = _retag(raw.decode(encoding), joint_name, values)
    si = joint.axes[a].si()
    check = partial(_compare_parallel, h.model, joint_name=joint_name, k=si["k"], c=si["c"])
    after = _write_checked(h, path, check, text.encode(encoding))
    dof = after.joint(joint_name).dofadr[0]
    inertia = _mass_diagonal(after)[dof]
    return {joint_name: step_advice(si["k"], si["c"], inertia, basis=MASS_MATRIX_BASIS)}, notes


def _parallel_values(
    h: _Host, joint: Joint, a: str, joint_name: str, rest: float | None, allow_outside_range: bool
) -> tuple[dict[str, str], tuple[str, ...]]:
    """The joint element's new attributes (host units) and the notes on every host value (SI)."""
    si = joint.axes[a].si()
    j = h.model.joint(joint_name)
    dof, adr = j.dofadr[0], j.qposadr[0]
    unit = "rad" if h.hinge else "m"
    old = {
        "stiffness": float(j.stiffness[0]),
        "damping": float(h.model.dof_damping[dof]),
        "springref": float(h.model.qpos_spring[adr]),
        "armature": float(h.model.dof_armature[dof]),
    }
    new = {"stiffness": si["k"], "damping": si["c"]}
    notes = []
    span = tuple(float(v) for v in h.model.jnt_range[j.id]) if h.model.jnt_limited[j.id] else None
    if rest is None:
        keys = {
            f"keyframe '{h.model.key(k).name or k}'": float(h.model.key_qpos[k][adr])
            for k in range(h.model.nkey)
        }
        rest, moved = robot.rest_inside(old["springref"], span, unit, "springref", keys)
        if moved is None:
            notes.append(f"springref kept at the host's {old['springref']:.4g} {unit} (give rest to set it)")
        else:
            notes.append(moved)
            new["springref"] = rest
    else:
        robot.check_rest(rest, span, joint_name, unit, allow_outside_range)
        new["springref"] = rest
    if old["armature"] > 0:
        notes.append(
            f"armature kept at the host's {old['armature']:.4g} (the motor's; the flexure's own moving "
            f"inertia {si['m'] if si['m'] is not None else 0:.3g} not added)"
        )
    elif si["m"] is not None:
        new["armature"] = si["m"]
    if float(h.model.qpos0[adr]) != 0.0:
        notes.append(
            f"rest is the joint's qpos, which this joint's ref puts at {float(h.model.qpos0[adr]):.4g} "
            f"{unit} in its reference pose"
        )
    notes += [f"{attr}: {old[attr]:.4g} -> {v:.4g} (SI)" for attr, v in new.items() if v != old[attr]]
    values = {attr: robot.num(h.angle(v) if attr == "springref" else v) for attr, v in new.items()}
    _springdamper_off(h, joint_name, values, notes)
    return values, tuple(notes)


def _insert_motor(host: _Host, joint_name: str, motor: robot.Sphere, servo: robot.Servo) -> int:
    """Put a motor body between the joint's body and its parent; return how many actuators moved to it.

    The motor body (inertial `motor`) takes the link body's place and frame attributes; the link sits
    in it at the identity. The motor joint is a copy of the host joint (type, axis, range...) with the
    servo's armature; joints written before the host joint in its body move with it, so the joints
    still act in the host's order. Actuators
    on the host joint now drive the motor joint; without any, `servo` is added as a position actuator
    (its derivative gain as the motor joint's damping).
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
        motor_joint.set("damping", robot.num(servo.kv))
        section = root.find("actuator")
        if section is None:
            section = etree.SubElement(root, "actuator")
        # ctrllimited stated: a host's actuator defaults may limit control to a range it never gave
        servo_xml = (
            f'<position name="{joint_name}_motor" joint="{joint_name}_motor" kp="{robot.num(servo.kp)}" '
            'ctrllimited="false"/>'
        )
        section.append(etree.fromstring(servo_xml))
    return len(moved)


def _key_layout(host: _Host, joint_name: str) -> dict[str, int]:
    """Where the host joint's entries sit in a keyframe's vectors (before the motor is inserted)."""
    j = host.model.joint(joint_name)
    return {"qpos": int(j.qposadr[0]), "qvel": int(j.dofadr[0]), "nq": host.model.nq, "nv": host.model.nv}


def _extend_keys(host: _Host, joint_name: str, at: dict[str, int], rest: float, *, servo_added: bool) -> None:
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


def _compare_series(before, after, joint_name: str, k: float, c: float) -> None:
    """Raise unless every host body keeps its world pose and every host joint its numbers.

    MuJoCo numbers bodies and joints in the file's depth-first order, so the inserted motor body and
    joint shift the ids after them by one; the host joint is compared with the motor joint, which
    took over its type, axis and range.
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
        fields = (
            ("type", "range", "axis", "limited")
            if i == motor_joint
            else ("type", "range", "axis", "limited", "stiffness", "armature", "damping")
        )
        if not all(np.array_equal(getattr(mine, f), getattr(theirs, f)) for f in fields):
            changed.append(mine.name or f"joint {i}")
    if changed:
        raise RuntimeError(f"the series edit changed host bodies or joints: {', '.join(changed)}")
    _check_joint(after, joint_name, k, c)


def _freeze_springdampers(host: _Host, joint_name: str) -> list[str]:
    """Write out the compiled stiffness and damping of every other joint with a springdamper.

    MuJoCo derives those from the mass matrix, so the motor body's mass would change them; written
    out (springdamper 0 0) they stay what the host compiled them to.
    """
    frozen = []
    for j in host.spec.joints:
        if j.name == joint_name or j.springdamper[0] <= 0:
            continue
        found = host.tree.getroot().xpath("//worldbody//joint[@name=$n]", n=j.name) if j.name else []
        if len(found) != 1:
            raise DesignerError(
                f"joint {j.name or '(unnamed)'} takes stiffness and damping from springdamper, which the "
                "series edit's motor body would change, and designer cannot find it in the file to keep them",
                "name the joint in the robot's file, or use form='parallel'",
            )
        compiled = host.model.joint(j.name)
        found[0].set("stiffness", robot.num(compiled.stiffness[0]))
        found[0].set("damping", robot.num(host.model.dof_damping[compiled.dofadr[0]]))
        found[0].set("springdamper", "0 0")
        frozen.append(j.name)
    if not frozen:
        return []
    named = ", ".join(frozen[:3]) + (", ..." if len(frozen) > 3 else "")
    return [
        f"{len(frozen)} joints with springdamper ({named}) "
        "keep their compiled stiffness and damping, now written out (springdamper 0 0): MuJoCo derives them "
        "from the mass matrix, which the motor body changes"
    ]


def _refuse_limit_sensors(host: _Host, joint_name: str) -> None:
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


def _series_notes(host: _Host, joint_name: str, si: dict, moved: int, rest: float) -> list[str]:
    """What the series edit did to the host's own values, one sentence each (SI)."""
    j = host.model.joint(joint_name)
    dof, adr = j.dofadr[0], j.qposadr[0]
    unit = "rad" if host.hinge else "m"
    old = (float(j.stiffness[0]), float(host.model.dof_damping[dof]), float(host.model.dof_armature[dof]))
    new = (si["k"], si["c"], si["m"])
    notes = [
        f"{joint_name} is now the flexure (SI): "
        + ", ".join(
            f"{n} {a:.4g} -> {b:.4g}"
            for n, a, b in zip(("stiffness", "damping", "armature"), old, new, strict=True)
        )
        + f", springref {float(host.model.qpos_spring[adr]):.4g} -> {rest:.4g} {unit}"
    ]
    if j.limited[0]:
        lo, hi = (float(v) for v in j.range)
        notes.append(f"range [{lo:.4g}, {hi:.4g}] {unit} moved to {joint_name}_motor; {joint_name} unlimited")
    if float(host.model.qpos0[adr]) != 0.0:
        notes.append(
            f"{joint_name}'s ref {float(host.model.qpos0[adr]):.4g} {unit} -> 0 (the motor keeps it)"
        )
    notes.append(
        f"{moved} actuator(s) moved from {joint_name} to {joint_name}_motor"
        if moved
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
    h = _open(host, joint_name)
    a = _axis(joint, axis, h, joint_name)
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
    link = _mass_diagonal(h.model)[dof] - host_armature + si["m"]
    if motor_inertia is None and host_armature > 0:
        motor_inertia = host_armature
    servo = robot.Servo.for_flexure(
        step_advice(si["k"], si["c"], link),
        carried=link + (clamp.inertia if h.hinge else clamp.mass),
        motor_inertia=motor_inertia,
        bandwidth=motor_bandwidth,
    )
    keys = _key_layout(h, joint_name)
    moved = _insert_motor(h, joint_name, clamp, servo)
    notes = _series_notes(h, joint_name, si, moved, rest)
    notes.append(
        f"{joint_name}_motor armature {servo.motor_inertia:.4g} (the motor's reflected inertia; the host "
        f"joint's was {host_armature:.4g})"
    )
    notes += _freeze_springdampers(h, joint_name)
    _extend_keys(h, joint_name, keys, rest, servo_added=not moved)
    _flexure(h, joint, a, rest, notes)
    for attr, value in (("ref", "0"), ("limited", "false")):
        h.element.set(attr, value)
    check = partial(_compare_series, h.model, joint_name=joint_name, k=si["k"], c=si["c"])
    after = _write_checked(h, path, check)
    diag = _mass_diagonal(after)
    flex_dof, motor_dof = after.joint(joint_name).dofadr[0], after.joint(f"{joint_name}_motor").dofadr[0]
    held = {"basis": MASS_MATRIX_BASIS.replace("the other joints held", "the motor and other joints held")}
    advice = {joint_name: step_advice(si["k"], si["c"], diag[flex_dof], **held)}
    if not moved:
        held = {
            "basis": MASS_MATRIX_BASIS.replace("the other joints held", "the flexure and other joints held")
        }
        advice[f"{joint_name}_motor"] = step_advice(servo.kp, servo.kv, diag[motor_dof], **held)
    return advice, tuple(notes)
