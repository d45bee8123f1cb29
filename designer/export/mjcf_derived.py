"""Host values MuJoCo derives from the mass matrix, which an export's added inertia (the flexure's
armature in parallel, the motor body in series) would silently change: a joint's `springdamper`
(stiffness and damping) and a position actuator's `dampratio` (its damping gain). The exports write
them out as the host compiled them, and say so.
"""

from __future__ import annotations

from ..errors import DesignerError
from . import robot
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
