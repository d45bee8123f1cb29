"""Export a Joint as URDF (spring in a Gazebo extension) or SDFormat (spring in the joint's dynamics).

URDF has damping (`<dynamics damping>`) but no joint spring: the stiffness goes into
`<gazebo reference="joint"><springStiffness>`/`<springReference>`, which Gazebo's URDF converter turns
into SDFormat's `//joint/axis/dynamics/spring_stiffness` and `spring_reference`; engines without a URDF
spring (MuJoCo, pybullet) read those two values from there. Each axis' link has a real mass and an
isotropic inertia and a collision sphere whose own inertia equals it (see `robot`), so pybullet's
default of recomputing inertia from collision shapes gives the same number.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from pathlib import Path

from .. import units
from ..errors import DesignerError
from ..files import atomic_path, atomic_write, check_suffix
from ..joint import Joint, check_joint
from . import robot, urdf_drake, xmltext
from .mjcf_host import compiled_changes
from .stability import step_advice
from .urdf_inertia import moved_inertia
from .urdf_packages import mujoco_urdf, packages_named

#: a prismatic URDF joint needs limits; these (m) are wide enough never to act on a flexure
PRISMATIC_LIMIT = 1.0


def _gazebo(name: str, k: float, rest: float) -> list[str]:
    return [
        f'  <gazebo reference="{name}">',
        f"    <springStiffness>{robot.num(k)}</springStiffness>",
        f"    <springReference>{robot.num(rest)}</springReference>",
        "  </gazebo>",
    ]


#: what a URDF --into advice's inertia is
INERTIA_BASIS = (
    "about the joint axis at the zero pose, from the links' <inertial> as written (origin and rpy honoured), "
    "the other joints held at 0; pybullet uses it only when loaded with flags=p.URDF_USE_INERTIA_FROM_FILE "
    "(by default it recomputes inertia from the collision shapes)"
)
#: who reads what of a URDF joint: URDF has no joint spring, only the extension some hosts read
READERS = (
    "the spring is read by Gazebo (<gazebo> springStiffness/springReference) and Drake (a "
    "<drake:linear_bushing_rpy> on the joint axis, exact within half a turn of the rest); MuJoCo and "
    "pybullet load this joint as a pure damper (<dynamics damping>)",
    "for the spring in MuJoCo export mjcf --into the robot's MJCF; in pybullet apply -k (q - rest) as the "
    "joint's torque each step (README: Robot and system formats)",
)


def urdf_text(joint: Joint, *, rest: float = 0.0) -> tuple[str, dict[str, robot.StepAdvice]]:
    """A base link fixed to `world` and one moving link per axis, chained; damping declared, spring in
    the Gazebo and Drake extensions (springReference `rest`, rad or m).

    The base carries the flexure's clamped part (the first axis' link sphere): a URDF link of mass 0
    is dropped by Gazebo's converter (libsdformat), and with it every link and joint after it.
    """
    bodies, advice = robot.chain(joint)
    first = bodies[next(iter(joint.axes))]
    lines = ['<?xml version="1.0"?>', robot.provenance_comment(joint)]
    lines += [
        f'<robot name="{joint.name}" xmlns:drake="{urdf_drake.DRAKE_NS}">',
        "  " + robot.xml_comment("world: Gazebo, Drake and MuJoCo fix a joint to a link of that name"),
        '  <link name="world"/>',
        f'  <joint name="{joint.name}_fixed" type="fixed">',
        '    <parent link="world"/>',
        f'    <child link="{joint.name}_base"/>',
        "  </joint>",
        f'  <link name="{joint.name}_base">',
        "    " + robot.xml_comment("the flexure's clamped part: " + first.basis),
        *_inertial(first),
        "  </link>",
    ]
    parent = f"{joint.name}_base"
    for a, ac in joint.axes.items():
        si, name, s = ac.si(), f"{joint.name}_{a}", bodies[a]
        rot = units.is_rotational(a)
        limit = (
            ""
            if rot
            else f'\n    <limit lower="{-PRISMATIC_LIMIT}" upper="{PRISMATIC_LIMIT}" effort="1e9" '
            'velocity="1e9"/>'
        )
        lines += [
            "  " + robot.xml_comment(f"{name}: {advice[name].text()}"),
            f'  <joint name="{name}" type="{"continuous" if rot else "prismatic"}">',
            f'    <parent link="{parent}"/>',
            f'    <child link="{name}_link"/>',
            f'    <axis xyz="{robot.AXIS_VECTORS[a]}"/>{limit}',
            f'    <dynamics damping="{robot.num(si["c"])}" friction="0"/>',
            "  </joint>",
            *_gazebo(name, si["k"], rest),
            *urdf_drake.bushing_lines(
                name,
                parent=parent,
                child=f"{name}_link",
                axis=[float(v) for v in robot.AXIS_VECTORS[a].split()],
                k=si["k"],
                rest=rest,
                prismatic=not rot,
            ),
            f'  <link name="{name}_link">',
            "    " + robot.xml_comment(s.basis + "; the collision sphere has the same inertia"),
            *_inertial(s),
            "  </link>",
        ]
        parent = f"{name}_link"
    return "\n".join([*lines, "</robot>", ""]), advice


def _inertial(s: robot.Sphere) -> list[str]:
    """A link's `<inertial>` (about its origin, the joint's) and a collision sphere of the same inertia."""
    i = robot.num(s.inertia)
    return [
        "    <inertial>",
        '      <origin xyz="0 0 0" rpy="0 0 0"/>',
        f'      <mass value="{robot.num(s.mass)}"/>',
        f'      <inertia ixx="{i}" ixy="0" ixz="0" iyy="{i}" iyz="0" izz="{i}"/>',
        "    </inertial>",
        f'    <collision><geometry><sphere radius="{robot.num(s.radius)}"/></geometry></collision>',
    ]


def sdf_text(joint: Joint) -> tuple[str, dict[str, robot.StepAdvice]]:
    """SDFormat 1.7: the same chain, fixed to the world, with spring_stiffness/spring_reference/damping."""
    bodies, advice = robot.chain(joint)
    lines = ['<?xml version="1.0"?>', robot.provenance_comment(joint), '<sdf version="1.7">']
    lines += [f'  <model name="{joint.name}">', f'    <link name="{joint.name}_base"/>']
    lines += [
        f'    <joint name="{joint.name}_fixed" type="fixed">',
        f"      <parent>world</parent><child>{joint.name}_base</child>",
        "    </joint>",
    ]
    parent = f"{joint.name}_base"
    for a, ac in joint.axes.items():
        si, name, s = ac.si(), f"{joint.name}_{a}", bodies[a]
        i = robot.num(s.inertia)
        lines += [
            "    " + robot.xml_comment(f"{name}: {advice[name].text()}"),
            f'    <joint name="{name}" type="{"revolute" if units.is_rotational(a) else "prismatic"}">',
            f"      <parent>{parent}</parent><child>{name}_link</child>",
            f"      <axis><xyz>{robot.AXIS_VECTORS[a]}</xyz>",
            f"        <dynamics><damping>{robot.num(si['c'])}</damping><friction>0</friction>"
            f"<spring_reference>0</spring_reference><spring_stiffness>{robot.num(si['k'])}</spring_stiffness>"
            "</dynamics>",
            "      </axis>",
            "    </joint>",
            f'    <link name="{name}_link">',
            "      " + robot.xml_comment(s.basis + "; the collision sphere has the same inertia"),
            f"      <inertial><mass>{robot.num(s.mass)}</mass>",
            f"        <inertia><ixx>{i}</ixx><ixy>0</ixy><ixz>0</ixz><iyy>{i}</iyy><iyz>0</iyz><izz>{i}</izz>"
            "</inertia>",
            "      </inertial>",
            f'      <collision name="{name}_sphere"><geometry><sphere><radius>{robot.num(s.radius)}</radius>'
            "</sphere></geometry></collision>",
            "    </link>",
        ]
        parent = f"{name}_link"
    return "\n".join([*lines, "  </model>", "</sdf>", ""]), advice


def _host_values(root, element, joint_name: str) -> dict[str, float]:
    """The joint's damping and Gazebo spring as the host URDF gives them (URDF's default damping 0)."""
    dynamics = element.find("dynamics")
    old = {"damping": float(dynamics.get("damping", 0)) if dynamics is not None else 0.0}
    for tag in ("springStiffness", "springReference"):
        found = root.xpath(f"/robot/gazebo[@reference=$n]/{tag}", n=joint_name)
        if found:
            old[tag] = float(found[0].text)
    return old


def _span(element) -> tuple[float, float] | None:
    """A revolute or prismatic URDF joint's `<limit lower upper>` (URDF's defaults 0); None for a
    continuous joint, which has no range."""
    if element.get("type") == "continuous":
        return None
    limit = element.find("limit")
    get = (lambda n: 0.0) if limit is None else (lambda n: float(limit.get(n, 0)))
    return get("lower"), get("upper")


def _into_urdf(
    joint: Joint,
    host: Path,
    *,
    joint_name: str,
    axis: str | None,
    rest: float | None,
    allow_outside_range: bool = False,
) -> tuple[bytes, dict[str, robot.StepAdvice], tuple[str, ...]]:
    """The host URDF's bytes with `joint_name`'s damping and Gazebo spring set, the rest as written;
    the joint's step advice (none when the links it moves declare no inertia); one note per host
    value changed or kept (old -> new, SI). `rest` None keeps the host's springReference (else 0)
    when it lies inside the joint's limits, else takes the limits' nearest value (stated); a given
    `rest` outside them is refused unless `allow_outside_range`, as in MJCF."""
    from lxml import etree

    if not host.is_file():
        raise DesignerError(f"into={str(host)!r} does not exist", "give the path of the robot's URDF file")
    try:
        tree = etree.parse(str(host))
    except etree.XMLSyntaxError as exc:
        raise DesignerError(f"into={str(host)!r} is not XML: {exc}", "give a URDF file") from None
    root = tree.getroot()
    found = root.xpath("/robot/joint[@name=$n]", n=joint_name)
    kinds = {"revolute": True, "continuous": True, "prismatic": False}
    if len(found) != 1 or found[0].get("type") not in kinds:
        have = [j.get("name") for j in root.xpath("/robot/joint") if j.get("type") in kinds]
        raise DesignerError(
            f"joint_name={joint_name!r}: the robot has no revolute, continuous or prismatic joint so named",
            f"its movable joints are: {', '.join(have) or 'none'}",
        )
    rot = kinds[found[0].get("type")]
    a = robot.pick_axis(joint, axis, rot)
    if units.is_rotational(a) != rot:
        raise DesignerError(
            f"axis={a!r} does not match the kind of robot joint '{joint_name}' ({found[0].get('type')})",
            "give an axis of the same kind as the robot joint",
        )
    si = joint.axes[a].si()
    old = _host_values(root, found[0], joint_name)
    notes = []
    span, unit = _span(found[0]), "rad" if rot else "m"
    if rest is None:
        host_rest = old.get("springReference", 0.0)
        rest, moved = robot.rest_inside(host_rest, span, unit, "springReference")
        how = "kept at the host's" if "springReference" in old else "set to"
        notes.append(moved or f"springReference {how} {rest:.4g} (give rest to set it)")
    else:
        robot.check_rest(rest, span, joint_name, unit, allow_outside_range)
    new = {"damping": si["c"], "springStiffness": si["k"], "springReference": rest}
    notes += [
        f"{tag}: {'none' if tag not in old else format(old[tag], '.4g')} -> {v:.4g} (SI)"
        for tag, v in new.items()
        if v != old.get(tag)
    ]
    encoding = tree.docinfo.encoding or "utf-8"
    # the robot-level <joint> among every element <joint name=...> (a <transmission> names its joint too)
    nth = [j.getparent() is root for j in root.iter("joint") if j.get("name") == joint_name].index(True)
    text = _set_damping(host.read_bytes().decode(encoding), joint_name, robot.num(si["c"]), nth)
    moved = moved_inertia(root, joint_name)
    advice = {joint_name: step_advice(si["k"], si["c"], moved, basis=INERTIA_BASIS)} if moved > 0 else {}
    text = _set_spring(text, joint_name, si["k"], rest)
    text = _add_drake_spring(text, root, found[0], si["k"], rest, prismatic=not rot)
    return text.encode(encoding), advice, tuple(notes)


def _add_drake_spring(text: str, root, element, k: float, rest: float, *, prismatic: bool) -> str:
    """`text` with the Drake bushing of joint `element` before `</robot>` (and Drake's namespace
    declared on `<robot>` when it is not)."""
    name = element.get("name")
    if root.xpath("/robot/frame[@name=$n]", n=f"{name}_spring_A"):
        raise DesignerError(
            f"the robot already has Drake spring frames for joint '{name}' (an earlier export?)",
            "export into the robot file as it was before",
        )
    lines = urdf_drake.bushing_lines(
        name, k=k, rest=rest, prismatic=prismatic, **urdf_drake.joint_geometry(element)
    )
    end = text.rindex("</robot")
    text = f"{text[:end].rstrip()}\n" + "\n".join(lines) + f"\n{text[end:]}"
    if root.nsmap.get("drake") is None:
        start = xmltext.find_one(text, "robot", "name", root.get("name"))
        text = (
            text[: start.start()]
            + xmltext.set_attributes(start.group(0), {"xmlns:drake": urdf_drake.DRAKE_NS})
            + text[start.end() :]
        )
    return text


def _set_damping(text: str, joint_name: str, damping: str, nth: int) -> str:
    """The joint element's `<dynamics damping>` set (a `<dynamics>` line added when it has none);
    the element is the `nth` <joint name=joint_name> of the text (the robot-level one)."""
    element = xmltext.find_one(text, "joint", "name", joint_name, whole=True, nth=nth)
    body = element.group(0)
    dynamics = re.search(r"<dynamics\b[^>]*>", body)
    if dynamics:
        body = (
            body[: dynamics.start()]
            + xmltext.set_attributes(dynamics.group(0), {"damping": damping})
            + body[dynamics.end() :]
        )
    else:
        close = body.rindex("</joint")
        pad = xmltext.indent_before(text, element.start())
        body = f'{body[:close].rstrip()}\n{pad}  <dynamics damping="{damping}"/>\n{pad}{body[close:]}'
    return text[: element.start()] + body + text[element.end() :]


def _set_spring(text: str, joint_name: str, k: float, rest: float) -> str:
    """The Gazebo extension's springStiffness/springReference set: in the joint's block, or a new block."""
    try:
        block = xmltext.find_one(text, "gazebo", "reference", joint_name, whole=True)
    except DesignerError:
        block = None
    values = {"springStiffness": robot.num(k), "springReference": robot.num(rest)}
    if block is not None and all(f"<{tag}>" in block.group(0) for tag in values):
        body = block.group(0)
        for tag, value in values.items():
            body = re.sub(rf"<{tag}>.*?</{tag}>", f"<{tag}>{value}</{tag}>", body, count=1, flags=re.S)
        return text[: block.start()] + body + text[block.end() :]
    if block is not None and any(f"<{tag}>" in block.group(0) for tag in values):
        raise DesignerError(
            f"the robot's <gazebo reference='{joint_name}'> has one of springStiffness/springReference",
            "give both or neither",
        )
    end = text.rindex("</robot")
    lines = "\n".join(_gazebo(joint_name, k, rest))
    return f"{text[:end].rstrip()}\n{lines}\n{text[end:]}"


def _mujoco_check(
    host: Path, path: Path, data: bytes, joint_name: str, package_paths: Mapping[str, str | Path] | None
) -> tuple[str, ...]:
    """Compile the host URDF and its edited copy (`data`, to be written at `path`) in MuJoCo and raise
    unless only the joint's damping differs; the note saying so, or why MuJoCo could not check it."""
    from lxml import etree

    try:
        before = mujoco_urdf(host, package_paths)
    except DesignerError as exc:
        if packages_named(host.read_text(errors="replace")) and "package://" in exc.problem:
            return (f"not checked in MuJoCo: {exc}",)
        if "MuJoCo cannot load" in exc.problem:
            return (f"not checked in MuJoCo: {exc.problem}",)
        raise
    encoding = etree.fromstring(data).getroottree().docinfo.encoding or "utf-8"
    after = mujoco_urdf(path, package_paths, data.decode(encoding))
    changed = compiled_changes(before, after, joint_name, {"dof_damping": "dof"})
    if changed:
        raise RuntimeError(f"MuJoCo reads more than {joint_name}'s damping changed: {', '.join(changed)}")
    damping = float(after.joint(joint_name).damping[0])
    return (
        f"checked in MuJoCo: {joint_name} damping {damping:.4g} (SI), every other compiled value as the "
        "host's",
    )


def export_urdf(
    joint: Joint,
    path: str | Path,
    *,
    into: str | Path | None = None,
    joint_name: str | None = None,
    axis: str | None = None,
    rest: float | None = None,
    allow_outside_range: bool = False,
    package_paths: Mapping[str, str | Path] | None = None,
) -> robot.RobotExport:
    """Write `joint` as URDF at `path` (.urdf) and return the path and the stated step advice.

    Standalone: a chain of links with real masses (see `urdf_text`), every spring at `rest`. With
    `into` (a URDF file) and
    `joint_name`: a copy of that robot with the joint's damping set and a Gazebo spring extension
    (stiffness, and `rest` in rad or m as springReference: None keeps the host's when it lies inside
    the joint's limits; outside them a given rest is refused unless `allow_outside_range`); its links
    are left as they are (URDF has no armature, so the flexure's own moving inertia is not added).
    The advice uses the inertia the joint moves according to the links' `<inertial>` (see `urdf_inertia`).
    MuJoCo, which reads URDF damping, then compiles the host and the copy and must see only that
    damping change; `package_paths` ({package name: folder}) resolves `package://` file names for it
    (see `urdf_packages`). A host MuJoCo cannot load is written unchecked, and the notes say why.

    Raises:
        DesignerError: a wrong suffix, a missing mass, or an `into` problem.
    """
    path = check_suffix(path, (".urdf",), what="a URDF")
    check_joint(joint)
    if into is not None:
        joint_name = robot.robot_joint_name(joint_name)
        data, advice, notes = _into_urdf(
            joint,
            Path(into),
            joint_name=joint_name,
            axis=axis,
            rest=rest,
            allow_outside_range=allow_outside_range,
        )
        checked = _mujoco_check(Path(into), path, data, joint_name, package_paths)
        with atomic_path(path) as tmp:
            tmp.write_bytes(data)
        return robot.RobotExport(path, advice, notes + checked + READERS)
    text, advice = urdf_text(robot.with_masses(joint), rest=rest or 0.0)
    with atomic_write(path) as fh:
        fh.write(text)
    return robot.RobotExport(path, advice, READERS)


def export_sdf(joint: Joint, path: str | Path) -> robot.RobotExport:
    """Write `joint` as an SDFormat 1.7 model at `path` (.sdf); see `sdf_text`.

    Raises:
        DesignerError: a wrong suffix or a missing mass.
    """
    path = check_suffix(path, (".sdf",), what="an SDFormat")
    check_joint(joint)
    text, advice = sdf_text(robot.with_masses(joint))
    with atomic_write(path) as fh:
        fh.write(text)
    return robot.RobotExport(path, advice)
