"""What the robot formats (MJCF, URDF, SDF) share: axis vectors, the joint's moving links, step advice.

A robot format needs real bodies, never placeholder masses: a moving body without mass breaks MuJoCo
("mass and inertia of moving bodies must be larger than mjMINVAL") and pybullet silently makes it 1 kg
or recomputes its inertia from the collision shape. Each axis of a joint therefore gets a link that
carries that axis' moving mass (translational axes) or moving inertia (rotational axes, with a mass
from the design or from the pseudo-rigid-body model, see `links`), modelled as a sphere centred on the
joint origin: its inertia is isotropic, so importers that recompute inertia from a collision sphere of
that radius (pybullet by default) get the same number.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

from .. import units
from ..errors import DesignerError, check_type
from ..joint import PRB_GAMMA, Joint
from ..mass import specimen_mass
from ..study import space
from .stability import StepAdvice, step_advice

#: the joint axis of each channel; the rotational ones follow roll (phi, x), pitch (theta, y), yaw (psi, z)
AXIS_VECTORS = {"x": "1 0 0", "y": "0 1 0", "z": "0 0 1", "phi": "1 0 0", "theta": "0 1 0", "psi": "0 0 1"}


@dataclass(frozen=True)
class Sphere:
    """A solid sphere on the joint origin: mass (kg), inertia about axes through it (kg.m^2), radius (m)."""

    mass: float
    inertia: float
    radius: float
    basis: str


def sphere_with_mass(mass: float, basis: str) -> Sphere:
    """The solid TPU sphere of `mass` kg (radius from the TPU density)."""
    r = (3 * mass / (4 * math.pi * units.TPU_DENSITY)) ** (1 / 3)
    return Sphere(mass, 0.4 * mass * r * r, r, basis)


def sphere_with_inertia(inertia: float, mass: float, basis: str) -> Sphere:
    """The sphere of `mass` kg with `inertia` kg.m^2 about its centre (radius from 2/5 m r^2)."""
    return Sphere(mass, inertia, math.sqrt(2.5 * inertia / mass), basis)


@dataclass(frozen=True)
class RobotExport:
    """What a robot-format export wrote: the path and, per joint name, the step advice it states."""

    path: Path
    advice: dict[str, StepAdvice]
    #: what the export did to a host's own values, one sentence each (old -> new, SI)
    notes: tuple[str, ...] = ()

    def __fspath__(self) -> str:
        return str(self.path)

    def to_dict(self) -> dict[str, object]:
        """Plain data for JSON: the path, each joint's step advice and the notes."""
        return {
            "path": str(self.path),
            "advice": {n: a.to_dict() for n, a in self.advice.items()},
            "notes": list(self.notes),
        }


def robot_joint_name(joint_name: object) -> str:
    """The `joint_name` an export into a robot needs (the robot joint to make flexible).

    Raises:
        DesignerError: none given, or not a str.
    """
    if joint_name is None:
        raise DesignerError("into= needs joint_name=", "name the robot joint to make flexible")
    check_type(joint_name, str, "joint_name", expected="a name", fix="give e.g. joint_name='knee'")
    return joint_name


def pick_axis(joint: Joint, axis: str | None, rotational: bool | None = None) -> str:
    """The joint's axis to export onto one robot joint: `axis`, or the only one (of the right kind)."""
    if axis is not None:
        return joint.axis(axis).axis
    fits = [a for a in joint.axes if rotational is None or units.is_rotational(a) == rotational]
    if not fits:
        kind, names = (
            ("rotational", units.ROTATIONAL) if rotational else ("translational", units.TRANSLATIONAL)
        )
        raise DesignerError(
            f"joint '{joint.name}' has no {kind} axis for this {'hinge' if rotational else 'slide'}",
            f"build the joint with a {kind} axis ({', '.join(names)})",
        )
    if len(fits) != 1:
        raise DesignerError(
            f"joint '{joint.name}' has axes {', '.join(joint.axes)}; cannot tell which one to export",
            f"pass axis={fits[0]!r}, or another of them",
        )
    return fits[0]


@dataclass(frozen=True)
class Servo:
    """A critically damped position servo: the motor's reflected inertia (its joint armature, SI), the
    bandwidth (Hz), the proportional gain kp and the derivative gain kv (the motor joint's damping).

    The motor body itself carries the flexure's clamped TPU part (see `links`); the rotor's inertia, as
    a geared motor's usually is, is reflected through the gearbox and so modelled as armature.
    """

    motor_inertia: float
    bandwidth: float
    kp: float
    kv: float

    @classmethod
    def for_flexure(
        cls,
        flex: StepAdvice,
        *,
        carried: float,
        motor_inertia: float | None = None,
        bandwidth: float | None = None,
    ) -> Servo:
        """Gains for a servo moving `motor_inertia` plus `carried` (what else turns with the motor).

        Defaults: 10 x the flexure's moving inertia (`flex.inertia`), 10 x its natural frequency.

        Raises:
            DesignerError: a motor inertia or bandwidth that is not positive.
        """
        motor_inertia = 10 * flex.inertia if motor_inertia is None else motor_inertia
        bandwidth = 10 * flex.natural_frequency if bandwidth is None else bandwidth
        if not (motor_inertia > 0 and bandwidth > 0):
            raise DesignerError(
                f"motor_inertia={motor_inertia:g} and motor_bandwidth={bandwidth:g} must be positive",
                "give positive numbers (SI inertia or mass, Hz)",
            )
        total = motor_inertia + carried
        kp = total * (2 * math.pi * bandwidth) ** 2
        return cls(motor_inertia, bandwidth, kp, 2 * math.sqrt(kp * total))


@dataclass(frozen=True)
class SeriesDrive:
    """Motor -> flexure -> link on one axis, standalone: the link (also the motor's body, the
    flexure's clamped part), the servo, and the step advice of the flexure (motor held) and of the
    motor (flexure held), keyed `<joint>_<axis>` and `<joint>_motor`."""

    link: Sphere
    servo: Servo
    advice: dict[str, StepAdvice]


def series_drive(
    joint: Joint, a: str, *, motor_inertia: float | None = None, motor_bandwidth: float | None = None
) -> SeriesDrive:
    """The standalone series form's bodies, servo and advice on axis `a` (see `Servo.for_flexure`):
    the motor turns its armature, its body and the link. The joint must carry masses."""
    rot = units.is_rotational(a)
    link = links(joint)[a]
    moving = link.inertia if rot else link.mass
    si = joint.axes[a].si()
    flex = step_advice(si["k"], si["c"], moving, basis="about the joint axis: the link, the motor held")
    servo = Servo.for_flexure(
        flex, carried=2 * moving, motor_inertia=motor_inertia, bandwidth=motor_bandwidth
    )
    motor = step_advice(
        servo.kp,
        servo.kv,
        servo.motor_inertia + 2 * moving,
        basis="about the joint axis: the motor's armature, its body and the link, the flexure held",
    )
    return SeriesDrive(link, servo, {f"{joint.name}_{a}": flex, f"{joint.name}_motor": motor})


def check_rest(
    rest: float, span: tuple[float, float] | None, joint_name: str, unit: str, allow: bool
) -> None:
    """Refuse a given spring rest outside the robot joint's range `span` (None: unlimited), unless `allow`.

    Raises:
        DesignerError: the rest lies outside the range.
    """
    if span is not None and not span[0] <= rest <= span[1] and not allow:
        raise DesignerError(
            f"rest={rest:g} {unit} is outside the range [{span[0]:.4g}, {span[1]:.4g}] {unit} of robot joint "
            f"'{joint_name}'",
            "give a rest inside the range, or allow_outside_range=True if the spring should preload "
            "the joint against its limit",
        )


def rest_inside(
    host_rest: float,
    span: tuple[float, float] | None,
    unit: str,
    what: str,
    poses: dict[str, float] | None = None,
) -> tuple[float, str | None]:
    """The rest an export uses when none is given: the host's `host_rest` (its springref or Gazebo
    springReference, named `what`) when it lies inside the range `span` (None: unlimited); otherwise
    the first of the host's named `poses` (keyframes) inside the range, else the range's value nearest
    to the host's. A spring resting outside the range would hold the joint against its limit, which a
    host rest of 0 on a joint whose range excludes 0 (MuJoCo's and URDF's default) never meant.
    Returns the rest and the note saying why it is not the host's (None when it is)."""
    if span is None or span[0] <= host_rest <= span[1]:
        return host_rest, None
    lo, hi = span
    for name, q in (poses or {}).items():
        if lo <= q <= hi:
            where = f"the {name} pose's {q:.4g} {unit}"
            return q, _outside_note(host_rest, span, unit, what, where)
    q = min(max(host_rest, lo), hi)
    return q, _outside_note(host_rest, span, unit, what, f"the range's nearest value {q:.4g} {unit}")


def _outside_note(host_rest: float, span: tuple[float, float], unit: str, what: str, where: str) -> str:
    return (
        f"{what}: the host's {host_rest:.4g} {unit} lies outside the joint's range [{span[0]:.4g}, "
        f"{span[1]:.4g}] {unit}, so the spring rests at {where} (give rest to choose another)"
    )


def num(v: float) -> str:
    """A number for XML: the shortest text that reads back as the same float."""
    return repr(float(v))


def inertial_xml(s: Sphere) -> str:
    """The MJCF `<inertial>` of a sphere on the body's origin."""
    i = num(s.inertia)
    return f'<inertial pos="0 0 0" mass="{num(s.mass)}" diaginertia="{i} {i} {i}"/>'


def with_masses(joint: Joint, why: str = "a robot link needs a real mass") -> Joint:
    """The joint with every axis' moving mass: given, or from the design's geometry.

    Raises:
        DesignerError: an axis has no mass and the joint has no design to compute it from.
    """
    if all(ac.m is not None for ac in joint.axes.values()):
        return joint
    try:
        return joint.with_masses()
    except DesignerError:
        missing = [a for a, ac in joint.axes.items() if ac.m is None]
        raise DesignerError(
            f"joint '{joint.name}' has no mass on axis {', '.join(missing)}: {why}",
            "build the joint with m for every axis (kg, or kg.m^2 on rotational axes), or from a design",
        ) from None


def links(joint: Joint) -> dict[str, Sphere]:
    """Per axis the moving link: its mass on a translational axis, its inertia on a rotational one.

    A rotational link weighs the specimen's mass when the joint comes from a design; otherwise the
    mass whose pseudo-rigid-body inertia m (gamma L)^2 is the axis' inertia, for the middle of the
    tested lengths (bounds over the whole range stated). The joint must carry masses (`with_masses`).
    """
    params = joint.provenance.get("params")
    lengths = space.BY_NAME["length"]
    out = {}
    for a, ac in joint.axes.items():
        m = ac.si()["m"]
        if not units.is_rotational(a):
            out[a] = sphere_with_mass(m, f"the axis' moving mass {m:.4g} kg as a solid TPU sphere")
        elif params is not None:
            ms = specimen_mass(params)
            out[a] = sphere_with_inertia(
                m, ms, f"the axis' moving inertia {m:.4g} kg.m^2 with the specimen's mass {ms:.4g} kg"
            )
        else:

            def mass(length_mm: float) -> float:
                return m / (PRB_GAMMA * length_mm * units.MM) ** 2  # noqa: B023

            mid = (lengths.low + lengths.high) / 2
            out[a] = sphere_with_inertia(
                m,
                mass(mid),
                f"the axis' moving inertia {m:.4g} kg.m^2 with mass {mass(mid):.3g} kg = m / (gamma L)^2 at "
                f"L = {mid:g} mm ({mass(lengths.high):.3g} to {mass(lengths.low):.3g} kg over the tested "
                f"{lengths.describe_range()})",
            )
    return out


def chain(joint: Joint) -> tuple[dict[str, Sphere], dict[str, StepAdvice]]:
    """The joint's links per axis, and the step advice per exported joint name (`<joint>_<axis>`).

    The links form a chain, one per axis, all on the joint origin, so an axis sees the sum of the
    masses (translational) or of the inertias (rotational) of its own and the following links, the
    other axes held: on a joint with several axes that is more than the axis' own m, and the advice
    (which states it) uses it. The joint must carry masses (see `with_masses`).
    """
    bodies = links(joint)
    order = list(joint.axes)
    advice = {}
    for i, a in enumerate(order):
        after = [bodies[b] for b in order[i:]]
        inertia = sum(s.inertia if units.is_rotational(a) else s.mass for s in after)
        si = joint.axes[a].si()
        basis = (
            "about the joint axis through the joint origin: this axis' link and those after it in the chain, "
            "the other axes held; each link's collision sphere has that inertia, so importers that "
            "recompute it (pybullet by default) agree"
        )
        advice[f"{joint.name}_{a}"] = step_advice(si["k"], si["c"], inertia, basis=basis)
    return bodies, advice


def provenance_comment(joint: Joint) -> str:
    """The joint's record as an XML comment (a '--' inside would end the comment early)."""
    text = json.dumps(joint.to_dict(), sort_keys=True, default=str).replace("--", "- -")
    return f"<!-- flexjoint designer: {text} -->"


def xml_comment(text: str) -> str:
    return "<!-- " + text.replace("--", "- -") + " -->"
