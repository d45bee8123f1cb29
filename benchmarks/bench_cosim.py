"""Co-simulation speed, CPU time, every ratio from one interleaved run (rounds alternate the contenders).

1. The two-link arm (examples/two_link_arm.toml), 100 s at 1 ms, per step:
   - the compiled kernel (designer.cosim.kernel: the loop only, systems built beforehand);
   - the engine floor: the same spring-dampers as MuJoCo `general` actuators with affine bias,
     stepped by mj_step(model, data, nstep=N) (no co-simulation, no motor references), as Python
     runs it (with the bindings' mjcb_time clock) and without that clock, as the kernel steps;
   - a bare Python loop: the law and the motor references in Python around mj_step;
   - libcosimpy stepping the same two joint FMUs (co-simulation, no robot: it cannot host one);
   - the Python master (designer's reference engine), over 10 s.
2. Per added joint: N-link arms, N = 1, 2, 4, 8, 16, 10 s at 1 ms; the slope of CPU per step
   against N (least squares), kernel against floor.
3. The whole `designer cosim` command on the arm (10 s, plot off) against `python -c "import mujoco"`,
   CPU time of the child process.

Targets (issue 14): kernel <= 1.25 x floor per step, >= 3 x faster than the bare loop, per added joint
<= 2 x the floor's, the whole command <= 2.5 x `import mujoco`.
Run: python benchmarks/bench_cosim.py [--rounds 5]
"""

from __future__ import annotations

import argparse
import contextlib
import ctypes
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import mujoco
import numpy as np

from designer.cosim import kernel, load, prepare
from designer.cosim.master import Master
from designer.cosim.robot import Robot, SpringDamper, load_spec
from designer.export.fmu import export_fmu

STEP = 1e-3
SCENARIO = Path(__file__).resolve().parent.parent / "examples" / "two_link_arm.toml"
LINKS = (1, 2, 4, 8, 16)


def cpu(fn) -> float:
    start = time.process_time()
    fn()
    return time.process_time() - start


def loop_cpu(session, duration: float, engine: str) -> float:
    """CPU seconds of the co-simulation loop alone: a prepared Session's run with the engine's loop
    timed inside."""
    owner = kernel.Bound if engine == "kernel" else Master
    inner, spent = owner.run, []

    def timed(*args, **kwargs):
        start = time.process_time()
        out = inner(*args, **kwargs)
        spent.append(time.process_time() - start)
        return out

    owner.run = timed
    try:
        session.trace(step=STEP, duration=duration, engine=engine)
    finally:
        owner.run = inner
    return spent[0]


@contextlib.contextmanager
def no_timer():
    """Without the clock mujoco's Python bindings install as mjcb_time (MuJoCo's profiling timers read
    it around every stage of mj_step); the kernel steps without it, so this is the like-for-like floor."""
    from designer.cosim.kernel_build import mujoco_paths

    hook = ctypes.c_void_p.in_dll(ctypes.CDLL(str(mujoco_paths()[1])), "mjcb_time")
    saved, hook.value = hook.value, None
    try:
        yield
    finally:
        hook.value = saved


def floor_cpu(sc, laws, duration: float, timer: bool = True) -> float:
    """CPU seconds of mj_step(nstep=N) with the joints' laws as in-engine actuators."""
    springs = {j: SpringDamper(p["k"], p["c"], p["offset"]) for j, p in laws.items()}
    robot = Robot(load_spec(sc.model, sc.lengths, sc.masses), sc.motors, STEP, "euler", in_engine=springs)
    n = int(round(duration / STEP))
    with contextlib.nullcontext() if timer else no_timer():
        return cpu(lambda: mujoco.mj_step(robot.model, robot.data, nstep=n))


def bare_cpu(sc, laws, duration: float) -> float:
    """CPU seconds of the law and the motor references in Python around mj_step (the Robot's model)."""
    robot = Robot(load_spec(sc.model, sc.lengths, sc.masses), sc.motors, STEP, "euler")
    model, data = robot.model, robot.data
    joints = [(model.joint(j).qposadr[0], model.joint(j).dofadr[0], sc.motors[j], laws[j]) for j in sc.joints]

    def loop():
        for n in range(int(round(duration / STEP))):
            t = n * STEP
            for qa, da, ref, p in joints:
                q, dq = ref(t)
                data.qfrc_applied[da] = -(
                    p["k"] * (data.qpos[qa] - q - p["offset"]) + p["c"] * (data.qvel[da] - dq)
                )
            mujoco.mj_step(model, data)

    return cpu(loop)


def libcosim_cpu(fmus, duration: float) -> float | None:
    """CPU seconds of libcosimpy stepping the joint FMUs (inputs at their start values); None if absent."""
    try:
        from libcosimpy.CosimExecution import CosimExecution
        from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
        from libcosimpy.CosimSlave import CosimLocalSlave
    except ImportError:
        return None
    log_output_level(CosimLogLevel.ERROR)
    execution = CosimExecution.from_step_size(step_size=int(round(STEP * 1e9)))
    for name, path in fmus.items():
        execution.add_local_slave(CosimLocalSlave(fmu_path=str(path), instance_name=name))
    return cpu(lambda: execution.simulate_until(target_time=int(round(duration * 1e9))))


def n_link(folder: Path, n: int):
    """An N-link arm scenario (links 60 mm, 30 g; joints 100 N.mm/rad), sines at the motors."""
    joints = "".join(
        f'[joints.j{i + 1}]\ncoefficients = {{ k = 100, c = 0.5 }}\nreference = {{ type = "sine", '
        f"amplitude = 0.05, frequency = {0.5 + 0.1 * i:g} }}\n"
        for i in range(n)
    )
    lengths = ", ".join(["0.06"] * n)
    masses = ", ".join(["0.03"] * n)
    path = folder / f"arm{n}.toml"
    path.write_text(
        f'[simulation]\nduration = 10.0\nstep = {STEP}\n[robot]\nmodel = "arm"\n'
        f"lengths = [{lengths}]\nmasses = [{masses}]\n{joints}"
    )
    return load(path)


def child_cpu(cmd: list[str], cwd: Path) -> float:
    """User + system CPU seconds of a child process."""
    proc = subprocess.Popen(cmd, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _, status, usage = os.wait4(proc.pid, 0)
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} exited with {proc.returncode}")
    return usage.ru_utime + usage.ru_stime


def command_folder(folder: Path) -> Path:
    """The arm example with the plot off, beside its suggestion.json."""
    text = SCENARIO.read_text().replace("plot = true", "plot = false")
    (folder / "arm.toml").write_text(text)
    shutil.copy(SCENARIO.parent / "suggestion.json", folder / "suggestion.json")
    return folder / "arm.toml"


def slope(ns, per_step) -> float:
    return float(np.polyfit(np.asarray(ns, float), np.asarray(per_step, float), 1)[0])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--duration", type=float, default=100.0, help="the arm's simulated seconds")
    args = parser.parse_args()
    beside = Path(sys.executable).parent / "designer"  # the script of this Python's install
    designer = str(beside) if beside.is_file() else shutil.which("designer") or "designer"
    sc = load(SCENARIO)
    times: dict[str, list[float]] = {}

    def add(key, value):
        if value is not None:
            times.setdefault(key, []).append(value)

    with contextlib.ExitStack() as stack:
        folder = Path(stack.enter_context(tempfile.TemporaryDirectory()))
        session = stack.enter_context(prepare(sc))
        laws = session.laws(session.parameters(None))
        fmus = {j: export_fmu(src.joint, folder / f"{j}.fmu") for j, src in sc.joints.items() if src.joint}
        arms = {n: n_link(folder, n) for n in LINKS}
        arm_sessions = {n: stack.enter_context(prepare(arm)) for n, arm in arms.items()}
        arm_laws = {n: s.laws(s.parameters(None)) for n, s in arm_sessions.items()}
        command = [designer, "cosim", str(command_folder(folder)), "-o", str(folder / "out")]
        loop_cpu(session, 0.1, "kernel")  # build the kernel, warm the caches
        child_cpu(command, folder)
        d = args.duration
        for _ in range(args.rounds):
            add("kernel", loop_cpu(session, d, "kernel") / (d / STEP))
            add("floor", floor_cpu(sc, laws, d) / (d / STEP))
            add("floor0", floor_cpu(sc, laws, d, timer=False) / (d / STEP))
            add("bare", bare_cpu(sc, laws, d) / (d / STEP))
            add("libcosim", None if (c := libcosim_cpu(fmus, d)) is None else c / (d / STEP))
            add("python", loop_cpu(session, 10.0, "python") / 1e4)
            for n, arm in arms.items():
                add(f"kernel{n}", loop_cpu(arm_sessions[n], 10.0, "kernel") / 1e4)
                add(f"floor{n}", floor_cpu(arm, arm_laws[n], 10.0) / 1e4)
                add(f"floor0{n}", floor_cpu(arm, arm_laws[n], 10.0, timer=False) / 1e4)
            add("command", child_cpu(command, folder))
            add("import", child_cpu([sys.executable, "-c", "import mujoco"], folder))
    report({k: statistics.median(v) for k, v in times.items()}, args)


def report(m: dict[str, float], args) -> None:
    us = 1e6

    def row(label: str, key: str, ratio: str = "") -> None:
        print(f"  {label:<22}{m[key] * us:8.2f} us   {ratio}")

    print(f"CPU time, medians of {args.rounds} interleaved rounds")
    print(f"two-link arm, {args.duration:g} s at {STEP * 1e3:g} ms, per step:")
    row("kernel", "kernel")
    row("engine floor", "floor", f"kernel / floor = {m['kernel'] / m['floor']:.2f} (target <= 1.25)")
    row("floor, no mjcb_time", "floor0", f"kernel / floor = {m['kernel'] / m['floor0']:.2f} (like for like)")
    row("bare Python loop", "bare", f"bare / kernel = {m['bare'] / m['kernel']:.2f} (target >= 3)")
    if "libcosim" in m:
        row("libcosimpy, FMUs only", "libcosim", f"libcosimpy / kernel = {m['libcosim'] / m['kernel']:.2f}")
    else:
        print("  libcosimpy            not installed")
    row("Python master (10 s)", "python", f"master / kernel = {m['python'] / m['kernel']:.2f}")
    print("N-link arms, 10 s at 1 ms, per step (us):")
    print("  N      " + "".join(f"{n:>8d}" for n in LINKS))
    print("  kernel " + "".join(f"{m[f'kernel{n}'] * us:8.2f}" for n in LINKS))
    print("  floor  " + "".join(f"{m[f'floor{n}'] * us:8.2f}" for n in LINKS))
    print("  floor0 " + "".join(f"{m[f'floor0{n}'] * us:8.2f}" for n in LINKS) + "   (no mjcb_time)")
    ks = slope(LINKS, [m[f"kernel{n}"] for n in LINKS])
    for label, key in (("floor", "floor"), ("floor0", "floor0")):
        fs = slope(LINKS, [m[f"{key}{n}"] for n in LINKS])
        print(
            f"  per added joint: kernel {ks * us:.3f} us, {label} {fs * us:.3f} us, "
            f"ratio {ks / fs:.2f} (target <= 2)"
        )
    ratio = m["command"] / m["import"]
    print(f"whole `designer cosim` (arm 10 s, plot off): {m['command']:.2f} s CPU")
    print(f'`python -c "import mujoco"`: {m["import"]:.2f} s CPU; ratio {ratio:.2f} (target <= 2.5)')


if __name__ == "__main__":
    main()
