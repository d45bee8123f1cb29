"""Make one joint of the user's MJCF robot a flexible joint in parallel: the joint itself becomes the
spring-damper. Only the joint's start tag changes in the file's text (every other byte stays as
written, but for the host values the edit would otherwise change, see `mjcf_derived`). The edited
file is compiled by MuJoCo from beside the output (relative asset paths must still resolve) and
checked against the host's own compiled model before it replaces the output: only that joint's
numbers and what MuJoCo derives from the mass matrix may differ. Values go in the host's angle unit.
The series form: `mjcf_series`.
"""

from __future__ import annotations

from functools import partial
from pathlib import Path

from ..joint import Joint
from . import robot, xmltext
from .mjcf_derived import dampratio_gains, gains_into_text, gains_note
from .mjcf_host import (
    MASS_MATRIX_BASIS,
    Host,
    check_joint,
    compiled_changes,
    host_axis,
    mass_diagonal,
    open_host,
    springdamper_off,
    write_checked,
)
from .stability import StepAdvice, step_advice


def _compare_parallel(before, after, joint_name: str, k: float, c: float) -> None:
    """Raise if compiling the edited model changed anything but the joint and its mass-matrix terms."""
    changed = compiled_changes(before, after, joint_name)
    check_joint(after, joint_name, k, c)
    if changed:
        raise RuntimeError(f"editing one joint changed the compiled model's {', '.join(changed)}")


def _retag(text: str, joint_name: str, values: dict[str, str]) -> str:
    """`text` with only the start tag of joint `joint_name` changed: `values` set, all else as written."""
    m = xmltext.find_one(text, "joint", "name", joint_name)
    return text[: m.start()] + xmltext.set_attributes(m.group(0), values) + text[m.end() :]


def into_parallel(
    joint: Joint,
    host: str | Path,
    path: Path,
    *,
    joint_name: str,
    axis: str | None = None,
    rest: float | None = None,
    allow_outside_range: bool = False,
) -> tuple[dict[str, StepAdvice], tuple[str, ...]]:
    """Write a copy of MJCF `host` to `path` with robot joint `joint_name` made this flexible joint.

    Sets stiffness and damping; springref to `rest` (SI, the joint's qpos, written in the host's
    angle unit; None keeps the host's); armature to the axis' moving mass only where the host has
    none (a host armature, the motor's reflected inertia, is kept), and then the host's `dampratio`
    actuators' damping gains as it compiled them (see `mjcf_derived`). Returns the step advice for the
    joint (inertia from the compiled model's mass matrix, other joints held, at the reference pose)
    and one note per host value changed or kept (old -> new, SI).

    Raises:
        DesignerError: no such host file or joint, a ball or free joint, an axis of the wrong kind, a
            rest outside a limited joint's range (unless `allow_outside_range`).
    """
    h = open_host(host, joint_name)
    a = host_axis(joint, axis, h, joint_name)
    values, notes = _parallel_values(h, joint, a, joint_name, rest, allow_outside_range)
    for attr, v in values.items():
        h.element.set(attr, v)
    raw = h.path.read_bytes()
    encoding = h.tree.docinfo.encoding or "utf-8"
    text = _retag(raw.decode(encoding), joint_name, values)
    if "armature" in values:  # the mass matrix changes: dampratio gains are kept as compiled
        gains = dampratio_gains(h)
        text = gains_into_text(text, gains)
        notes += tuple(gains_note(gains, "the flexure's armature"))
    si = joint.axes[a].si()
    check = partial(_compare_parallel, h.model, joint_name=joint_name, k=si["k"], c=si["c"])
    after = write_checked(h, path, check, text.encode(encoding))
    dof = after.joint(joint_name).dofadr[0]
    inertia = mass_diagonal(after)[dof]
    return {joint_name: step_advice(si["k"], si["c"], inertia, basis=MASS_MATRIX_BASIS)}, notes


def _parallel_values(
    h: Host, joint: Joint, a: str, joint_name: str, rest: float | None, allow_outside_range: bool
) -> tuple[dict[str, str], tuple[str, ...]]:
    """The joint element's new attributes (host units) and the notes on every host value (SI)."""
    si = joint.axes[a].si()
    j = h.model.joint(joint_name)
    dof, adr = j.dofadr[0], j.qposadr[0]
    unit = "rad" if h.hinge else "m"
    old = {
        "stiffness": float(j.stiffness[0]),
        "damping": float(h.model.dof_damping[dof]),
        "springref": float(h.model.qpos_spring[adr]),
        "armature": float(h.model.dof_armature[dof]),
    }
    new = {"stiffness": si["k"], "damping": si["c"]}
    notes = []
    span = tuple(float(v) for v in h.model.jnt_range[j.id]) if h.model.jnt_limited[j.id] else None
    if rest is None:
        keys = {
            f"keyframe '{h.model.key(k).name or k}'": float(h.model.key_qpos[k][adr])
            for k in range(h.model.nkey)
        }
        rest, moved = robot.rest_inside(old["springref"], span, unit, "springref", keys)
        if moved is None:
            notes.append(f"springref kept at the host's {old['springref']:.4g} {unit} (give rest to set it)")
        else:
            notes.append(moved)
            new["springref"] = rest
    else:
        robot.check_rest(rest, span, joint_name, unit, allow_outside_range)
        new["springref"] = rest
    if old["armature"] > 0:
        notes.append(
            f"armature kept at the host's {old['armature']:.4g} (the motor's; the flexure's own moving "
            f"inertia {si['m'] if si['m'] is not None else 0:.3g} not added)"
        )
    elif si["m"] is not None:
        new["armature"] = si["m"]
    if float(h.model.qpos0[adr]) != 0.0:
        notes.append(
            f"rest is the joint's qpos, which this joint's ref puts at {float(h.model.qpos0[adr]):.4g} "
            f"{unit} in its reference pose"
        )
    notes += [f"{attr}: {old[attr]:.4g} -> {v:.4g} (SI)" for attr, v in new.items() if v != old[attr]]
    values = {attr: robot.num(h.angle(v) if attr == "springref" else v) for attr, v in new.items()}
    springdamper_off(h, joint_name, values, notes)
    return values, tuple(notes)
