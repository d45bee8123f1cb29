"""Sweep speed: cases per second of the FMU path and of the in-engine path, against a bare `mujoco.rollout`
of the same batch, in one run.

The batch: Monte Carlo draws of the example arm's two joints (examples/two_link_arm.toml) over 1 s
at 1 ms, the same cases for all three, evaluated serially in this process (one core). The FMU path
co-simulates every case with the joint FMUs through one prepared Session (designer.cosim.prepare:
set-up once, a reset and a compiled-kernel run per case); the in-engine path computes the same
spring-dampers inside MuJoCo through `mujoco.rollout`; the bare rollout runs the in-engine path's
compiled models and controls with nothing around it. Each round runs the three one after the other
(interleaved, so a change of load on the shared machine hits all three); the medians are printed with
the targets of issue 21: FMU path >= in-engine path, and >= 0.8 x bare rollout.
Run: python benchmarks/bench_sweep.py [--cases 200] [--rounds 3]
"""

from __future__ import annotations

import argparse
import copy
import statistics
import time
from pathlib import Path

import mujoco
import numpy as np
from mujoco import rollout

from designer import cosim, sweep
from designer.cosim.robot import SpringDamper
from designer.cosim.robot_scenario import robot_system
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
    laws = [{j: SpringDamper(**si_law(sc.joints[j], c.coefficients[j])) for j in joints} for c in cases]
    robot = robot_system(sc, sc.step, in_engine=laws[0])
    n = int(round(sc.duration / sc.step))
    state = np.empty(mujoco.mj_stateSize(robot.model, mujoco.mjtState.mjSTATE_FULLPHYSICS))
    mujoco.mj_getState(robot.model, robot.data, state, mujoco.mjtState.mjSTATE_FULLPHYSICS)
    motor = np.array([[sc.motors[j](i * sc.step) for j in joints] for i in range(n)])  # (n, joints, 2)
    models, control = [], np.zeros((len(cases), n, robot.model.nu))
    for b, law in enumerate(laws):
        m = copy.copy(robot.model)
        for k, (j, act) in enumerate(zip(joints, robot.actuators, strict=True)):
            m.actuator_biasprm[act, 1:3] = (-law[j].k, -law[j].c)
            control[b, :, act] = law[j].control(motor[:, k, 0], motor[:, k, 1])
        models.append(m)
    start = time.perf_counter()
    rollout.rollout(models, mujoco.MjData(robot.model), state[None, :], control)
    return len(models) / (time.perf_counter() - start)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=200, help="cases of the batch (all three paths)")
    parser.add_argument("--rounds", type=int, default=3, help="interleaved rounds; medians are printed")
    args = parser.parse_args()
    rates: dict[str, list[float]] = {"fmu": [], "engine": [], "bare": []}
    sweep_rate(spec_for("fmu", 4))  # build the kernel, warm the caches
    for _ in range(args.rounds):  # interleaved, so a change of load on the machine hits all three
        rates["fmu"].append(sweep_rate(spec_for("fmu", args.cases)))
        rates["engine"].append(sweep_rate(spec_for("engine", args.cases)))
        rates["bare"].append(bare_rollout_rate(spec_for("engine", args.cases)))
    fmu, engine, bare = (statistics.median(rates[k]) for k in ("fmu", "engine", "bare"))
    print(f"two-link arm, 1 s at 1 ms, {args.cases} Monte Carlo draws, serial in one process")
    print(f"medians of {args.rounds} interleaved rounds (each round: FMU, in-engine, bare)")
    for label, key in (
        ("FMU co-simulation path", "fmu"),
        ("in-engine path", "engine"),
        ("bare mujoco.rollout", "bare"),
    ):
        rounds = ", ".join(f"{r:.0f}" for r in rates[key])
        print(f"{label + ':':<24}{statistics.median(rates[key]):8.1f} cases/s  (rounds: {rounds})")
    print(f"FMU / in-engine: {fmu / engine:.2f} (target >= 1)")
    print(f"FMU / bare rollout: {fmu / bare:.2f} (target >= 0.8)")


if __name__ == "__main__":
    main()
