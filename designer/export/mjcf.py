"""Export a Joint for MuJoCo: a standalone MJCF snippet, a series-elastic form, or into the user's robot.

The snippet declares no `<compiler>`, `<option>` or `<default>`: `<include>`-ing it changes nothing
global in the host. Every value it writes is angle-unit free (stiffness, damping and inertia are per
radian whatever the compiler's angle; springref is 0). Into a robot, the host file is edited in place
of one joint element (lxml keeps everything else byte for byte), springref is written in the host's
angle unit, and both models are compiled and compared: only that joint's numbers and what MuJoCo
derives from the mass matrix may differ.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import units
from ..errors import DesignerError
from ..files import atomic_path, atomic_write
from ..joint import Joint
from . import robot
from .stability import StepAdvice, step_advice

FORMS = ("parallel", "series")
#: compiled-model arrays that follow from the mass matrix, so they change with a joint's armature
_DERIVED = {"actuator_acc0", "body_invweight0", "dof_M0", "dof_invweight0", "tendon_invweight0"}
#: compiled-model arrays the edit sets, per joint or per degree of freedom
_EDITED = {"jnt_stiffness": "jnt", "dof_damping": "dof", "dof_armature": "dof", "qpos_spring": "qpos"}


@dataclass(frozen=True)
class RobotExport:
    """What a robot-format export wrote: the path and, per joint name, the step advice it states."""

    path: Path
    advice: dict[str, StepAdvice]

    def __fspath__(self) -> str:
        return str(self.path)

    def to_dict(self) -> dict[str, object]:
        return {"path": str(self.path), "advice": {n: a.to_dict() for n, a in self.advice.items()}}


def _num(v: float) -> str:
    return repr(float(v))


def _inertial(s: robot.Sphere) -> str:
    i = _num(s.inertia)
    return f'<inertial pos="0 0 0" mass="{_num(s.mass)}" diaginertia="{i} {i} {i}"/>'


def _joint_element(name: str, a: str, k: float, c: float) -> str:
    kind = "hinge" if units.is_rotational(a) else "slide"
    return (
        f'<joint name="{name}" type="{kind}" axis="{robot.AXIS_VECTORS[a]}" stiffness="{_num(k)}" '
        f'damping="{_num(c)}" springref="0" ref="0" armature="0" frictionloss="0" limited="false"/>'
    )


def _document(joint: Joint, notes: list[str], body: list[str], actuators: list[str]) -> str:
    lines = [robot.provenance_comment(joint), f'<mujoco model="{joint.name}">']
    lines += ["  " + robot.xml_comment(n) for n in notes]
    lines += ["  <worldbody>", *body, "  </worldbody>"]
    if actuators:
        lines += ["  <actuator>", *actuators, "  </actuator>"]
    return "\n".join([*lines, "</mujoco>", ""])


def parallel_text(joint: Joint) -> tuple[str, dict[str, StepAdvice]]:
    """The joint as a chain of links, one per axis, each on its spring-damper joint to the previous one.

    The joint must carry masses (see `robot.with_masses`).
    """
    bodies = robot.links(joint)
    advice = {f"{joint.name}_{a}": adv for a, adv in robot.chain_advice(joint, bodies).items()}
    notes = ["no compiler, option or default here: including this file changes nothing global"]
    opening, closing = [], []
    for depth, a in enumerate(joint.axes, start=2):
        si, pad = joint.axes[a].si(), "  " * depth
        name = f"{joint.name}_{a}"
        opening += [
            f'{pad}<body name="{name}_link">',
            f"{pad}  {robot.xml_comment(f'{name}: {advice[name].text()}')}",
            f"{pad}  {robot.xml_comment('link: ' + bodies[a].basis)}",
            f"{pad}  {_inertial(bodies[a])}",
            f"{pad}  {_joint_element(name, a, si['k'], si['c'])}",
        ]
        closing.insert(0, f"{pad}</body>")
    return _document(joint, notes, opening + closing, []), advice


def series_text(
    joint: Joint, a: str, *, motor_inertia: float | None = None, motor_bandwidth: float | None = None
) -> tuple[str, dict[str, StepAdvice]]:
    """Motor -> flexure -> link on axis `a`: a position-servoed motor joint, the flexure joint on it.

    The motor body carries `motor_inertia` (SI; default 10 x the link's) and a `position` actuator whose
    gain puts the servo at `motor_bandwidth` Hz (default 10 x the flexure's natural frequency); the
    servo's derivative gain is the motor joint's damping, critically damped, so MuJoCo's Euler and
    implicitfast treat it implicitly. The actuator's ctrl is the motor angle (rad) or position (m).
    """
    rot = units.is_rotational(a)
    link = robot.links(joint)[a]
    link_inertia = link.inertia if rot else link.mass
    si = joint.axes[a].si()
    flex = step_advice(si["k"], si["c"], link_inertia)
    motor_inertia = 10 * link_inertia if motor_inertia is None else motor_inertia
    bandwidth = 10 * flex.natural_frequency if motor_bandwidth is None else motor_bandwidth
    if not (motor_inertia > 0 and bandwidth > 0):
        raise DesignerError(
            f"motor_inertia = {motor_inertia:g} and motor_bandwidth = {bandwidth:g} must be positive",
            "give positive numbers (SI inertia or mass, Hz)",
        )
    total = motor_inertia + link_inertia
    kp = total * (2 * math.pi * bandwidth) ** 2
    kv = 2 * math.sqrt(kp * total)
    if rot:
        motor = robot.sphere_with_inertia(
            motor_inertia, link.mass, f"motor inertia {motor_inertia:.4g} kg.m^2"
        )
    else:
        motor = robot.sphere_with_mass(motor_inertia, f"motor mass {motor_inertia:.4g} kg")
    n = joint.name
    advice = {f"{n}_{a}": flex, f"{n}_motor": step_advice(kp, kv, total)}
    kind = "hinge" if rot else "slide"
    body = [
        f'    <body name="{n}_motor_rotor">',
        f"      {robot.xml_comment(f'{n}_motor servo, flexure held: ' + advice[f'{n}_motor'].text())}",
        f"      {robot.xml_comment('rotor: ' + motor.basis)}",
        f"      {_inertial(motor)}",
        f'      <joint name="{n}_motor" type="{kind}" axis="{robot.AXIS_VECTORS[a]}" damping="{_num(kv)}" '
        'armature="0" frictionloss="0" limited="false"/>',
        f'      <body name="{n}_{a}_link">',
        f"        {robot.xml_comment(f'{n}_{a} flexure, motor held: ' + flex.text())}",
        f"        {robot.xml_comment('link: ' + link.basis)}",
        f"        {_inertial(link)}",
        f"        {_joint_element(f'{n}_{a}', a, si['k'], si['c'])}",
        "      </body>",
        "    </body>",
    ]
    actuators = [f'    <position name="{n}_motor" joint="{n}_motor" kp="{_num(kp)}" ctrllimited="false"/>']
    notes = [
        "series elastic: motor -> flexure -> link; ctrl of actuator "
        f"{n}_motor is the motor's target {'angle (rad)' if rot else 'position (m)'}",
        f"servo at {bandwidth:.4g} Hz, critically damped: kp = {kp:.4g}, derivative gain as the motor "
        f"joint's damping {kv:.4g} (SI)",
    ]
    return _document(joint, notes, body, actuators), advice


def _host_joint(spec, name: str):
    """The host's hinge or slide joint `name` (MjsJoint), else a DesignerError listing the candidates."""
    import mujoco

    kinds = (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE)
    have = [j.name for j in spec.joints if j.type in kinds and j.name]
    if name not in have:
        raise DesignerError(
            f"joint_name={name!r}: the robot has no hinge or slide joint of that name",
            f"its hinge and slide joints are: {', '.join(have) or 'none'}",
        )
    return spec.joint(name)


def pick_axis(joint: Joint, axis: str | None, rotational: bool | None = None) -> str:
    """The joint's axis to export onto one robot joint: `axis`, or the only one (of the right kind)."""
    if axis is not None:
        return joint.axis(axis).axis
    fits = [a for a in joint.axes if rotational is None or units.is_rotational(a) == rotational]
    if len(fits) != 1:
        raise DesignerError(
            f"joint '{joint.name}' has axes {', '.join(joint.axes)}; cannot tell which one to export",
            "give axis= one of them",
        )
    return fits[0]


def _compare(before, after, jnt: int, dof: int, qpos: int) -> None:
    """Raise if compiling the edited model changed anything but the joint and its mass-matrix terms."""
    index = {"jnt": jnt, "dof": dof, "qpos": qpos}
    changed = []
    for name in dir(before):
        a = getattr(before, name)
        if name.startswith("_") or not isinstance(a, np.ndarray) or name in _DERIVED:
            continue
        b = getattr(after, name)
        if a.shape != b.shape:
            changed.append(name)
            continue
        if name in _EDITED:
            a, b = np.delete(a, index[_EDITED[name]], axis=0), np.delete(b, index[_EDITED[name]], axis=0)
        if not np.array_equal(a, b, equal_nan=True):
            changed.append(name)
    for group in ("opt", "vis"):
        if repr(getattr(before, group)) != repr(getattr(after, group)):
            changed.append(group)
    if changed:
        raise RuntimeError(f"editing one joint changed the compiled model's {', '.join(changed)}")


def _edit(host: Path, name: str, values: dict[str, float]) -> bytes:
    """The host file's bytes with joint `name`'s attributes set to `values` (lxml: the rest untouched)."""
    from lxml import etree

    tree = etree.parse(str(host), etree.XMLParser(remove_blank_text=False))
    found = tree.getroot().xpath("//worldbody//joint[@name=$n]", n=name)
    if len(found) != 1:
        raise DesignerError(
            f"joint '{name}' is not written in {host} itself (it comes from an <include>d file)",
            "give the file that defines the joint as into=",
        )
    for attr, v in values.items():
        found[0].set(attr, _num(v))
    declared = host.read_bytes().lstrip().startswith(b"<?xml")
    return etree.tostring(tree, xml_declaration=declared, encoding="utf-8")


def into_robot(
    joint: Joint, host: str | Path, path: Path, *, joint_name: str, axis: str | None = None, rest: float = 0.0
) -> dict[str, StepAdvice]:
    """Write a copy of MJCF `host` to `path` with robot joint `joint_name` made this flexible joint.

    Sets stiffness, damping, armature (the axis' moving mass, when known) and springref (`rest`, SI,
    written in the host's angle unit); compiles both models and checks that nothing else changed.
    Returns the step advice for the joint, its inertia from the compiled model's mass matrix (other
    joints held, at the reference pose).

    Raises:
        DesignerError: no such host file or joint, a ball or free joint, an axis of the wrong kind.
    """
    import mujoco

    host = Path(host)
    if not host.is_file():
        raise DesignerError(f"into={str(host)!r} does not exist", "give the path of the robot's MJCF file")
    try:
        before = mujoco.MjModel.from_xml_path(str(host))
        spec = mujoco.MjSpec.from_file(str(host))
    except ValueError as exc:
        raise DesignerError(f"MuJoCo cannot load into={str(host)!r}: {exc}", "give an MJCF file") from None
    hinge = _host_joint(spec, joint_name).type == mujoco.mjtJoint.mjJNT_HINGE
    a = pick_axis(joint, axis, hinge)
    if units.is_rotational(a) != hinge:
        raise DesignerError(
            f"axis={a!r} is {'rotational' if units.is_rotational(a) else 'translational'} but robot joint "
            f"'{joint_name}' is a {'hinge' if hinge else 'slide'}",
            "give an axis of the same kind as the robot joint",
        )
    si = joint.axes[a].si()
    values = {"stiffness": si["k"], "damping": si["c"]}
    values["springref"] = math.degrees(rest) if hinge and spec.compiler.degree else rest
    if si["m"] is not None:
        values["armature"] = si["m"]
    with atomic_path(path) as tmp:
        tmp.write_bytes(_edit(host, joint_name, values))
        try:
            after = mujoco.MjModel.from_xml_path(str(tmp))
        except ValueError as exc:
            raise DesignerError(
                f"the edited robot does not load from {path.parent}: {exc}",
                "write path= into the robot's folder so its relative file names still resolve",
            ) from None
        j = after.joint(joint_name)
        _compare(before, after, j.id, j.dofadr[0], j.qposadr[0])
    full = np.zeros((after.nv, after.nv))
    data = mujoco.MjData(after)
    mujoco.mj_forward(after, data)
    try:
        mujoco.mj_fullM(after, data, full)  # MuJoCo 4
    except TypeError:
        mujoco.mj_fullM(after, full, data.qM)  # MuJoCo 3
    dof = j.dofadr[0]
    return {joint_name: step_advice(si["k"], si["c"], full[dof, dof])}


def export_mjcf(
    joint: Joint,
    path: str | Path,
    *,
    into: str | Path | None = None,
    joint_name: str | None = None,
    axis: str | None = None,
    form: str = "parallel",
    rest: float = 0.0,
    motor_inertia: float | None = None,
    motor_bandwidth: float | None = None,
) -> RobotExport:
    """Write `joint` for MuJoCo at `path` (.xml) and return the path and the stated step advice.

    Standalone (`into` None): form "parallel" is a chain of links, one per axis, each on a spring-damper
    joint; form "series" is motor -> flexure -> link on one axis (see `series_text`). With `into` (an
    MJCF file) and `joint_name`, a copy of that robot with the joint made flexible (see `into_robot`).
    Masses come from the joint, or from the design's geometry.

    Raises:
        DesignerError: a wrong suffix, unknown form, missing mass, or an `into` problem.
    """
    path = robot.check_suffix(path, (".xml", ".mjcf"), "an MJCF model")
    if form not in FORMS:
        raise DesignerError(f"form={form!r} is not a form", f"use one of: {', '.join(FORMS)}")
    if into is not None:
        if form != "parallel" or joint_name is None:
            raise DesignerError(
                "into= needs joint_name= and the parallel form",
                "name the robot joint to make flexible; the series form is standalone only",
            )
        return RobotExport(path, into_robot(joint, into, path, joint_name=joint_name, axis=axis, rest=rest))
    joint = robot.with_masses(joint)
    if form == "series":
        a = pick_axis(joint, axis)
        text, advice = series_text(joint, a, motor_inertia=motor_inertia, motor_bandwidth=motor_bandwidth)
    else:
        text, advice = parallel_text(joint)
    with atomic_write(path) as fh:
        fh.write(text)
    return RobotExport(path, advice)
