"""The inertia a URDF joint moves: its child link and every link after it, the other joints held at 0.

URDF places each joint frame in its parent link's frame (`<origin xyz rpy>`, rpy as fixed-axis roll,
pitch, yaw: R = Rz(yaw) Ry(pitch) Rx(roll)), the child link's frame on the joint frame, and each link's
`<inertial>` in the link frame. About a revolute axis a through the joint origin, a link of mass m,
centre c and central inertia I (both in the joint frame) adds a.I.a + m |c - (c.a) a|^2 (parallel
axes); along a prismatic axis the subtree's masses add.
"""

from __future__ import annotations

from collections import defaultdict

import numpy as np


def _vector(text: str | None, default: tuple[float, ...]) -> np.ndarray:
    return np.array([float(v) for v in text.split()] if text else default, dtype=float)


def _frame(element) -> np.ndarray:
    """The 4x4 transform of an element's `<origin>` (identity when absent)."""
    origin = element.find("origin")
    xyz = _vector(None if origin is None else origin.get("xyz"), (0.0, 0.0, 0.0))
    roll, pitch, yaw = _vector(None if origin is None else origin.get("rpy"), (0.0, 0.0, 0.0))
    cr, sr, cp, sp, cy, sy = (
        np.cos(roll),
        np.sin(roll),
        np.cos(pitch),
        np.sin(pitch),
        np.cos(yaw),
        np.sin(yaw),
    )
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    out = np.eye(4)
    out[:3, :3], out[:3, 3] = rz @ ry @ rx, xyz
    return out


def _link_term(inertial, frame: np.ndarray, axis: np.ndarray, revolute: bool) -> float:
    """One link's contribution about (revolute) or along (prismatic) `axis` through the origin."""
    mass_el = inertial.find("mass")
    mass = float(mass_el.get("value")) if mass_el is not None else 0.0
    if not revolute:
        return mass
    at = frame @ _frame(inertial)
    i = inertial.find("inertia")
    get = (lambda n: float(i.get(n, 0.0))) if i is not None else (lambda n: 0.0)
    central = np.array(
        [
            [get("ixx"), get("ixy"), get("ixz")],
            [get("ixy"), get("iyy"), get("iyz")],
            [get("ixz"), get("iyz"), get("izz")],
        ]
    )
    rotation, centre = at[:3, :3], at[:3, 3]
    off_axis = centre - (centre @ axis) * axis
    return float(axis @ rotation @ central @ rotation.T @ axis + mass * off_axis @ off_axis)


def moved_inertia(root, joint_name: str) -> float:
    """Inertia (kg.m^2, revolute/continuous) or mass (kg, prismatic) joint `joint_name` moves in the
    URDF tree `root` (an lxml or ElementTree `<robot>` element), the other joints at 0."""
    joints = {j.get("name"): j for j in root.findall("joint")}
    links = {link.get("name"): link for link in root.findall("link")}
    children = defaultdict(list)
    for j in joints.values():
        children[j.find("parent").get("link")].append(j)
    joint = joints[joint_name]
    axis = _vector(None if joint.find("axis") is None else joint.find("axis").get("xyz"), (1.0, 0.0, 0.0))
    axis = axis / np.linalg.norm(axis)
    revolute = joint.get("type") in ("revolute", "continuous")
    total, stack = 0.0, [(joint.find("child").get("link"), np.eye(4))]
    while stack:
        name, frame = stack.pop()
        inertial = links[name].find("inertial") if name in links else None
        if inertial is not None:
            total += _link_term(inertial, frame, axis, revolute)
        stack += [(j.find("child").get("link"), frame @ _frame(j)) for j in children[name]]
    return total
