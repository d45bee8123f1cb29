"""The robot side of a co-simulation: a MuJoCo model whose chosen joints are motor -> flexible joint -> link.

Each mapped joint's coordinate is the link's angle relative to its parent; the motor is an ideal
position source on the parent, so the flexible joint sees the deflection s = q - q_motor(t) and its
rate, and its torque acts on that coordinate. The same spring-damper can instead be computed inside
MuJoCo (a `general` actuator with affine bias) as the validation reference.
"""

from __future__ import annotations

import ctypes
from collections.abc import Mapping, Sequence
from ctypes import POINTER, c_double, c_int32, c_int64, c_void_p
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import DesignerError
from . import binding as kb
from .references import Reference
from .twin import Twin

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


def _urdf_text(path: Path, package_paths: Mapping[str, str | Path] | None) -> str:
    """A URDF's text with its file names resolved (see `designer.export.urdf_packages`).

    Raises:
        DesignerError: a package the URDF names that `package_paths` does not.
    """
    from ..export.urdf_packages import packages_named, resolved_urdf

    missing = sorted(packages_named(path.read_text(errors="replace")) - set(package_paths or {}))
    if missing:
        raise DesignerError(
            f"robot model {path.name} names files by package://{missing[0]}/..., which MuJoCo cannot resolve",
            f'give the package\'s folder: [robot] package_paths = {{ {missing[0]} = "DIR" }} in a scenario '
            "file (package_paths= in Python), as ROS's package path would",
        )
    return resolved_urdf(path, package_paths)


def load_spec(
    path: str | Path | None = None,
    lengths=ARM_LENGTHS,
    masses=ARM_MASSES,
    package_paths: Mapping[str, str | Path] | None = None,
):
    """A MuJoCo spec from an MJCF or URDF file, or the built-in planar arm when `path` is None.

    A URDF's `package://NAME/` file names resolve against `package_paths[NAME]` (a folder), as ROS's
    package path would (see `designer.export.urdf_packages`); MuJoCo knows no packages.
    """
    import mujoco

    if path is None:
        return mujoco.MjSpec.from_string(planar_arm_xml(lengths, masses))
    path = Path(path)
    if not path.is_file():
        raise DesignerError(f"robot model {path} does not exist", "give the path of an MJCF or URDF file")
    try:
        if path.suffix.lower() == ".urdf":
            return mujoco.MjSpec.from_string(_urdf_text(path, package_paths))
        return mujoco.MjSpec.from_file(str(path))
    except DesignerError:
        raise
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


#: a host joint's own parallel elements the flexible joint replaces: (MjSpec attribute, SI unit of a
#: hinge, of a slide)
HOST_ELEMENTS = (
    ("stiffness", "N.m/rad", "N/m"),
    ("damping", "N.m.s/rad", "N.s/m"),
    ("armature", "kg.m^2", "kg"),
)


def free_host_joints(spec, names: Sequence[str]) -> tuple[str, ...]:
    """Zero the stiffness, damping and armature the host model gives the joints `names` (in `spec`),
    since the flexible joint takes their place; returns one note per joint changed (old -> 0, SI)."""
    import mujoco

    notes = []
    for name in names:
        joint = spec.joint(name)
        hinge = joint.type == mujoco.mjtJoint.mjJNT_HINGE
        changed = []
        for attr, hinge_unit, slide_unit in HOST_ELEMENTS:
            value = getattr(joint, attr)  # newer MuJoCo: stiffness, damping as coefficient arrays
            old = np.array(value, dtype=float)  # a copy: the spec writes through its arrays
            if np.any(old != 0.0):
                setattr(joint, attr, np.zeros_like(old) if old.ndim else 0.0)
                changed.append(f"{attr} {old.ravel()[0]:.4g} -> 0 {hinge_unit if hinge else slide_unit}")
        if changed:
            notes.append(
                f"the robot's joint '{name}' had its own {', '.join(changed)}: the flexible joint replaces "
                f"them (keep_host = true in [joints.{name}] keeps them in parallel)"
            )
    return tuple(notes)


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
    """The joint's law computed inside MuJoCo (the validation reference and the sweeps' in-engine
    path): tau = -(k (s - offset) + c v), SI, with s = q - q_motor and v = q' - q_motor' its
    deflection and rate. This class is its one definition: MuJoCo computes it as a `general`
    actuator with affine bias (gain 1, bias -k q - c q') driven by `control`; the compiled kernel
    (fmus/kernel/systems.c) and the sweeps' rollout (designer/sweep/engine.py) compute `control` too,
    and tests/test_cosim.py checks each against `torque`.

    `explicit`: MuJoCo's implicit integrators (implicitfast, implicit) take an actuator's
    velocity-dependent bias implicitly, while a co-simulated torque is a force set for the step; an
    explicit law is a plain force actuator (gain 1, no bias) whose control is `torque` at the start of
    each step, the co-simulation's own exchange, so a same-step comparison is like with like.
    """

    k: float
    c: float
    offset: float = 0.0
    explicit: bool = False

    def torque(self, s, v):
        """The torque (N.m, or N on a slide) at deflection `s` and rate `v` (arrays broadcast)."""
        return -(self.k * (s - self.offset) + self.c * v)

    def control(self, motor_q, motor_v):
        """The actuator control that makes MuJoCo's affine bias equal `torque` for motor angle
        `motor_q` and rate `motor_v` (arrays broadcast): k (q_motor + offset) + c q_motor'."""
        return self.k * (motor_q + self.offset) + self.c * motor_v

    def actuator(self, spec, joint: str):
        """Add the `general` actuator `flex_<joint>` computing this law to MuJoCo spec `spec`."""
        import mujoco

        act = spec.add_actuator(
            name=f"flex_{joint}",
            target=joint,
            trntype=mujoco.mjtTrn.mjTRN_JOINT,
            gaintype=mujoco.mjtGain.mjGAIN_FIXED,
            biastype=mujoco.mjtBias.mjBIAS_NONE if self.explicit else mujoco.mjtBias.mjBIAS_AFFINE,
        )
        act.gainprm[0] = 1.0
        if not self.explicit:
            act.biasprm[1] = -self.k
            act.biasprm[2] = -self.c
        act.ctrllimited = mujoco.mjtLimited.mjLIMITED_FALSE
        return act


class RobotStruct(ctypes.Structure):
    """kernel.h ks_robot: the robot as the compiled kernel steps it."""

    _fields_ = [
        ("model", c_void_p),
        ("data", c_void_p),
        ("n_joints", c_int32),
        ("n_inputs", c_int32),
        ("qposadr", kb.P_INT),
        ("dofadr", kb.P_INT),
        ("input_dof", kb.P_INT),
        ("refs", POINTER(kb.Reference)),
        ("motor_q", kb.P_DOUBLE),
        ("motor_v", kb.P_DOUBLE),
        ("steps", c_int64),
        ("time", c_double),
        ("n_engine", c_int32),
        ("pad", c_int32),
        ("engine_actuator", kb.P_INT),
        ("engine_joint", kb.P_INT),
        ("engine_law", kb.P_DOUBLE),
    ]


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
        notes: tuple[str, ...] = (),
    ) -> None:
        import mujoco

        check_joints(spec, list(motors))
        if integrator not in INTEGRATORS:
            raise DesignerError(f"unknown integrator '{integrator}'", f"use one of: {', '.join(INTEGRATORS)}")
        spec = spec.copy()
        spec.option.timestep = step
        spec.option.integrator = getattr(mujoco.mjtIntegrator, f"mjINT_{integrator.upper()}")
        self.notes = tuple(notes)  # what the reader should know of how the host model was changed
        self.in_engine = dict(in_engine or {})
        for name, law in self.in_engine.items():
            law.actuator(spec, name)
        try:
            self.model = spec.compile()
        except Exception as exc:  # mujoco raises a bare ValueError with its compiler's message
            raise DesignerError(
                f"MuJoCo cannot compile the robot model: {str(exc).strip().replace(chr(10), '; ')}",
                "fix the model (MuJoCo's message says where)",
            ) from None
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
            if law.explicit:  # the torque at the step's start, as the co-simulation exchanges it
                s = self.data.qpos[self.qpos[k]] - self.motor_q[k]
                v = self.data.qvel[self.dof[k]] - self.motor_v[k]
                self.data.ctrl[self.actuators[i]] = law.torque(s, v)
            else:
                self.data.ctrl[self.actuators[i]] = law.control(self.motor_q[k], self.motor_v[k])
        self._mj_step(self.model, self.data)
        if self._bad.number:
            raise diverged(self.time)
        self._steps += 1
        self.time = self._steps * h
        self._motor(self.time)

    def binding(self) -> kb.Binding:
        """The robot for the compiled kernel (see designer.cosim.binding): a copy of its MuJoCo model
        and data that the kernel steps, synchronised with this robot's before and after each run
        (designer.cosim.twin), its joints and motors, the spring-dampers MuJoCo computes itself.

        Raises:
            DesignerError: a mujoco too old to load a model from memory, or a motor reference the
                kernel does not know.
        """
        if any(law.explicit for law in self.in_engine.values()):
            raise DesignerError(
                "the compiled kernel computes in-engine spring-dampers in their implicit form only",
                "run this robot with engine='python'",
            )
        twin = Twin(self.model, self.data)  # the kernel steps its own copy (see twin.py)
        keep: list = []
        refs = (kb.Reference * len(self.motors))(*[kb.reference(r, keep) for r in self.motors])
        qposadr, dofadr, inputs = kb.ints(self.qpos), kb.ints(self.dof), kb.ints(self._input_dof)
        engine_act = kb.ints(self.actuators)
        engine_joint = kb.ints([self.joints.index(j) for j in self.in_engine])
        engine_law = np.array([(v.k, v.c, v.offset) for v in self.in_engine.values()], float).reshape(-1, 3)
        struct = RobotStruct(
            model=twin.model,
            data=twin.data,
            n_joints=len(self.joints),
            n_inputs=len(inputs),
            qposadr=kb.pointer(qposadr, kb.P_INT),
            dofadr=kb.pointer(dofadr, kb.P_INT),
            input_dof=kb.pointer(inputs, kb.P_INT),
            refs=refs,
            motor_q=kb.pointer(self.motor_q),
            motor_v=kb.pointer(self.motor_v),
            n_engine=len(engine_act),
            engine_actuator=kb.pointer(engine_act, kb.P_INT),
            engine_joint=kb.pointer(engine_joint, kb.P_INT),
            engine_law=kb.pointer(engine_law),
        )
        keep += [refs, qposadr, dofadr, inputs, engine_act, engine_joint, engine_law, struct, twin]

        def start(step: float) -> int:
            twin.load()
            struct.steps, struct.time = self._steps, self.time
            for ref in refs:
                ref.cursor = 0
            return self._steps

        def finish(steps: int) -> None:
            twin.store()
            self._steps, self.time = struct.steps, struct.time

        return kb.Binding(
            kb.ROBOT,
            ctypes.addressof(struct),
            start,
            finish,
            keep=keep,
            error=lambda call, status, t: diverged(t),
            struct=struct,
        )
