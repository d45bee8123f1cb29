"""Check of the joint FMUs: validate_fmu, the analytic step response in fmpy, and a second importer.

The joint, load, analytic solution and libcosimpy stepper here are the fixtures the FMU tests use too.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from .checks import CheckResult, Context

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

    from ..export.fmu import value_reference

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

    from ..export.fmu import export_fmu
    from ..files import private_tempdir
    from ..joint import Joint
    from ..plots.common import save_figure
    from ..plots.timeseries import plot_timeseries

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
        plot_timeseries(
            frame,
            panels={"x.s (m)": ["analytic", *curves], "error (m)": list(errors)},
            titles={
                "x.s (m)": f"deflection under a {FMU_LOAD:g} N step: the analytic solution and "
                f"{len(curves)} FMU runs (wider lines underneath)",
                "error (m)": "each FMU run minus the analytic solution",
            },
        ),
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


#: the SSP check's run: the FMU joint under the static load, 1 ms steps (the body FMU's steps are
#: exact for a constant load) for 0.5 s, when the response has settled (damping ratio 0.35 at 45 Hz)
SSP_STEP, SSP_STOP = 1e-3, 0.5


def ssp_with_value(path: Path, out: Path, *, ssv: str, parameter: str, value: float) -> Path:
    """A copy of SSP archive `path` whose SSV `ssv` states `value` for `parameter`; all else as written."""
    import re
    import zipfile

    with zipfile.ZipFile(path) as zin, zipfile.ZipFile(out, "w") as zout:
        for name in zin.namelist():
            data = zin.read(name)
            if name == ssv:
                pattern = (
                    rb'(<ssv:Parameter name="' + re.escape(parameter.encode()) + rb'"><ssv:Real value=")[^"]*'
                )
                data, n = re.subn(pattern, rb"\g<1>" + repr(float(value)).encode(), data)
                if n != 1:
                    raise ValueError(f"{ssv} in {path} has no parameter {parameter}")
            zout.writestr(name, data)
    return out


def libcosim_ssp_run(path: Path, *, element: str, load: tuple[str, float], output: str) -> np.ndarray:
    """libcosim loads SSP `path` (its SSD's parameter bindings applied by libcosim itself), holds the
    input `load` = (variable, value) of component `element` from the start, and records `output` after
    each step of SSP_STEP up to SSP_STOP."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver

    log_output_level(CosimLogLevel.ERROR)
    execution = CosimExecution.from_ssp_file(str(path), step_size=int(round(SSP_STEP * 1e9)))
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)
    index = execution.slave_index_from_instance_name(element)
    refs = {v.name.decode(): v.reference for v in execution.slave_variables(index)}
    execution.real_initial_value(index, refs[load[0]], load[1])
    out = []
    for _ in range(int(round(SSP_STOP / SSP_STEP))):
        execution.step()
        out.append(observer.last_real_values(index, [refs[output]])[0])
    return np.array(out)


def _ssp_runs(tmp: Path, joint) -> tuple[dict[str, np.ndarray], dict[str, float]]:
    """x.s of the FMU joint under the load in libcosim and fmpy, as exported and with k doubled in
    the bound SSV only; and the k each run should see (SI)."""
    from fmpy.ssp.simulation import simulate_ssp

    from ..export.ssp import export_ssp, fmpy_parameter_set

    k = joint.axes["x"].si()["k"]
    runs, ks = {}, {}
    for wired in (False, True):
        path = export_ssp(joint, tmp / f"joint{int(wired)}.ssp", system_connectors=wired)
        stiff = ssp_with_value(
            path,
            tmp / f"stiff{int(wired)}.ssp",
            ssv="resources/report_joint.ssv",
            parameter="x.k",
            value=2 * k,
        )
        for label, p, kk in (("k", path, k), ("2k in the SSV", stiff, 2 * k)):
            if wired:
                r = simulate_ssp(
                    str(p),
                    stop_time=SSP_STOP,
                    step_size=SSP_STEP,
                    parameter_set=fmpy_parameter_set(p),
                    input={"report_joint_x.f": lambda t: FMU_LOAD},
                )
                name, x = f"fmpy, {label}", r["report_joint_x.s"][: int(round(SSP_STOP / SSP_STEP))]
            else:
                name = f"libcosim, {label}"
                x = libcosim_ssp_run(p, element="report_joint", load=("x.f", FMU_LOAD), output="x.s")
            runs[name], ks[name] = x, kk
    return runs, ks


def check_ssp(ctx: Context) -> CheckResult:
    """An exported SSP runs in libcosim and in fmpy, and both apply its SSV: doubling k in the bound
    SSV alone halves the static deflection in each."""
    from ..files import temporary_folder
    from ..joint import Joint
    from ..plots.common import save_figure
    from ..plots.timeseries import plot_timeseries

    joint = Joint.from_coefficients({"x": FMU_JOINT}, name="report_joint")
    with temporary_folder("designer-report-") as tmp:
        runs, ks = _ssp_runs(Path(tmp), joint)
    rows = []
    for name, x in runs.items():
        want = FMU_LOAD / ks[name]
        err = abs(float(x[-1]) - want) / want
        rows.append(
            {
                "check": f"static deflection, {name}",
                "figure": f"{x[-1] * 1e3:.4f} mm against F/k {want * 1e3:.4f} mm (error {err:.1g})",
                "passed": err <= 1e-9,
            }
        )
    t = SSP_STEP * np.arange(1, len(next(iter(runs.values()))) + 1)
    frame = pd.DataFrame({"t": t, **runs})
    title = (
        f"deflection under a {FMU_LOAD:g} N step: libcosim and fmpy, as exported (k) and with k "
        "doubled in the SSV"
    )
    fig = save_figure(
        plot_timeseries(frame, panels={"x.s (m)": list(runs)}, titles={"x.s (m)": title}),
        ctx.figures / "ssp_runners.png",
    )
    table = pd.DataFrame(rows)
    summary = (
        f"{int(table.passed.sum())} of {len(table)} SSP runs settle at F/k: libcosim applies the SSD's "
        "binding, fmpy the set designer.export.ssp.fmpy_parameter_set builds from it; k doubled in the SSV "
        "halves both"
    )
    return CheckResult(
        "SSP: libcosim and fmpy apply the SSV", bool(table.passed.all()), summary, table, [fig]
    )


def joint_numbers(model, name: str) -> dict[str, np.ndarray]:
    """A joint's numbers as MuJoCo compiled them (SI): spring, damping, inertia, limits, placement."""
    j = model.joint(name)
    dof, adr = j.dofadr[0], j.qposadr[0]
    return {
        "stiffness": j.stiffness.copy(),
        "damping": model.dof_damping[dof : dof + 1].copy(),
        "armature": model.dof_armature[dof : dof + 1].copy(),
        "frictionloss": model.dof_frictionloss[dof : dof + 1].copy(),
        "springref": model.qpos_spring[adr : adr + 1].copy(),
        "ref": model.qpos0[adr : adr + 1].copy(),
        "range": j.range.copy(),
        "limited": j.limited.copy(),
        "axis": j.axis.copy(),
        "pos": j.pos.copy(),
    }


def pose_changes(before, after) -> list[str]:
    """The named host bodies whose world pose differs between two models, at the reference pose and
    at each keyframe (by index; also a changed number of keyframes)."""
    import mujoco

    def poses(model, key):
        data = mujoco.MjData(model)
        if key is not None:
            mujoco.mj_resetDataKeyframe(model, data, key)
        mujoco.mj_kinematics(model, data)
        return {model.body(i).name: (data.xpos[i].copy(), data.xquat[i].copy()) for i in range(model.nbody)}

    if before.nkey != after.nkey:
        return [f"{before.nkey} keyframes became {after.nkey}"]
    changed = []
    for key in [None, *range(before.nkey)]:
        old, new = poses(before, key), poses(after, key)
        for body, (pos, quat) in old.items():
            # q and -q are the same orientation
            same = (
                np.allclose(pos, new[body][0], atol=1e-9) and abs(abs(np.dot(quat, new[body][1])) - 1) < 1e-9
            )
            if not same:
                changed.append(f"{body} at {'the reference pose' if key is None else f'keyframe {key}'}")
    return changed


def other_joint_changes(before, after, name: str) -> list[str]:
    """The named joints other than `name` whose compiled numbers differ, with the field."""
    changed = []
    for i in range(before.njnt):
        other = before.joint(i).name
        if other and other != name:
            old, new = joint_numbers(before, other), joint_numbers(after, other)
            changed += [f"{other}.{f}" for f, v in old.items() if not np.array_equal(v, new[f])]
    return changed


def gain_changes(before, after) -> list[str]:
    """The named actuators whose compiled gains differ (gain, bias, dynamics parameters, gear), as
    "name.field old -> new"; MuJoCo resolves a `dampratio` into biasprm[2] from the mass matrix."""
    changed = []
    for i in range(before.nu):
        name = before.actuator(i).name
        if not name:
            continue
        old, new = before.actuator(name), after.actuator(name)
        for field in ("gainprm", "biasprm", "dynprm", "gear"):
            a, b = getattr(old, field), getattr(new, field)
            if not np.array_equal(a, b):
                k = int(np.flatnonzero(a != b)[0])
                changed.append(f"{name}.{field}[{k}] {a[k]:.4g} -> {b[k]:.4g}")
    return changed


#: the MJCF check's host: mujoco's own test model (shipped in the mujoco wheel: tendons, a keyframe,
#: sensors, default classes) and its joint coupled by a fixed tendon
MJCF_HOST, MJCF_HOST_JOINT = "testdata/model.xml", "hipy_0"


def check_mjcf_into(ctx: Context) -> CheckResult:
    """MJCF --into mujoco's test model, in parallel and in series: the joint's k and c exact in SI,
    every other joint's numbers and every body's pose (keyframes too) as the host had them."""
    import shutil

    import mujoco

    from ..export.mjcf import export_mjcf
    from ..files import temporary_folder
    from ..joint import Joint

    joint = Joint.from_coefficients({"theta": {"k": 50.0, "c": 0.5, "m": 1e-5}}, name="report_joint")
    si = joint.axes["theta"].si()
    rows = []
    with temporary_folder("designer-report-") as tmp:
        host = Path(tmp) / "model.xml"
        shutil.copy(Path(mujoco.__file__).parent / MJCF_HOST, host)
        before = mujoco.MjModel.from_xml_path(str(host))
        for form in ("parallel", "series"):
            out = export_mjcf(
                joint, Path(tmp) / f"{form}.xml", into=host, joint_name=MJCF_HOST_JOINT, form=form
            )
            after = mujoco.MjModel.from_xml_path(str(out.path))
            got = joint_numbers(after, MJCF_HOST_JOINT)
            exact = got["stiffness"][0] == si["k"] and got["damping"][0] == si["c"]
            changed = other_joint_changes(before, after, MJCF_HOST_JOINT) + pose_changes(before, after)
            which = ": " + ", ".join(changed[:3]) if changed else ""
            rows.append(
                {
                    "check": f"{form} into mujoco's test model, joint {MJCF_HOST_JOINT}",
                    "figure": (
                        f"k {got['stiffness'][0]:g} N.m/rad, c {got['damping'][0]:g} N.m.s/rad; "
                        f"{len(changed)} other host value(s) changed{which}; "
                        f"{len(out.notes)} note(s)"
                    ),
                    "passed": exact and not changed and bool(out.notes),
                }
            )
    table = pd.DataFrame(rows)
    summary = (
        f"{int(table.passed.sum())} of {len(table)} MJCF --into exports of mujoco's test model keep every "
        f"other joint and body pose (with {before.nkey} keyframe(s)) and set k {si['k']:g} N.m/rad, "
        f"c {si['c']:g} N.m.s/rad"
    )
    return CheckResult(
        "MJCF --into a robot: exact joint, host unchanged", bool(table.passed.all()), summary, table
    )
