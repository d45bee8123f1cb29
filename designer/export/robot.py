"""Export a Joint as MJCF (MuJoCo) or URDF snippets: stiffness, damping and moving mass per axis, SI units."""

from __future__ import annotations

import json
from pathlib import Path
from xml.sax.saxutils import quoteattr

from .. import units
from ..files import atomic_write, check_suffix
from ..joint import Joint

#: the joint axis of each channel; the rotational ones follow roll (phi, x), pitch (theta, y), yaw (psi, z)
AXIS_VECTORS = {"x": "1 0 0", "y": "0 1 0", "z": "0 0 1", "phi": "1 0 0", "theta": "0 1 0", "psi": "0 0 1"}


def _comment(joint: Joint) -> str:
    text = json.dumps(joint.to_dict(), sort_keys=True, default=str).replace("--", "- -")
    return f"<!-- flexjoint designer: {text} -->"


def mjcf_text(joint: Joint) -> str:
    """A loadable MJCF model: one body carrying the joint's axes, moving mass as joint armature."""
    joints = []
    for a, ac in joint.axes.items():
        si = ac.si()
        kind = "hinge" if units.is_rotational(a) else "slide"
        armature = f' armature="{si["m"]!r}"' if si["m"] is not None else ""
        joints.append(
            f'      <joint name="{joint.name}_{a}" type="{kind}" axis="{AXIS_VECTORS[a]}" '
            f'stiffness="{si["k"]!r}" damping="{si["c"]!r}"{armature} springref="0"/>'
        )
    return "\n".join(
        [
            _comment(joint),
            f"<mujoco model={quoteattr(joint.name)}>",
            "  <!-- MJCF reads angles in degrees by default; these joints use radians -->",
            '  <compiler angle="radian"/>',
            "  <worldbody>",
            f'    <body name="{joint.name}_link">',
            "      <!-- the joint's moving mass is its armature; replace this placeholder inertial -->",
            '      <inertial pos="0 0 0" mass="1e-9" diaginertia="1e-12 1e-12 1e-12"/>',
            *joints,
            "    </body>",
            "  </worldbody>",
            "</mujoco>",
            "",
        ]
    )


def urdf_text(joint: Joint) -> str:
    """A URDF chain with one joint per axis; damping is declared, stiffness only stated (URDF has none)."""
    lines = ['<?xml version="1.0"?>', _comment(joint), f"<robot name={quoteattr(joint.name)}>"]
    lines.append(f'  <link name="{joint.name}_base"/>')
    parent = f"{joint.name}_base"
    for a, ac in joint.axes.items():
        si = ac.si()
        rot = units.is_rotational(a)
        child = f"{joint.name}_{a}_link"
        lines += [
            f"  <!-- URDF has no joint stiffness: add k = {si['k']!r} {units.si_unit('k', a)} "
            "on this joint in the simulator (a spring plugin or a controller) -->",
            f'  <joint name="{joint.name}_{a}" type="{"revolute" if rot else "prismatic"}">',
            f'    <parent link="{parent}"/>',
            f'    <child link="{child}"/>',
            f'    <axis xyz="{AXIS_VECTORS[a]}"/>',
            f'    <limit lower="{-3.14159 if rot else -0.01}" upper="{3.14159 if rot else 0.01}" '
            'effort="1000" velocity="100"/>',
            f'    <dynamics damping="{si["c"]!r}" friction="0"/>',
            "  </joint>",
            f'  <link name="{child}">',
        ]
        if si["m"] is not None:
            mass = si["m"] if not rot else 1e-9
            inertia = si["m"] if rot else 1e-12
            lines += [
                "    <inertial>",
                f'      <mass value="{mass!r}"/>',
                f'      <inertia ixx="{inertia!r}" ixy="0" ixz="0" iyy="{inertia!r}" iyz="0" '
                f'izz="{inertia!r}"/>',
                "    </inertial>",
            ]
        lines.append("  </link>")
        parent = child
    lines += ["</robot>", ""]
    return "\n".join(lines)


def export_robot(joint: Joint, path: str | Path, fmt: str) -> Path:
    """Write the MJCF ('mjcf') or URDF ('urdf') snippet atomically and return its path."""
    text = mjcf_text(joint) if fmt == "mjcf" else urdf_text(joint)
    path = check_suffix(path, (".xml", ".mjcf") if fmt == "mjcf" else (".urdf",), what=f"an {fmt.upper()}")
    with atomic_write(path) as fh:
        fh.write(text)
    return path


def export_mjcf(joint: Joint, path: str | Path) -> Path:
    """Write the joint as an MJCF model at `path` (atomically); returns the path."""
    return export_robot(joint, path, "mjcf")


def export_urdf(joint: Joint, path: str | Path) -> Path:
    """Write the joint as a URDF chain at `path` (atomically); returns the path."""
    return export_robot(joint, path, "urdf")
