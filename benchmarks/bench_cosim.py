"""Co-simulation speed: real-time factor of the two-link arm at 1 ms, as ratios to baselines run here.

Baselines: a bare MuJoCo loop computing the same spring-damper in Python (the floor for any master
in Python), and libcosimpy stepping the same two joint FMUs (without the robot, which it cannot host)
against our master stepping those FMUs alone.
Run: python benchmarks/bench_cosim.py
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import mujoco

from designer.cosim import load_spec
from designer.cosim.master import Master
from designer.cosim.run import joint_fmus, robot_run
from designer.cosim.scenario import load

DURATION, STEP = 10.0, 1e-3
SCENARIO = Path(__file__).resolve().parent.parent / "examples" / "two_link_arm.toml"


def bare_loop(k: float, c: float) -> float:
    """Seconds for the arm with the law in Python around mj_step, motors as in the example."""
    sc = load(SCENARIO)
    spec = load_spec(None, sc.lengths, sc.masses)
    spec.option.timestep = STEP
    model = spec.compile()
    data = mujoco.MjData(model)
    motors = list(sc.motors.values())
    start = time.perf_counter()
    for n in range(int(DURATION / STEP)):
        t = n * STEP
        for i, ref in enumerate(motors):
            q, dq = ref(t)
            data.qfrc_applied[i] = -(k * (data.qpos[i] - q) + c * (data.qvel[i] - dq))
        mujoco.mj_step(model, data)
    return time.perf_counter() - start


def fmus_alone(fmus: dict[str, Path], steps: int) -> float:
    """Seconds for our master stepping the two force FMUs with their inputs held."""
    from designer.cosim.fmu import FmuSystem

    class Hold:
        feedthrough = False
        inputs: list[str] = []
        outputs = ["s", "v"]

        def get(self):
            import numpy as np

            return np.array([0.1, 0.0])

        def set(self, values):
            pass

        def do_step(self, h):
            pass

    systems = {"hold": Hold(), **{n: FmuSystem(p, ["theta"], name=n) for n, p in fmus.items()}}
    wires = [(f"hold.{v}", f"{n}.theta.{v}") for n in fmus for v in ("s", "v")]
    start = time.perf_counter()
    Master(systems, wires).run(steps * STEP, STEP)
    elapsed = time.perf_counter() - start
    for n in fmus:
        systems[n].close()
    return elapsed


def libcosim(fmus: dict[str, Path], steps: int) -> float:
    """Seconds for libcosimpy stepping the same two FMUs (inputs at their start values)."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimSlave import CosimLocalSlave

    log_output_level(CosimLogLevel.ERROR)

    execution = CosimExecution.from_step_size(step_size=int(STEP * 1e9))
    for name, path in fmus.items():
        execution.add_local_slave(CosimLocalSlave(fmu_path=str(path), instance_name=name))
    start = time.perf_counter()
    execution.simulate_until(target_time=int(steps * STEP * 1e9))
    return time.perf_counter() - start


def main() -> None:
    sc = load(SCENARIO)
    with tempfile.TemporaryDirectory():
        with joint_fmus(sc) as fmus:
            from designer.cosim.run import law

            p = law(sc.joints["j1"], fmus["j1"])
            ours = time.perf_counter()
            robot_run(sc, fmus, STEP, DURATION, "gauss-seidel")
            ours = time.perf_counter() - ours
            floor = bare_loop(p["k"], p["c"])
            steps = int(DURATION / STEP)
            alone = fmus_alone(fmus, steps)
            cosim = libcosim(fmus, steps)
    print(f"two-link arm, {DURATION:g} s at {STEP * 1e3:g} ms, Gauss-Seidel through two FMI 2 FMUs:")
    print(f"  real-time factor            {DURATION / ours:8.2f} x  ({ours:.2f} s wall)")
    print(f"  bare MuJoCo loop, law in Python: real-time factor {DURATION / floor:.2f} x")
    print(f"  ratio master / bare loop    {ours / floor:8.2f}")
    print(f"  two FMUs alone, {steps} steps: our master {alone:.3f} s, libcosimpy {cosim:.3f} s")
    print(f"  ratio master / libcosimpy   {alone / cosim:8.2f}")


if __name__ == "__main__":
    main()
