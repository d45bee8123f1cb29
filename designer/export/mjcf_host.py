"""The user's MJCF robot as `export mjcf --into` opens it: its file, compiled model, spec and XML tree,
the joint to make flexible, and the steps both forms share (write beside the output and compile there,
the joint-space inertia, the joint's compiled k and c, a springdamper switched off).
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

#: compiled-model arrays that follow from the mass matrix, so they change with a joint's armature
#: (tendon_lengthspring follows the springref of the joints a fixed tendon couples, unless the host
#: gives the tendon's springlength, which the edit does not touch)
DERIVED = {
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
ASSET_NAMES = {"hfield_pathadr", "mesh_pathadr", "skin_pathadr", "tex_pathadr"}

#: compiled-model arrays the parallel edit sets, per joint, degree of freedom or qpos entry
EDITED = {"jnt_stiffness": "jnt", "dof_damping": "dof", "dof_armature": "dof", "qpos_spring": "qpos"}
#: what the advice's inertia is when it comes from the compiled robot
MASS_MATRIX_BASIS = (
    "about the joint axis: MuJoCo's joint-space inertia (armature included) at the reference pose qpos0, "
    "the other joints held"
)


@dataclass
class Host:
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


#: how to write a model with its <include>s merged, beside it (its meshes are found relative to it)
FLATTEN = (
    "in its folder, python -c \"import mujoco; open('{flat}', 'w').write(mujoco.MjSpec.from_file("
    "'{main}').to_xml())\", then export with into='{flat}'"
)


def defining_include(host: Path, joint_name: str) -> str | None:
    """The path (as the model writes it) of the file among `host`'s <include>s, followed
    recursively, that writes the joint `joint_name`; None if none does. MuJoCo resolves every
    include relative to the main file's folder."""
    from lxml import etree

    todo, seen = [host], {host.resolve()}
    while todo:
        for inc in etree.parse(str(todo.pop())).getroot().iter("include"):
            name = inc.get("file") or ""
            path = host.parent / name
            if not path.is_file() or path.resolve() in seen:
                continue
            seen.add(path.resolve())
            if etree.parse(str(path)).getroot().xpath("//joint[@name=$n]", n=joint_name):
                return name
            todo.append(path)
    return None


def open_host(host: str | Path, joint_name: str) -> Host:
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
        tree = etree.parse(str(host))
    except etree.XMLSyntaxError as exc:
        raise DesignerError(f"into={str(host)!r} is not XML ({exc})", "give the robot's MJCF file") from None
    if tree.getroot().tag == "robot":  # before MuJoCo, which may not find a URDF's package:// meshes
        raise DesignerError(
            f"into={str(host)!r} is a URDF: MuJoCo reads it, but designer writes MJCF into MJCF files only",
            f"export urdf with into={host.name!r}, or save it as MJCF first (MuJoCo's compile tool, or "
            "mujoco.MjSpec.from_file(...).to_xml())",
        )
    try:
        model = mujoco.MjModel.from_xml_path(str(host))
        spec = mujoco.MjSpec.from_file(str(host))
    except ValueError as exc:
        raise DesignerError(f"MuJoCo cannot load into={str(host)!r}: {exc}", "give an MJCF file") from None
    kinds = (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE)
    have = [j.name for j in spec.joints if j.type in kinds and j.name]
    if joint_name not in have:
        written = [j for j in tree.getroot().iter("joint") if j.get("name") == joint_name]
        if any(j.getparent().tag == "body" for j in written):  # written, yet compiled to no joint
            raise DesignerError(
                f"joint '{joint_name}' is written in {host.name} outside any <worldbody>: the file is a "
                "fragment that another model includes, and compiles to no body alone",
                "flatten the model that includes it: "
                + FLATTEN.format(main="MAIN.xml", flat="MAIN_flat.xml"),
            )
        raise DesignerError(
            f"joint_name={joint_name!r}: the robot has no hinge or slide joint of that name",
            f"its hinge and slide joints are: {', '.join(have) or 'none'}",
        )
    found = tree.getroot().xpath("//worldbody//body/joint[@name=$n]", n=joint_name)
    if len(found) != 1:
        where = defining_include(host, joint_name)
        flat = f"{host.stem}_flat.xml"
        raise DesignerError(
            f"joint '{joint_name}' is not written in {host.name} itself but in "
            f"{where or 'a file it includes'}: designer edits the file that writes the joint",
            f"flatten the model first: {FLATTEN.format(main=host.name, flat=flat)}",
        )
    hinge = spec.joint(joint_name).type == mujoco.mjtJoint.mjJNT_HINGE
    return Host(host, model, spec, tree, found[0], hinge)


def host_axis(joint: Joint, axis: str | None, host: Host, joint_name: str) -> str:
    a = robot.pick_axis(joint, axis, host.hinge)
    if units.is_rotational(a) != host.hinge:
        raise DesignerError(
            f"axis={a!r} is {'rotational' if units.is_rotational(a) else 'translational'} but robot joint "
            f"'{joint_name}' is a {'hinge' if host.hinge else 'slide'}",
            "give an axis of the same kind as the robot joint",
        )
    return a


def write_checked(host: Host, path: Path, check, data: bytes | None = None) -> object:
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


def mass_diagonal(model) -> np.ndarray:
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


def springdamper_off(host: Host, joint_name: str, values: dict[str, str], notes: list[str]) -> None:
    """Add springdamper="0 0" to `values` (and say so) when the host joint has one: MuJoCo would
    otherwise compute stiffness and damping from it and ignore the flexure's."""
    timeconst, ratio = (float(v) for v in host.spec.joint(joint_name).springdamper)
    if timeconst > 0:
        values["springdamper"] = "0 0"
        notes.append(
            f"springdamper (time constant {timeconst:.4g} s, damping ratio {ratio:.4g}) -> 0 0: MuJoCo would "
            "derive stiffness and damping from it in place of the flexure's"
        )


def check_joint(after, joint_name: str, k: float, c: float) -> None:
    """Raise unless MuJoCo compiled the edited joint with exactly stiffness `k` and damping `c`."""
    j = after.joint(joint_name)
    got = (float(j.stiffness[0]), float(after.dof_damping[j.dofadr[0]]))
    if got != (k, c):
        raise RuntimeError(f"joint {joint_name} compiled with stiffness, damping {got}, not {(k, c)}")


def compiled_changes(before, after, joint_name: str, edited: dict[str, str] | None = None) -> list[str]:
    """The compiled-model arrays (and options) that differ between `before` and `after`, leaving out
    joint `joint_name`'s entries of the `edited` arrays (default: the parallel edit's, `EDITED`), what
    MuJoCo derives from the mass matrix and where it stored asset file names."""
    edited = EDITED if edited is None else edited
    j = after.joint(joint_name)
    index = {"jnt": j.id, "dof": j.dofadr[0], "qpos": j.qposadr[0]}
    changed = []
    for name in dir(before):
        a = getattr(before, name)
        if name.startswith("_") or not isinstance(a, np.ndarray) or name in DERIVED | ASSET_NAMES:
            continue
        b = getattr(after, name)
        if a.shape == b.shape and name in edited:
            a, b = np.delete(a, index[edited[name]], axis=0), np.delete(b, index[edited[name]], axis=0)
        if a.shape != b.shape or not np.array_equal(a, b, equal_nan=True):
            changed.append(name)
    return changed + [g for g in ("opt", "vis") if repr(getattr(before, g)) != repr(getattr(after, g))]
