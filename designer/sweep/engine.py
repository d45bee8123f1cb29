"""The in-engine fast path: linear joints as MuJoCo `general` actuators with affine bias, run through
`mujoco.rollout` without MuJoCo's profiling clock (designer.cosim.clock).

It is the co-simulation's validation reference (designer.cosim.robot.Robot with `in_engine`) run
for many cases: one compiled model whose actuators' bias parameters (-k, -c) are set per case, and
an open-loop control k (q_motor(t) + offset) + c q_motor'(t) precomputed from the motor references,
applied before each step exactly as `Robot.do_step` does.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..cosim.clock import without_clock
from ..cosim.master import Trace
from ..cosim.robot import SpringDamper
from ..cosim.robot_scenario import RobotScenario, robot_system
from ..errors import DesignerError
from .cases import Case, si_law


def _offsets(sc: RobotScenario) -> dict[str, float]:
    return {j: float(src.parameters.get(f"{src.axis}.offset", 0.0)) for j, src in sc.joints.items()}


def _motors(sc: RobotScenario, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Time (n + 1), motor angles and rates (n + 1, joints) at t = 0, h, ..., n h."""
    t = np.arange(n + 1) * sc.step
    mq = np.empty((n + 1, len(sc.joints)))
    mv = np.empty_like(mq)
    for i, ti in enumerate(t):
        for k, j in enumerate(sc.joints):
            mq[i, k], mv[i, k] = sc.motors[j](float(ti))
    return t, mq, mv


def rollout_traces(sc: RobotScenario, cases: Sequence[Case]) -> list[Trace | Exception]:
    """The trace of each case (columns `robot.J.q|motor|v` as in a co-simulation's result, rows at
    t = 0, h, ...), or a DesignerError for a case whose model diverged (MuJoCo reset it)."""
    import mujoco
    from mujoco import rollout

    joints = list(sc.joints)
    offsets = _offsets(sc)
    laws = [
        {j: SpringDamper(**si_law(sc.joints[j], case.coefficients[j]), offset=offsets[j]) for j in joints}
        for case in cases
    ]
    robot = robot_system(sc, sc.step, in_engine=laws[0])
    base = robot.model
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state0 = np.empty(mujoco.mj_stateSize(base, spec))
    mujoco.mj_getState(base, robot.data, state0, spec)
    n = int(round(sc.duration / sc.step))
    t, mq, mv = _motors(sc, n)
    data = mujoco.MjData(base)
    control = np.zeros((1, n, base.nu))
    states = np.empty((len(cases), n, state0.size))
    # one model, its actuators' bias set per case, one rollout per case: a copy of the MjModel per
    # case cost more than the extra calls (the same states, bit for bit)
    with without_clock():  # MuJoCo's profiling clock on every step: 1.6x the CPU, the same states
        for b, law in enumerate(laws):
            for k, (j, act) in enumerate(zip(joints, robot.actuators, strict=True)):
                base.actuator_biasprm[act, 1] = -law[j].k
                base.actuator_biasprm[act, 2] = -law[j].c
                control[0, :, act] = law[j].control(mq[:-1, k], mv[:-1, k])
            rollout.rollout(base, data, state0[None, :], control, state=states[b : b + 1])
    qadr = 1 + robot.qpos  # FULLPHYSICS state: time, qpos, qvel, act, plugin
    vadr = 1 + base.nq + robot.dof
    columns = [f"robot.{j}.{x}" for x in ("q", "motor", "v") for j in joints]
    out: list[Trace | Exception] = []
    for b in range(len(cases)):
        s = np.vstack([state0[None, :], states[b]])
        wrong = np.flatnonzero(~np.isfinite(s).all(axis=1) | (np.abs(s[:, 0] - t) > 0.5 * sc.step))
        if len(wrong):
            out.append(
                DesignerError(
                    f"the robot diverged at t = {t[max(wrong[0] - 1, 0)]:g} s (MuJoCo reset it)",
                    "use a smaller step",
                )
            )
            continue
        values = np.column_stack([s[:, qadr], mq, s[:, vadr] - mv])
        out.append(Trace(t, columns, values))
    return out
