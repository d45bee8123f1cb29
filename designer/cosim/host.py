"""What a co-simulation does to the robot's own model around a flexible joint, each change stated.

A flexible joint in co-simulation owns its joint: the motor is the scenario's ideal position source
and the flexure's torque is the only drive on the link. So a host actuator on that joint (a servo
holding the link where the robot's own controller would, as in MuJoCo Menagerie's arms) is taken out,
and its removal is stated; one that reaches the joint through a tendon cannot be taken apart from its
other joints and is refused with the reason. The host's integrator is kept unless the scenario names
one, and a change is stated.
"""

from __future__ import annotations

from collections.abc import Sequence

from ..errors import DesignerError
from .robot import INTEGRATORS


def integrator_name(spec) -> str:
    """The integrator a MuJoCo spec's `<option>` gives, by the scenario's name for it."""
    import mujoco

    return {getattr(mujoco.mjtIntegrator, f"mjINT_{n.upper()}"): n for n in INTEGRATORS}[
        spec.option.integrator
    ]


def host_integrator(spec, requested: str | None) -> tuple[str, tuple[str, ...]]:
    """The integrator to run: `requested` (the scenario's), else the robot's own; with a note when the
    scenario changes the robot's."""
    own = integrator_name(spec)
    if requested is None or requested == own:
        return own, ()
    return requested, (
        f"integrator: the robot's {own} -> {requested} (the scenario's [simulation] integrator)",
    )


def _describe(act) -> str:
    """An actuator's kind and gains in a few words (SI)."""
    import mujoco

    gain, bias = float(act.gainprm[0]), [float(v) for v in act.biasprm[:3]]
    if act.biastype == mujoco.mjtBias.mjBIAS_AFFINE and bias[1] != 0:
        return f"a servo, kp {-bias[1]:.4g}" + (f", kv {-bias[2]:.4g}" if bias[2] < 0 else "")
    return f"gain {gain:.4g}"


def take_host_actuators(spec, joints: Sequence[str]) -> tuple[str, ...]:
    """Delete from `spec` every actuator that drives one of the flexible `joints` directly; one note
    per actuator removed.

    Raises:
        DesignerError: an actuator drives such a joint through a tendon (it also moves other joints).
    """
    import mujoco

    owned = set(joints)
    tendon_joints = {
        t.name: {w.target.name for w in t.path if w.type == mujoco.mjtWrap.mjWRAP_JOINT}
        for t in spec.tendons
        if t.name
    }
    notes, remove = [], []
    for act in spec.actuators:
        label = act.name or f"#{len(remove)}"
        if act.trntype == mujoco.mjtTrn.mjTRN_JOINT and act.target in owned:
            remove.append(act)
            notes.append(
                f"the robot's actuator '{label}' ({_describe(act)}) drove joint '{act.target}', whose motor "
                "is now the scenario's ideal position source: removed, so the flexible joint alone drives "
                "the link"
            )
        elif act.trntype == mujoco.mjtTrn.mjTRN_TENDON and owned & tendon_joints.get(act.target, set()):
            joint = sorted(owned & tendon_joints[act.target])[0]
            raise DesignerError(
                f"the robot's actuator '{label}' drives joint '{joint}' through tendon '{act.target}', which "
                "also moves other joints: the flexible joint cannot own that joint",
                "make another joint flexible, or take the actuator out of the robot's model",
            )
    if remove:
        import numpy as np

        gone = [i for i, act in enumerate(spec.actuators) if any(act is r for r in remove)]
        for key in spec.keys:  # a keyframe's ctrl lists every actuator: drop the removed ones
            ctrl = np.array(key.ctrl, dtype=float)
            if ctrl.size == len(spec.actuators):
                key.ctrl = np.delete(ctrl, gone)
        for act in remove:
            spec.delete(act)
    return tuple(notes)
