"""The robot side of a co-simulation: a MuJoCo model whose chosen joints are motor -> flexible joint -> link.

Each mapped joint's coordinate is the link's angle relative to its parent; the motor is an ideal
position source on the parent, so the flexible joint sees the deflection s = q - q_motor(t) and its
rate, and its torque acts on that coordinate. The same spring-damper can instead be computed inside
MuJoCo (a `general` actuator with affine bias) as the validation reference.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import DesignerError
from .references import Reference

INTEGRATORS = ("euler", "implicitfast", "implicit", "rk4")

#: default planar arm: link lengths (m) and masses (kg) of a small printed two-link arm
ARM_LENGTHS = (0.08, 0.06)
ARM_MASSES = (0.03, 0.02)


def planar_arm_xml(lengths: Sequence[float] = ARM_LENGTHS, masses: Sequence[float] = ARM_MASSES) -> str:
    """MJCF of an N-link arm in the vertical x-z plane: hinges j1..jN about y, links along x, gravity -z."""
    if len(lengths) != len(masses) or not lengths:
        raise DesignerError(
            f"the arm has {len(lengths)} link lengths and {len(masses)} link masses",
            "give one length and one mass per link",
        )
    for what, values in (("length", lengths), ("mass", masses)):
        if not all(np.isfinite(v) and v > 0 for v in values):
            raise DesignerError(f"every link {what} must be a positive number", f"got {list(values)}")
    body = ""
    for i, (length, mass) in reversed(list(enumerate(zip(lengths, masses, strict=True), start=1))):
        pos = f"{lengths[i - 2]:g} 0 0" if i > 1 else "0 0 0"
        inertia = mass * length**2 / 12.0
        body = (
            f'<body name="link{i}" pos="{pos}">'
            f'<joint name="j{i}" type="hinge" axis="0 1 0"/>'
            f'<inertial pos="{length / 2:g} 0 0" mass="{mass:g}" '
            f'diaginertia="{inertia * 1e-3:.9g} {inertia:.9g} {inertia:.9g}"/>'
            f'<geom type="capsule" fromto="0 0 0 {length:g} 0 0" size="0.005" contype="0" conaffinity="0"/>'
            f"{body}</body>"
        )
    return f'<mujoco model="planar_arm"><option gravity="0 0 -9.81"/><worldbody>{body}</worldbody></mujoco>'


def load_spec(path: str | Path | None = None, lengths=ARM_LENGTHS, masses=ARM_MASSES):
    """A MuJoCo spec from an MJCF or URDF file, or the built-in planar arm when `path` is None."""
    import mujoco

    if path is None:
        return mujoco.MjSpec.from_string(planar_arm_xml(lengths, masses))
    path = Path(path)
    if not path.is_file():
        raise DesignerError(f"robot model {path} does not exist", "give the path of an MJCF or URDF file")
    try:
        return mujoco.MjSpec.from_file(str(path))
    except Exception as exc:  # mujoco raises a bare ValueError with its parser message
        raise DesignerError(
            f"MuJoCo cannot load {path}: {exc}", "give an MJCF or URDF file MuJoCo reads"
        ) from None


def joint_names(spec) -> list[str]:
    """The names of the hinge and slide joints of a model, the ones a flexible joint can sit on."""
    import mujoco

    kinds = (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE)
    return [j.name for j in spec.joints if j.type in kinds and j.name]


def check_joints(spec, names: Sequence[str]) -> None:
    """Raise a DesignerError naming any joint the robot does not have."""
    have = joint_names(spec)
    for name in names:
        if name not in have:
            raise DesignerError(
                f"the robot has no joint '{name}'",
                f"its hinge and slide joints are: {', '.join(have) or 'none'}",
            )


def constraint_free(model) -> bool:
    """True if the compiled model can have no constraint: no equality, joint or tendon limit, friction
    loss, flex, or geom pair that may touch. MuJoCo's constraint stage then only costs time."""
    if model.neq or model.npair or model.nflex or model.ntendon:
        return False
    if np.any(model.jnt_limited) or np.any(model.dof_frictionloss > 0):
        return False
    return not (np.any(model.geom_contype) and np.any(model.geom_conaffinity))


def diverged(t: float) -> DesignerError:
    """The error for MuJoCo's bad-acceleration warning in the step from `t` (s): it reset the state."""
    return DesignerError(
        f"the robot diverged at t = {t:g} s (MuJoCo reset it)",
        "use a smaller step, or the gauss-seidel algorithm",
    )


@dataclass(frozen=True)
class SpringDamper:
    """The law computed in-engine for the reference: tau = -(k (s - offset) + c v), SI."""

    k: float
    c: float
    offset: float = 0.0


class Robot:
    """A MuJoCo robot stepped by the master: outputs `<joint>.s|v|q|motor`; inputs `<joint>.tau`."""

    feedthrough = False

    def __init__(
        self,
        spec,
        motors: Mapping[str, Reference],
        step: float,
        integrator: str = "euler",
        in_engine: Mapping[str, SpringDamper] | None = None,
    ) -> None:
        import mujoco

        check_joints(spec, list(motors))
        if integrator not in INTEGRATORS:
            raise DesignerError(f"unknown integrator '{integrator}'", f"use one of: {', '.join(INTEGRATORS)}")
        spec = spec.copy()
        spec.option.timestep = step
        spec.option.integrator = getattr(mujoco.mjtIntegrator, f"mjINT_{integrator.upper()}")
        self.in_engine = dict(in_engine or {})
        for name, law in self.in_engine.items():
            act = spec.add_actuator(
                name=f"flex_{name}",
                target=name,
                trntype=mujoco.mjtTrn.mjTRN_JOINT,
                gaintype=mujoco.mjtGain.mjGAIN_FIXED,
                biastype=mujoco.mjtBias.mjBIAS_AFFINE,
            )
            act.gainprm[0] = 1.0
            act.biasprm[1] = -law.k
            act.biasprm[2] = -law.c
            act.ctrllimited = mujoco.mjtLimited.mjLIMITED_FALSE
        self.model = spec.compile()
        if constraint_free(self.model):  # same result, 20 % less per step on the built-in arm
            self.model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT
        self.data = mujoco.MjData(self.model)
        self._mj_step = mujoco.mj_step
        self._bad = self.data.warning[mujoco.mjtWarning.mjWARN_BADQACC]
        self.joints = list(motors)
        self.motors = [motors[j] for j in self.joints]
        self.qpos = np.array([self.model.joint(j).qposadr[0] for j in self.joints])
        self.dof = np.array([self.model.joint(j).dofadr[0] for j in self.joints])
        self.actuators = [self.model.actuator(f"flex_{j}").id for j in self.in_engine]
        driven = [j for j in self.joints if j not in self.in_engine]
        self.inputs = [f"{j}.tau" for j in driven]
        self._input_dof = np.array([self.model.joint(j).dofadr[0] for j in driven], dtype=int)
        self.outputs = [f"{j}.{v}" for v in ("s", "v", "q", "motor") for j in self.joints]
        self.motor_q = np.zeros(len(self.joints))
        self.motor_v = np.zeros(len(self.joints))
        self.reset()

    def reset(self) -> None:
        """Back to t = 0 (mj_resetData, counters), each link undeflected where its motor puts it."""
        import mujoco

        mujoco.mj_resetData(self.model, self.data)
        self.time = 0.0
        self._steps = 0
        self._motor(0.0)
        # start undeflected: each link where its motor puts it, moving with it
        self.data.qpos[self.qpos] = self.motor_q
        self.data.qvel[self.dof] = self.motor_v

    def _motor(self, t: float) -> None:
        for i, ref in enumerate(self.motors):
            self.motor_q[i], self.motor_v[i] = ref(t)

    def get(self) -> np.ndarray:
        """Outputs in `self.outputs` order: deflections, their rates, joint angles, motor angles."""
        q = self.data.qpos[self.qpos]
        return np.concatenate([q - self.motor_q, self.data.qvel[self.dof] - self.motor_v, q, self.motor_q])

    def set(self, values: np.ndarray) -> None:
        """Inputs in `self.inputs` order: the flexible joints' torques on their links (N.m or N)."""
        self.data.qfrc_applied[self._input_dof] = values

    def do_step(self, h: float) -> None:
        """Advance one physics step (h must be the model's timestep), then move the motors to t + h."""
        for i, (j, law) in enumerate(self.in_engine.items()):
            k = self.joints.index(j)
            self.data.ctrl[self.actuators[i]] = (
                law.k * (self.motor_q[k] + law.offset) + law.c * self.motor_v[k]
            )
        self._mj_step(self.model, self.data)
        if self._bad.number:
            raise diverged(self.time)
        self._steps += 1
        self.time = self._steps * h
        self._motor(self.time)
