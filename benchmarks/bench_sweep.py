"""Sweep speed: cases per second of the FMU path and of the in-engine path, against a bare `mujoco.rollout`
of the same batch, in one run.

The batch: Monte Carlo draws of the example arm's two joints (examples/two_link_arm.toml) over 1 s
at 1 ms, evaluated serially in this process (one core). The bare rollout runs the same compiled
models and controls with nothing around it, the floor of the in-engine path; the ratios say what
the sweep adds (models, controls, metrics, rows) and what the FMU co-simulation costs per case.
Run: python benchmarks/bench_sweep.py [--cases 200] [--fmu-cases 40] [--repeat 3] (best of the repeats)
"""

from __future__ import annotations

import argparse
import copy
import time
from pathlib import Path

import mujoco
import numpy as np
from mujoco import rollout

from designer import cosim, sweep
from designer.cosim.robot import Robot, SpringDamper, load_spec
from designer.sweep.evaluate import si_law
from designer.sweep.executors import SerialExecutor
from designer.sweep.spec import Cases, Spec, with_duration

SCENARIO = Path(__file__).resolve().parent.parent / "examples" / "two_link_arm.toml"


def spec_for(path: str, n: int) -> Spec:
    sc = with_duration(cosim.load(SCENARIO), 1.0)
    cases = Cases(type="montecarlo", joints={"j1": None, "j2": None}, n=n, seed=11)
    return Spec(scenario=sc, cases=cases, path=path, check=0)


def sweep_rate(spec: Spec) -> float:
    """Cases per second of a whole serial sweep (cases made, evaluated, tabled, summarised)."""
    start = time.perf_counter()
    result = sweep.run(spec, executor=SerialExecutor())
    elapsed = time.perf_counter() - start
    assert (result.table["status"] == "ok").all()
    return len(result.table) / elapsed


def bare_rollout_rate(spec: Spec) -> float:
    """Cases per second of mujoco.rollout alone on the same models and controls (built beforehand)."""
    sc = spec.scenario
    cases = sweep.make_cases(spec)
    joints = list(sc.joints)
    laws = [{j: si_law(sc.joints[j], c.coefficients[j]) for j in joints} for c in cases]
    springs = {j: SpringDamper(laws[0][j]["k"], laws[0][j]["c"]) for j in joints}
    robot = Robot(
        load_spec(None, sc.lengths, sc.masses), sc.motors, sc.step, sc.integrator, in_engine=springs
    )
    n = int(round(sc.duration / sc.step))
    state = np.empty(mujoco.mj_stateSize(robot.model, mujoco.mjtState.mjSTATE_FULLPHYSICS))
    mujoco.mj_getState(robot.model, robot.data, state, mujoco.mjtState.mjSTATE_FULLPHYSICS)
    models = []
    for law in laws:
        m = copy.copy(robot.model)
        for j, act in zip(joints, robot.actuators, strict=True):
            m.actuator_biasprm[act, 1:3] = (-law[j]["k"], -law[j]["c"])
        models.append(m)
    motor = np.array([[sc.motors[j](i * sc.step) for j in joints] for i in range(n)])  # (n, joints, 2)
    control = np.zeros((len(models), n, robot.model.nu))
    for b, law in enumerate(laws):
        for k, (j, act) in enumerate(zip(joints, robot.actuators, strict=True)):
            control[b, :, act] = law[j]["k"] * motor[:, k, 0] + law[j]["c"] * motor[:, k, 1]
    start = time.perf_counter()
    rollout.rollout(models, mujoco.MjData(robot.model), state[None, :], control)
    return len(models) / (time.perf_counter() - start)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=200, help="cases of the engine path and bare rollout")
    parser.add_argument("--fmu-cases", type=int, default=40, help="cases of the FMU path (slower)")
    parser.add_argument("--repeat", type=int, default=3, help="best of this many runs of each")
    args = parser.parse_args()
    engine = bare = fmu = 0.0
    for _ in range(args.repeat):  # interleaved, so a change of load on the machine hits all three
        engine = max(engine, sweep_rate(spec_for("engine", args.cases)))
        bare = max(bare, bare_rollout_rate(spec_for("engine", args.cases)))
        fmu = max(fmu, sweep_rate(spec_for("fmu", args.fmu_cases)))
    print(f"two-link arm, 1 s at 1 ms, Monte Carlo draws, serial in one process, best of {args.repeat}")
    print(f"FMU co-simulation path: {fmu:8.1f} cases/s ({args.fmu_cases} cases)")
    print(f"in-engine path:         {engine:8.1f} cases/s ({args.cases} cases)")
    print(f"bare mujoco.rollout:    {bare:8.1f} cases/s (same batch)")
    print(f"in-engine / FMU: {engine / fmu:.1f}x; bare rollout / in-engine: {bare / engine:.2f}x")


if __name__ == "__main__":
    main()
