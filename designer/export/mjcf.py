"""Export a Joint for MuJoCo: a standalone MJCF snippet, a series-elastic form, or into the user's robot.

The snippet declares no `<compiler>`, `<option>` or `<default>`: `<include>`-ing it changes nothing
global in the host. Every value it writes is angle-unit free (stiffness, damping and inertia are per
radian whatever the compiler's angle; springref is 0). Into a robot: see `mjcf_into` (parallel) and
`mjcf_series`.
"""

from __future__ import annotations

from contextlib import contextmanager
from pathlib import Path

from .. import units
from ..errors import DesignerError
from ..files import atomic_write, check_suffix
from ..joint import Joint, check_joint
from . import robot
from .mjcf_into import into_parallel
from .mjcf_series import into_series
from .stability import StepAdvice

FORMS = ("parallel", "series")


def _joint_element(name: str, a: str, k: float, c: float) -> str:
    kind = "hinge" if units.is_rotational(a) else "slide"
    return (
        f'<joint name="{name}" type="{kind}" axis="{robot.AXIS_VECTORS[a]}" stiffness="{robot.num(k)}" '
        f'damping="{robot.num(c)}" springref="0" ref="0" armature="0" frictionloss="0" limited="false"/>'
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
    bodies, advice = robot.chain(joint)
    notes = ["no compiler, option or default here: including this file changes nothing global"]
    opening, closing = [], []
    for depth, a in enumerate(joint.axes, start=2):
        si, pad = joint.axes[a].si(), "  " * depth
        name = f"{joint.name}_{a}"
        opening += [
            f'{pad}<body name="{name}_link">',
            f"{pad}  {robot.xml_comment(f'{name}: {advice[name].text()}')}",
            f"{pad}  {robot.xml_comment('link: ' + bodies[a].basis)}",
            f"{pad}  {robot.inertial_xml(bodies[a])}",
            f"{pad}  {_joint_element(name, a, si['k'], si['c'])}",
        ]
        closing.insert(0, f"{pad}</body>")
    return _document(joint, notes, opening + closing, []), advice


def series_text(
    joint: Joint, a: str, *, motor_inertia: float | None = None, motor_bandwidth: float | None = None
) -> tuple[str, dict[str, StepAdvice]]:
    """Motor -> flexure -> link on axis `a`: a position-servoed motor joint, the flexure joint on it.

    The motor joint has armature `motor_inertia` (SI; default 10 x the link's), its body the flexure's
    clamped part (as the link's body), and a `position` actuator whose gain puts the servo at
    `motor_bandwidth` Hz (default 10 x the flexure's natural frequency); the servo's derivative gain is
    the motor joint's damping, critically damped, so MuJoCo's Euler and implicitfast treat it
    implicitly. The actuator's ctrl is the motor angle (rad) or position (m).
    """
    rot = units.is_rotational(a)
    series = robot.series_drive(joint, a, motor_inertia=motor_inertia, motor_bandwidth=motor_bandwidth)
    link, servo, advice = series.link, series.servo, series.advice
    n, si = joint.name, joint.axes[a].si()
    kind = "hinge" if rot else "slide"
    body = [
        f'    <body name="{n}_motor_rotor">',
        f"      {robot.xml_comment(f'{n}_motor servo, flexure held: ' + advice[f'{n}_motor'].text())}",
        f"      {robot.xml_comment('motor output: ' + link.basis + '; its reflected inertia as armature')}",
        f"      {robot.inertial_xml(link)}",
        f'      <joint name="{n}_motor" type="{kind}" axis="{robot.AXIS_VECTORS[a]}" '
        f'damping="{robot.num(servo.kv)}" armature="{robot.num(servo.motor_inertia)}" frictionloss="0" '
        'limited="false"/>',
        f'      <body name="{n}_{a}_link">',
        f"        {robot.xml_comment(f'{n}_{a} flexure, motor held: ' + advice[f'{n}_{a}'].text())}",
        f"        {robot.xml_comment('link: ' + link.basis)}",
        f"        {robot.inertial_xml(link)}",
        f"        {_joint_element(f'{n}_{a}', a, si['k'], si['c'])}",
        "      </body>",
        "    </body>",
    ]
    actuators = [
        f'    <position name="{n}_motor" joint="{n}_motor" kp="{robot.num(servo.kp)}" ctrllimited="false"/>'
    ]
    notes = [
        "series elastic: motor -> flexure -> link; ctrl of actuator "
        f"{n}_motor is the motor's target {'angle (rad)' if rot else 'position (m)'}",
        f"servo at {servo.bandwidth:.4g} Hz, critically damped: kp = {servo.kp:.4g}, derivative gain as "
        f"the motor joint's damping {servo.kv:.4g} (SI)",
    ]
    return _document(joint, notes, body, actuators), advice


@contextmanager
def _mujoco_warnings():
    """Collect MuJoCo's warnings (a host's deprecated attributes...) for the notes, rather than let
    MuJoCo print them and append them to MUJOCO_LOG.TXT in the current folder."""
    import mujoco

    warned: list[str] = []
    previous = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(lambda message: warned.append(" ".join(message.split())))
    try:
        yield warned
    finally:
        mujoco.set_mju_user_warning(previous)


def _into(
    joint: Joint,
    into: str | Path,
    path: Path,
    *,
    joint_name: str,
    axis: str | None,
    form: str,
    rest: float | None,
    motor_inertia: float | None,
    motor_bandwidth: float | None,
    allow_outside_range: bool,
) -> tuple[dict[str, StepAdvice], tuple[str, ...]]:
    """`into_series` or `into_parallel` with export_mjcf's arguments: (advice, notes)."""
    if form == "series":
        return into_series(
            joint,
            into,
            path,
            joint_name=joint_name,
            axis=axis,
            rest=0.0 if rest is None else rest,
            motor_inertia=motor_inertia,
            motor_bandwidth=motor_bandwidth,
        )
    return into_parallel(
        joint,
        into,
        path,
        joint_name=joint_name,
        axis=axis,
        rest=rest,
        allow_outside_range=allow_outside_range,
    )


def export_mjcf(
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
    """Write `joint` for MuJoCo at `path` (.xml) and return the path and the stated step advice.

    Standalone (`into` None): form "parallel" is a chain of links, one per axis, each on a spring-damper
    joint; form "series" is motor -> flexure -> link on one axis (see `series_text`). With `into` (an
    MJCF file) and `joint_name`, a copy of that robot with the joint made flexible, in parallel or in
    series (see `mjcf_into.into_parallel`, `mjcf_series.into_series`). `rest` (rad or m, the joint's
    qpos): in parallel None keeps the host's springref; a rest outside a limited joint's range is
    refused unless `allow_outside_range`. Masses come from the joint, or from the design's geometry.

    Raises:
        DesignerError: a wrong suffix, unknown form, missing mass, or an `into` problem.
    """
    path = check_suffix(path, (".xml", ".mjcf"), what="an MJCF")
    check_joint(joint)
    if form not in FORMS:
        raise DesignerError(f"form={form!r} is not a form", f"use one of: {', '.join(FORMS)}")
    if into is not None:
        joint_name = robot.robot_joint_name(joint_name)
        with _mujoco_warnings() as warned:
            advice, notes = _into(
                joint,
                into,
                path,
                joint_name=joint_name,
                axis=axis,
                form=form,
                rest=rest,
                motor_inertia=motor_inertia,
                motor_bandwidth=motor_bandwidth,
                allow_outside_range=allow_outside_range,
            )
        notes += tuple(f"MuJoCo warns about the robot: {w}" for w in dict.fromkeys(warned))
        return robot.RobotExport(path, advice, notes)
    if rest not in (None, 0.0):
        raise DesignerError(
            f"rest={rest:g} is for exports into a robot (into=...): a standalone snippet cannot know its "
            "host's angle unit",
            "leave rest at 0 (the snippet's springref), or export into the robot",
        )
    joint = robot.with_masses(joint)
    if form == "series":
        a = robot.pick_axis(joint, axis)
        text, advice = series_text(joint, a, motor_inertia=motor_inertia, motor_bandwidth=motor_bandwidth)
    else:
        text, advice = parallel_text(joint)
    with atomic_write(path) as fh:
        fh.write(text)
    return robot.RobotExport(path, advice)
