"""Host values MuJoCo derives from the mass matrix, which an export's added inertia (the flexure's
armature in parallel, the motor body in series) would silently change: a joint's `springdamper`
(stiffness and damping) and a position actuator's `dampratio` (its damping gain). The exports write
them out as the host compiled them, and say so.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import DesignerError
from . import robot, xmltext
from .mjcf_host import Host


def freeze_springdampers(host: Host, joint_name: str) -> list[str]:
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


@dataclass(frozen=True)
class ResolvedGain:
    """A `dampratio` actuator written out with the damping gain the host compiled: its element's tag
    and name, the attributes to set and to drop, and what changed in words."""

    tag: str
    name: str
    values: dict[str, str]
    drop: tuple[str, ...]
    said: str


def dampratio_gains(host: Host) -> list[ResolvedGain]:
    """Every actuator whose damping gain MuJoCo derives from `dampratio` (an affine bias whose third
    parameter is positive), resolved to the gain the host compiled: `kv` on a `<position>`, the third
    `biasprm` on a `<general>`.

    Raises:
        DesignerError: such an actuator is unnamed, not written in the host file, or of another kind.
    """
    import mujoco

    out = []
    for i, act in enumerate(host.spec.actuators):
        if act.biastype != mujoco.mjtBias.mjBIAS_AFFINE or act.biasprm[2] <= 0:
            continue
        found = host.tree.getroot().xpath("//actuator/*[@name=$n]", n=act.name) if act.name else []
        if len(found) != 1 or found[0].tag not in ("position", "general"):
            raise DesignerError(
                f"actuator {act.name or i} takes its damping from dampratio, which the flexure's inertia "
                "would change, and designer cannot write it out (unnamed, from an <include>, or not a "
                "<position> or <general>)",
                "name it in the robot's file, or give it kv in place of dampratio",
            )
        kv = -float(host.model.actuator_biasprm[i][2])
        ratio = float(act.biasprm[2])
        if found[0].tag == "position":
            values, drop = {"kv": robot.num(kv)}, ("dampratio",)
        else:
            bias = [float(v) for v in act.biasprm]
            bias[2] = -kv
            while len(bias) > 3 and bias[-1] == 0:
                bias.pop()
            values, drop = {"biasprm": " ".join(robot.num(v) for v in bias)}, ()
        out.append(
            ResolvedGain(
                found[0].tag, act.name, values, drop, f"{act.name} dampratio {ratio:.4g} -> kv {kv:.4g}"
            )
        )
    return out


def gains_note(gains: list[ResolvedGain], cause: str) -> list[str]:
    """The note saying which dampratio actuators keep their compiled damping gain, and why."""
    if not gains:
        return []
    return [
        f"{len(gains)} actuator(s) with dampratio keep the damping gain the host compiled, now written as "
        f"kv (SI; MuJoCo derives it from the mass matrix, which {cause} changes): "
        + ", ".join(g.said for g in gains)
    ]


def gains_into_tree(host: Host, gains: list[ResolvedGain]) -> None:
    """Write the resolved gains into the host's XML tree (the series edit)."""
    for g in gains:
        element = host.tree.getroot().xpath("//actuator/*[@name=$n]", n=g.name)[0]
        for attr in g.drop:
            element.attrib.pop(attr, None)
        for attr, value in g.values.items():
            element.set(attr, value)


def gains_into_text(text: str, gains: list[ResolvedGain]) -> str:
    """`text` with each resolved actuator's start tag edited, every other byte as written (parallel)."""
    for g in gains:
        m = xmltext.find_one(text, g.tag, "name", g.name)
        tag = xmltext.set_attributes(xmltext.remove_attributes(m.group(0), g.drop), g.values)
        text = text[: m.start()] + tag + text[m.end() :]
    return text
