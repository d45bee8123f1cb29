"""Make one joint of the user's MJCF robot a flexible joint: in parallel (the joint itself becomes the
spring-damper) or in series (motor -> flexure -> link: a motor body is inserted before the link).

The host file is edited with lxml at the element level, so comments, layout, units and every other
element stay as written; values go in the host's angle unit. The edited file is compiled by MuJoCo
from beside the output (relative asset paths must still resolve) and checked against the host's own
compiled model before it replaces the output: in parallel, only that joint's numbers and what MuJoCo
derives from the mass matrix may differ; in series, every host body keeps its world pose at the
reference configuration and every other joint its numbers.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import units
from ..errors import DesignerError
from ..files import atomic_path
from ..joint import Joint
from . import robot
from .stability import StepAdvice, step_advice

#: compiled-model arrays that follow from the mass matrix, so they change with a joint's armature
_DERIVED = {"actuator_acc0", "body_invweight0", "dof_M0", "dof_invweight0", "tendon_invweight0"}
#: compiled-model arrays the parallel edit sets, per joint, degree of freedom or qpos entry
_EDITED = {"jnt_stiffness": "jnt", "dof_damping": "dof", "dof_armature": "dof", "qpos_spring": "qpos"}
#: body attributes that place a body in its parent's frame
_FRAME = ("pos", "quat", "euler", "axisangle", "xyaxes", "zaxis")


def _num(v: float) -> str:
    return repr(float(v))


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
        from lxml import etree

        declared = self.path.read_bytes().lstrip().startswith(b"<?xml")
        return etree.tostring(self.tree, xml_declaration=declared, encoding="utf-8")


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


def _write_checked(host: _Host, path: Path, check) -> object:
    """Write the edited tree beside `path`, compile it there, run `check(model)`, then rename."""
    import mujoco

    with atomic_path(path) as tmp:
        tmp.write_bytes(host.bytes())
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


def _compare_parallel(before, after, joint_name: str) -> None:
    """Raise if compiling the edited model changed anything but the joint and its mass-matrix terms."""
    j = after.joint(joint_name)
    index = {"jnt": j.id, "dof": j.dofadr[0], "qpos": j.qposadr[0]}
    changed = []
    for name in dir(before):
        a = getattr(before, name)
        if name.startswith("_") or not isinstance(a, np.ndarray) or name in _DERIVED:
            continue
        b = getattr(after, name)
        if a.shape == b.shape and name in _EDITED:
            a, b = np.delete(a, index[_EDITED[name]], axis=0), np.delete(b, index[_EDITED[name]], axis=0)
        if a.shape != b.shape or not np.array_equal(a, b, equal_nan=True):
            changed.append(name)
    changed += [g for g in ("opt", "vis") if repr(getattr(before, g)) != repr(getattr(after, g))]
    if changed:
        raise RuntimeError(f"editing one joint changed the compiled model's {', '.join(changed)}")


def _flexure(host: _Host, joint: Joint, a: str, rest: float) -> None:
    """Set the joint element's stiffness, damping, armature (moving inertia, if known) and springref."""
    si = joint.axes[a].si()
    values = {"stiffness": si["k"], "damping": si["c"], "springref": host.angle(rest)}
    if si["m"] is not None:
        values["armature"] = si["m"]
    for attr, v in values.items():
        host.element.set(attr, _num(v))


def into_parallel(
    joint: Joint, host: str | Path, path: Path, *, joint_name: str, axis: str | None = None, rest: float = 0.0
) -> dict[str, StepAdvice]:
    """Write a copy of MJCF `host` to `path` with robot joint `joint_name` made this flexible joint.

    Sets stiffness, damping, armature (the axis' moving mass, when known) and springref (`rest`, SI,
    written in the host's angle unit). Returns the step advice for the joint, with its inertia from
    the compiled model's mass matrix (other joints held, at the reference pose).

    Raises:
        DesignerError: no such host file or joint, a ball or free joint, an axis of the wrong kind.
    """
    h = _open(host, joint_name)
    a = _axis(joint, axis, h, joint_name)
    _flexure(h, joint, a, rest)
    after = _write_checked(h, path, lambda m: _compare_parallel(h.model, m, joint_name))
    si = joint.axes[a].si()
    return {
        joint_name: step_advice(si["k"], si["c"], _mass_diagonal(after)[after.joint(joint_name).dofadr[0]])
    }
