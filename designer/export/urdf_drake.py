"""A URDF joint spring for Drake: its `drake:linear_bushing_rpy` extension element.

Drake's URDF parser reads no spring on a revolute or prismatic joint (only `<dynamics damping>`), but
it reads two Drake extensions at robot level: `<frame name link xyz rpy>` and
`<drake:linear_bushing_rpy>` (a bushing between two frames, with torque and force stiffness per
roll-pitch-yaw and x-y-z of the second frame relative to the first). With frame A on the parent at the
joint origin and frame C on the child, both turned so that their z axis is the joint axis, the
bushing's yaw (or z) stiffness k alone gives exactly -k (q - rest) on the joint: frame C is turned (or
moved) back by `rest`, so the two frames coincide at q = rest. A revolute bushing measures the angle as
a yaw in (-pi, pi], so it is exact within half a turn of the rest. The bushing's damping is left at 0:
the joint's own damping carries c.
"""

from __future__ import annotations

import numpy as np

from . import robot

#: the namespace Drake's parser expects for its extension elements
DRAKE_NS = "http://drake.mit.edu"


def _z_onto(axis: np.ndarray):
    """A rotation that turns z onto the unit vector `axis`, twisted about z so that its roll-pitch-yaw
    is clear of pitch +-90 deg (where the angles are not unique)."""
    import warnings

    from scipy.spatial.transform import Rotation

    z = np.array([0.0, 0.0, 1.0])
    base = (
        Rotation.from_rotvec([np.pi, 0.0, 0.0])
        if np.allclose(axis, -z)
        else Rotation.align_vectors([axis], [z])[0]
    )
    for twist in (0.0, np.pi / 2, np.pi / 4):
        r = base * Rotation.from_rotvec([0.0, 0.0, twist])
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            pitch = r.as_euler("xyz")[1]
        if abs(abs(pitch) - np.pi / 2) > 1e-3:
            return r
    raise AssertionError("no twist clears the pitch singularity")  # two of the three twists always do


def _rpy(rotation) -> str:
    return _triple(rotation.as_euler("xyz"))


def _triple(values) -> str:
    return " ".join(robot.num(float(v) + 0.0) for v in values)  # + 0.0: no "-0.0"


def bushing_lines(
    name: str,
    *,
    parent: str,
    child: str,
    origin_xyz=(0.0, 0.0, 0.0),
    origin_rpy=(0.0, 0.0, 0.0),
    axis=(1.0, 0.0, 0.0),
    k: float,
    rest: float,
    prismatic: bool,
    pad: str = "  ",
) -> list[str]:
    """The `<frame>`s and `<drake:linear_bushing_rpy>` that give joint `name` its spring in Drake.

    `origin_xyz`, `origin_rpy`, `axis` are the URDF joint's (its `<origin>` in the parent link, its
    `<axis>` in the joint frame, which is the child link's frame); k in N.m/rad or N/m, rest in rad or m.
    """
    from scipy.spatial.transform import Rotation

    a = np.asarray(axis, dtype=float)
    a = a / np.linalg.norm(a)
    to_axis = _z_onto(a)
    frame_a = Rotation.from_euler("xyz", origin_rpy) * to_axis
    if prismatic:
        frame_c, c_xyz = to_axis, -rest * a
        torque, force = (0.0, 0.0, 0.0), (0.0, 0.0, k)
    else:
        frame_c, c_xyz = to_axis * Rotation.from_rotvec([0.0, 0.0, -rest]), np.zeros(3)
        torque, force = (0.0, 0.0, k), (0.0, 0.0, 0.0)
    kind = "force along" if prismatic else "torque about"
    return [
        pad + robot.xml_comment(f"Drake reads the spring of {name} here: bushing {kind} z = the joint axis"),
        *(
            f'{pad}<frame name="{name}_spring_{end}" link="{link}" xyz="{_triple(xyz)}" rpy="{_rpy(rot)}"/>'
            for end, link, xyz, rot in (("A", parent, origin_xyz, frame_a), ("C", child, c_xyz, frame_c))
        ),
        f"{pad}<drake:linear_bushing_rpy>",
        f'{pad}  <drake:bushing_frameA name="{name}_spring_A"/>',
        f'{pad}  <drake:bushing_frameC name="{name}_spring_C"/>',
        f'{pad}  <drake:bushing_torque_stiffness value="{_triple(torque)}"/>',
        f'{pad}  <drake:bushing_torque_damping value="0 0 0"/>',
        f'{pad}  <drake:bushing_force_stiffness value="{_triple(force)}"/>',
        f'{pad}  <drake:bushing_force_damping value="0 0 0"/>',
        f"{pad}</drake:linear_bushing_rpy>",
    ]


def joint_geometry(element) -> dict[str, object]:
    """A URDF `<joint>` element's parent, child, origin and axis, URDF's defaults where absent."""
    origin, axis = element.find("origin"), element.find("axis")

    def triple(node, attr: str, default: tuple[float, float, float]) -> tuple[float, ...]:
        text = node.get(attr) if node is not None else None
        return tuple(float(v) for v in text.split()) if text else default

    return {
        "parent": element.find("parent").get("link"),
        "child": element.find("child").get("link"),
        "origin_xyz": triple(origin, "xyz", (0.0, 0.0, 0.0)),
        "origin_rpy": triple(origin, "rpy", (0.0, 0.0, 0.0)),
        "axis": triple(axis, "xyz", (1.0, 0.0, 0.0)),
    }
