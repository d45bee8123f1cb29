"""Check of the co-simulation: the two-link arm converges to the in-engine reference with the macro step."""

from __future__ import annotations

import numpy as np
import pandas as pd

from .checks import CheckResult, Context

#: the co-simulated arm (as examples/two_link_arm.toml, over 2 s): macro steps of the convergence
COSIM_STEPS = (4e-3, 2e-3, 1e-3, 5e-4)
COSIM_SECONDS = 2.0
#: co-simulation and the same spring-damper inside MuJoCo agree to round-off at each step, rad
COSIM_SAME_STEP = 1e-9
#: smallest observed order of convergence against the fine reference (Euler: first order)
COSIM_ORDER = 0.8


def check_cosim(ctx: Context) -> CheckResult:
    """The arm co-simulated with two joint FMUs converges to the in-engine reference with the macro step."""
    from ..cosim.references import Sine, Step
    from ..cosim.robot_scenario import robot_reference
    from ..cosim.run import run
    from ..cosim.scenario import JointSource, Scenario
    from ..joint import Joint
    from ..plots.checks import plot_convergence
    from ..plots.common import save_figure
    from ..plots.timeseries import plot_timeseries

    joint = JointSource(axis="theta", joint=Joint.from_coefficients({"theta": {"k": 330.0, "c": 0.83}}))
    sc = Scenario(
        duration=COSIM_SECONDS,
        step=1e-3,
        joints={"j1": joint, "j2": joint},
        motors={"j1": Sine(0.5, 0.5), "j2": Step(0.3, 1.0)},
        validation_steps=COSIM_STEPS,
    )
    result = run(sc, validate=True)
    val = result.validation
    cosim = result.to_frame()
    ref = robot_reference(sc, result.laws, sc.step, sc.duration, sc.integrator)
    reference = pd.DataFrame(ref.values, columns=ref.columns).assign(t=ref.time)
    steps = pd.DataFrame(val["steps"]).sort_values("step", ascending=False, ignore_index=True)
    err = steps["max_error"].to_numpy()
    steps["order"] = np.concatenate([[np.nan], np.log2(err[:-1] / err[1:])])
    ok = bool(
        (steps["max_error_same_step"] <= COSIM_SAME_STEP).all()
        and (steps["order"].iloc[1:] >= COSIM_ORDER).all()
    )
    figs = [
        save_figure(
            plot_convergence(
                steps[["step", "max_error", "max_error_same_step"]].rename(
                    columns={
                        "max_error": f"against RK4 at {min(COSIM_STEPS) / 4:g} s",
                        "max_error_same_step": "against MuJoCo in-engine",
                    }
                ),
                unit="rad",
            ),
            ctx.figures / "cosim_convergence.png",
        ),
        save_figure(
            plot_timeseries(
                cosim, columns=["robot.j1.q", "robot.j2.q", "j1.theta.f", "j2.theta.f"], reference=reference
            ),
            ctx.figures / "cosim_arm.png",
        ),
    ]
    summary = (
        f"two-link arm, Gauss-Seidel, {COSIM_SECONDS:g} s: error against the fine reference "
        + ", ".join(f"{r.max_error:.2g} rad at {r.step:g} s" for r in steps.itertuples())
        + f" (order {steps['order'].iloc[1:].min():.2f} or better); against the same spring-damper inside "
        f"MuJoCo at most {steps['max_error_same_step'].max():.1g} rad. Reference: {val['reference']}"
    )
    return CheckResult("Co-simulation convergence", ok, summary, steps, figs)
