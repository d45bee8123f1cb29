"""Check of the joint FMUs: validate_fmu, the analytic step response in fmpy, and a second importer.

The joint, load, analytic solution and libcosimpy stepper here are the fixtures the FMU tests use too.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ..checks import CheckResult, Context

#: the joint of the FMU checks: the study's x axis near its middle (rig units, kg) and the study's
#: 280 g static load, N
FMU_JOINT = {"k": 0.8, "c": 2e-3, "m": 0.01}
FMU_LOAD = 2.744
#: largest relative error of the step response: exact ZOH (co-simulation), fmpy's CVode (model exchange)
FMU_TOLERANCE = {"CoSimulation": 1e-9, "ModelExchange": 1e-5}
FMU_STOP = 0.5


def step_response(m: float, c: float, k: float, force: float, t):
    """Displacement of m y'' + c y' + k y = force from rest (SI, under-damped)."""
    wn, z = np.sqrt(k / m), c / (2 * np.sqrt(k * m))
    wd = wn * np.sqrt(1 - z * z)
    decay = np.exp(-z * wn * t) * (np.cos(wd * t) + z / np.sqrt(1 - z * z) * np.sin(wd * t))
    return force / k * (1 - decay)


def libcosim_step(path: Path, steps: int, step: float) -> object:
    """The body FMU's displacement after each step under the static load, run by libcosimpy."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    from .fmu import value_reference

    log_output_level(CosimLogLevel.ERROR)
    ex = CosimExecution.from_step_size(step_size=int(round(step * 1e9)))
    index = ex.add_local_slave(local_slave=CosimLocalSlave(fmu_path=str(path), instance_name="joint"))
    obs = CosimObserver.create_last_value()
    ex.add_observer(observer=obs)
    ex.real_initial_value(slave_index=index, variable_reference=value_reference("x", "f"), value=FMU_LOAD)
    s = value_reference("x", "s")
    out = []
    for _ in range(steps):
        ex.step()
        out.append(obs.last_real_values(slave_index=index, variable_references=[s])[0])
    return np.array(out)


def _step_rows(body: Path, version: int, t: np.ndarray, exact: np.ndarray) -> tuple[list, dict]:
    """fmpy's co-simulation and model exchange of the body FMU under the load, against `exact`."""
    from fmpy import simulate_fmu

    rows, curves, scale = [], {}, np.max(np.abs(exact))
    for fmi_type, tol in FMU_TOLERANCE.items():
        r = simulate_fmu(
            str(body),
            fmi_type=fmi_type,
            stop_time=FMU_STOP,
            step_size=1e-3,
            output_interval=1e-3,
            relative_tolerance=1e-10,
            start_values={"x.f": FMU_LOAD},
            output=["x.s"],
        )
        s = np.interp(t, r["time"], r["x.s"])
        err = float(np.max(np.abs(s - exact)) / scale)
        curves[f"FMI {version} {fmi_type}"] = s
        rows.append(_row(f"fmpy step response FMI {version} {fmi_type}", err, tol))
    return rows, curves


def _row(check: str, err: float, tol: float) -> dict:
    return {
        "check": check,
        "figure": f"max error {err:.2g} of the peak (limit {tol:g})",
        "passed": err <= tol,
    }


def _libcosim_row(body: Path, t: np.ndarray, exact: np.ndarray) -> dict:
    """libcosimpy stepping the FMI 2 body FMU, against `exact` (skipped when not installed)."""
    try:
        s = libcosim_step(body, len(t) - 1, 1e-3)
    except ImportError:
        return {"check": "libcosimpy", "figure": "skipped: libcosimpy not installed", "passed": True}
    err = float(np.max(np.abs(s - exact[1:])) / np.max(np.abs(exact)))
    return _row("libcosimpy step response FMI 2 CoSimulation", err, FMU_TOLERANCE["CoSimulation"])


def check_fmus(ctx: Context) -> CheckResult:
    """FMI 2 and 3 archives pass validate_fmu; the body step response matches the analytic one in fmpy
    (co-simulation and model exchange) and in libcosimpy."""
    from fmpy.validation import validate_fmu

    from ..files import private_tempdir
    from ..joint import Joint
    from ..plots.common import save_figure
    from ..plots.timeseries import plot_timeseries
    from .fmu import export_fmu

    joint = Joint.from_coefficients({"x": FMU_JOINT}, name="report_joint")
    m, c, k = (joint.axes["x"].si()[q] for q in ("m", "c", "k"))
    rows, curves = [], {}
    t = np.linspace(0.0, FMU_STOP, int(round(FMU_STOP / 1e-3)) + 1)
    exact = step_response(m, c, k, FMU_LOAD, t)
    with private_tempdir("designer-report-") as tmp:  # fmpy's unpacked FMUs go in there too
        for version in (2, 3):
            for interface in ("force", "body"):
                path = Path(tmp) / f"joint{version}{interface}.fmu"
                problems = validate_fmu(
                    str(export_fmu(joint, path, fmi_version=version, interface=interface))
                )
                rows.append(
                    {
                        "check": f"validate_fmu FMI {version} {interface}",
                        "figure": f"{len(problems)} problem(s)",
                        "passed": not problems,
                    }
                )
            more, found = _step_rows(Path(tmp) / f"joint{version}body.fmu", version, t, exact)
            rows += more
            curves |= found
        rows.append(_libcosim_row(Path(tmp) / "joint2body.fmu", t, exact))
    errors = {f"{name} error": curves[name] - exact for name in curves}
    frame = pd.DataFrame({"t": t, "analytic": exact, **curves}).assign(**errors)
    fig = save_figure(
        plot_timeseries(frame, panels={"x.s (m)": ["analytic", *curves], "error (m)": list(errors)}),
        ctx.figures / "fmu_step_response.png",
    )
    table = pd.DataFrame(rows)
    summary = (
        f"{int(table.passed.sum())} of {len(table)} FMU checks pass: joint k {FMU_JOINT['k']:g} N/mm, "
        f"c {FMU_JOINT['c']:g} N.s/mm, m {FMU_JOINT['m']:g} kg under a {FMU_LOAD:g} N step"
    )
    return CheckResult(
        "FMUs: validate_fmu, analytic step, second importer", bool(table.passed.all()), summary, table, [fig]
    )
