"""`designer validate`: every check the tool can make of itself, each with its verdict and figure.

A check is a function of a `Context` returning a `CheckResult` (name, passed, summary, a table of
the numbers behind the verdict, figures). `run_checks` runs them in order; `write_report` writes
`report.html` and `report.md` with the figures beside them in `figures/`.
"""

from __future__ import annotations

import html
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from . import space
from .data import coefficient_columns, load_table, table_hash
from .errors import DesignerError
from .files import atomic_write
from .units import rig_unit


@dataclass
class CheckResult:
    """The verdict of one check and the evidence for it."""

    name: str
    passed: bool
    summary: str
    table: pd.DataFrame | None = None
    figures: list[Path] = field(default_factory=list)
    seconds: float = 0.0

    def to_dict(self) -> dict:
        return {
            "name": self.name,
            "passed": self.passed,
            "summary": self.summary,
            "table": None if self.table is None else self.table.to_dict(orient="records"),
            "figures": [str(p) for p in self.figures],
            "seconds": self.seconds,
        }


@dataclass
class Context:
    """What the checks share: the coefficient table, where figures go, the surrogate (made once)."""

    table: pd.DataFrame
    figures: Path
    source: str = "bundled study table"
    _surrogate: object = None

    @property
    def surrogate(self):
        """The shipped surrogate when it was fitted to this table, else one fitted to it now."""
        if self._surrogate is None:
            from .surrogate import Surrogate

            sur = Surrogate.load_default()
            if sur.table_hash != table_hash(self.table):
                sur = Surrogate().fit(self.table)
            self._surrogate = sur
        return self._surrogate


# --- checks --------------------------------------------------------------------------------------


def check_dataset(ctx: Context) -> CheckResult:
    """The table holds the six factors at tested values and positive coefficients, with no gaps."""
    from .plots.heatmap import plot_heatmap

    t = ctx.table
    rows, problems = [], []
    for f in space.FACTORS:
        values = t[f.name]
        off = values[~values.between(f.low - 1e-9, f.high + 1e-9)]
        if len(off):
            problems.append(f"{f.name} has {len(off)} value(s) outside {f.describe_range()}")
        levels = ", ".join(f"{v:g}: {n}" for v, n in values.value_counts().sort_index().items())
        rows.append(
            {
                "column": f.name,
                "unit": f.unit,
                "min": values.min(),
                "max": values.max(),
                "runs per level": levels,
            }
        )
    coefs = coefficient_columns(t)
    for col in coefs:
        quantity, axis = col.split("_", 1)
        v = t[col]
        rows.append(
            {
                "column": col,
                "unit": rig_unit(quantity, axis),
                "min": v.min(),
                "max": v.max(),
                "runs per level": f"median {v.median():.4g}, CV {v.std() / v.mean():.0%}",
            }
        )
    fig = plot_heatmap(t, coefs, ctx.figures / "dataset_heatmap.png")
    summary = (
        f"{len(t)} runs from the {ctx.source} (sha256 {table_hash(t)[:12]}), responses {', '.join(coefs)}"
        + ("; " + "; ".join(problems) if problems else "; every factor within its tested range")
    )
    return CheckResult("Dataset summary", not problems and len(t) > 0, summary, pd.DataFrame(rows), [fig])


#: directions of main effects the study states for x (Figs 5-6 and their text): (response, factor, sign);
#: sign -1: the median falls from the factor's lowest to its highest level. "The thicker, the more
#: damping" is read for both width and height.
STUDY_EFFECTS: tuple[tuple[str, str, int], ...] = (
    ("k_x", "width", -1),
    ("k_x", "height", -1),
    ("k_x", "length", -1),
    ("k_x", "layer", -1),
    ("k_x", "raster", -1),
    ("c_x", "layer", -1),
    ("c_x", "width", +1),
    ("c_x", "height", +1),
)
#: factors significant for k_x in the study's Table 4 (p < 0.05): only their directions must agree
SIGNIFICANT_K_X = ("width", "height", "layer")


def check_main_effects(ctx: Context) -> CheckResult:
    """Medians move as the study's effect plots say, for each factor its Table 4 finds significant."""
    from .plots.effects import main_effects, plot_effects

    responses = [r for r in ("c_x", "k_x") if r in ctx.table.columns]
    if "k_x" not in responses:
        raise DesignerError(
            "the table has no k_x column", "the study's effects are on the x axis: give c_x, k_x"
        )
    med = main_effects(ctx.table, responses).set_index(["response", "factor", "level"])["median"].sort_index()
    rows = []
    for resp, fac, sign in STUDY_EFFECTS:
        if resp not in responses:
            continue
        m = med.loc[(resp, fac)]
        lo, hi = float(m.iloc[0]), float(m.iloc[-1])
        agrees = (hi - lo) * sign > 0
        binding = resp == "k_x" and fac in SIGNIFICANT_K_X
        rows.append(
            {
                "response": resp,
                "factor": fac,
                "study says": "falls" if sign < 0 else "rises",
                "median at low": lo,
                "median at high": hi,
                "agrees": agrees,
                "counts": "yes" if binding else "no (not significant in Table 4)",
            }
        )
    table = pd.DataFrame(rows)
    binding = table[table["counts"] == "yes"]
    fig = plot_effects(ctx.table, responses, ctx.figures / "main_effects.png")
    summary = (
        f"{int(binding.agrees.sum())} of {len(binding)} directions the study finds significant agree; "
        f"{int(table.agrees.sum())} of {len(table)} stated directions agree in all"
    )
    return CheckResult(
        "Main effects as the study's Figs 5-6", bool(binding.agrees.all()), summary, table, [fig]
    )


#: a response's LOO coverage fails when a count this low has below this probability for a true 95 % PI
COVERAGE_P = 0.01


def check_surrogate_loo(ctx: Context) -> CheckResult:
    """Leave-one-out metrics per response, and whether its 95 % PIs cover as often as they claim."""
    from scipy.stats import binom

    from .plots.loo import loo_table, plot_loo

    sur = ctx.surrogate
    rows = []
    for resp in sur.responses:
        model = sur.model(resp)
        d = loo_table(sur, resp)
        covered, n = int(d.covered.sum()), len(d)
        p_low = float(binom.cdf(covered, n, 0.95))
        rows.append(
            {
                "response": resp,
                "form": model.form,
                "Q2": model.loo["q2"],
                "RMSE": f"{model.loo['rmse']:.3g} {model.unit}",
                "MAPE %": model.loo["mape"],
                "PI coverage": f"{covered}/{n} ({covered / n:.0%})",
                "P(count this low)": p_low,
                "coverage ok": p_low >= COVERAGE_P,
                "explains": "some of the variation" if model.predictable else "nothing beyond the mean",
            }
        )
    table = pd.DataFrame(rows)
    fig = plot_loo(sur, sur.responses, ctx.figures / "surrogate_loo.png")
    summary = "; ".join(
        f"{r['response']}: {r['form']}, Q2 {r['Q2']:.2f}, 95 % PI covers {r['PI coverage']}" for r in rows
    )
    return CheckResult(
        "Surrogate leave-one-out and PI coverage", bool(table["coverage ok"].all()), summary, table, [fig]
    )


def check_table4(ctx: Context) -> CheckResult:
    """Our type III ANOVA of k_x against the study's Table 4: F and p side by side."""
    from .plots.checks import plot_table4
    from .stats import TABLE4_NOTE, compare_table4

    if "k_x" not in ctx.table.columns:
        raise DesignerError("the table has no k_x column", "Table 4 is the ANOVA of k_x: give c_x, k_x")
    cmp = compare_table4(ctx.table)
    fig = plot_table4(cmp, ctx.figures / "table4.png")
    ours = {s for s, sig in zip(cmp.source, cmp.significant, strict=True) if sig}
    summary = (
        f"{int(cmp.agrees.sum())} of {len(cmp)} sources agree (F within 10 % where the paper's F > 1, same "
        f"verdict at alpha 0.05); significant: {', '.join(sorted(ours))}. {TABLE4_NOTE}"
    )
    return CheckResult("The study's Table 4 against ours", bool(cmp.agrees.all()), summary, cmp, [fig])


#: the joint of the FMU checks: the study's x axis near its middle (rig units, kg) and the study's
#: 280 g static load, N
FMU_JOINT = {"k": 0.8, "c": 2e-3, "m": 0.01}
FMU_LOAD = 2.744
#: largest relative error of the step response: exact ZOH (co-simulation), fmpy's CVode (model exchange)
FMU_TOLERANCE = {"CoSimulation": 1e-9, "ModelExchange": 1e-5}
FMU_STOP = 0.5


def _step_response(m: float, c: float, k: float, force: float, t):
    """Displacement of m y'' + c y' + k y = force from rest (SI, under-damped)."""
    import numpy as np

    wn, z = np.sqrt(k / m), c / (2 * np.sqrt(k * m))
    wd = wn * np.sqrt(1 - z * z)
    decay = np.exp(-z * wn * t) * (np.cos(wd * t) + z / np.sqrt(1 - z * z) * np.sin(wd * t))
    return force / k * (1 - decay)


def _libcosim_step(path: Path, steps: int, step: float) -> object:
    """The body FMU's displacement after each step under the static load, run by libcosimpy."""
    import numpy as np
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    from .export.fmu import value_reference

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


def check_fmu(ctx: Context) -> CheckResult:
    """FMI 2 and 3 archives pass validate_fmu; the body step response matches the analytic one in fmpy
    (co-simulation and model exchange) and in libcosimpy."""
    import tempfile

    import numpy as np
    from fmpy import simulate_fmu
    from fmpy.validation import validate_fmu

    from .export.fmu import export_fmu
    from .joint import from_coefficients
    from .plots.timeseries import plot_timeseries

    joint = from_coefficients({"x": FMU_JOINT}, name="report_joint")
    m, c, k = (joint.axes["x"].si()[q] for q in ("m", "c", "k"))
    rows, curves = [], {}
    t = np.linspace(0.0, FMU_STOP, int(round(FMU_STOP / 1e-3)) + 1)
    exact = _step_response(m, c, k, FMU_LOAD, t)
    scale = np.max(np.abs(exact))
    with tempfile.TemporaryDirectory(prefix="designer-report-") as tmp:
        for version in (2, 3):
            for interface in ("force", "body"):
                path = export_fmu(joint, Path(tmp) / f"joint{version}{interface}.fmu", version, interface)
                problems = validate_fmu(str(path))
                rows.append(
                    {
                        "check": f"validate_fmu FMI {version} {interface}",
                        "figure": f"{len(problems)} problem(s)",
                        "passed": not problems,
                    }
                )
            body = Path(tmp) / f"joint{version}body.fmu"
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
                rows.append(
                    {
                        "check": f"fmpy step response FMI {version} {fmi_type}",
                        "figure": f"max error {err:.2g} of the peak (limit {tol:g})",
                        "passed": err <= tol,
                    }
                )
        try:
            s = _libcosim_step(Path(tmp) / "joint2body.fmu", len(t) - 1, 1e-3)
        except ImportError:
            rows.append(
                {"check": "libcosimpy", "figure": "skipped: libcosimpy not installed", "passed": True}
            )
        else:
            err = float(np.max(np.abs(s - exact[1:])) / scale)
            tol = FMU_TOLERANCE["CoSimulation"]
            rows.append(
                {
                    "check": "libcosimpy step response FMI 2 CoSimulation",
                    "figure": f"max error {err:.2g} of the peak (limit {tol:g})",
                    "passed": err <= tol,
                }
            )
    frame = pd.DataFrame({"t": t, "analytic": exact, **curves})
    errors = {f"{name} error": curves[name] - exact for name in curves}
    frame = frame.assign(**errors)
    fig = plot_timeseries(
        frame,
        ctx.figures / "fmu_step_response.png",
        panels={"x.s (m)": ["analytic", *curves], "error (m)": list(errors)},
    )
    table = pd.DataFrame(rows)
    summary = (
        f"{int(table.passed.sum())} of {len(table)} FMU checks pass: joint k {FMU_JOINT['k']:g} N/mm, "
        f"c {FMU_JOINT['c']:g} N.s/mm, m {FMU_JOINT['m']:g} kg under a {FMU_LOAD:g} N step"
    )
    return CheckResult(
        "FMUs: validate_fmu, analytic step, second importer", bool(table.passed.all()), summary, table, [fig]
    )


#: coefficient sets of the closed loop (rig units): the bundled table's lowest, middle and highest
#: k_x, and the example joint's theta axis
IDENTIFY_SETS: tuple[tuple[str, dict[str, float]], ...] = (
    ("x", {"k": 0.246, "c": 4.91e-4, "m": 1e-3}),
    ("x", {"k": 0.8, "c": 2e-3, "m": 1e-3}),
    ("x", {"k": 2.09, "c": 4.52e-3, "m": 1e-3}),
    ("theta", {"k": 330.0, "c": 0.83, "m": 2e-6}),
)
IDENTIFY_SECONDS = 60.0
IDENTIFY_TOLERANCE_PCT = 1.0


def check_identification(ctx: Context) -> CheckResult:
    """The virtual rig's log (1 % force noise, dropouts), identified, gives back k and c within 1 %."""
    from .plots.checks import plot_identification
    from .rig.identify import identify
    from .rig.logs import validate_frame
    from .rig.simulate import simulate

    rows = []
    for i, (axis, coef) in enumerate(IDENTIFY_SETS):
        log = simulate({axis: coef}, duration=IDENTIFY_SECONDS, noise=0.01, dropouts=0.001, seed=i)
        fit = identify(validate_frame(log, source="virtual rig"))[0].axes[axis]
        k_err, c_err = 100 * (fit.k / coef["k"] - 1), 100 * (fit.c / coef["c"] - 1)
        rows.append(
            {
                "set": f"{axis}: k {coef['k']:g}, c {coef['c']:g}",
                "k true": f"{coef['k']:g} {rig_unit('k', axis)}",
                "k identified": fit.k,
                "k error %": k_err,
                "c true": f"{coef['c']:g} {rig_unit('c', axis)}",
                "c identified": fit.c,
                "c error %": c_err,
                "R2": fit.r2,
                "within": max(abs(k_err), abs(c_err)) <= IDENTIFY_TOLERANCE_PCT,
            }
        )
    table = pd.DataFrame(rows)
    fig = plot_identification(table, IDENTIFY_TOLERANCE_PCT, ctx.figures / "identification.png")
    worst = table[["k error %", "c error %"]].abs().max()
    summary = (
        f"{int(table.within.sum())} of {len(table)} sets within {IDENTIFY_TOLERANCE_PCT:g} % on "
        f"{IDENTIFY_SECONDS:g} s logs; worst k error {worst['k error %']:.2g} %, worst c error "
        f"{worst['c error %']:.2g} %"
    )
    return CheckResult("Identification closed loop", bool(table.within.all()), summary, table, [fig])


#: the co-simulated arm (as examples/two_link_arm.toml, over 2 s): macro steps of the convergence
COSIM_STEPS = (4e-3, 2e-3, 1e-3, 5e-4)
COSIM_SECONDS = 2.0
#: co-simulation and the same spring-damper inside MuJoCo agree to round-off at each step, rad
COSIM_SAME_STEP = 1e-9
#: smallest observed order of convergence against the fine reference (Euler: first order)
COSIM_ORDER = 0.8


def _frame(res) -> pd.DataFrame:
    frame = pd.DataFrame(res.values, columns=res.columns)
    frame.insert(0, "t", res.time)
    return frame


def check_cosim(ctx: Context) -> CheckResult:
    """The arm co-simulated with two joint FMUs converges to the in-engine reference with the macro step."""
    import numpy as np

    from .cosim import run
    from .cosim.references import Sine, Step
    from .cosim.scenario import JointSource, Scenario
    from .joint import from_coefficients
    from .plots.checks import plot_convergence
    from .plots.timeseries import plot_timeseries

    joint = JointSource(axis="theta", joint=from_coefficients({"theta": {"k": 330.0, "c": 0.83}}))
    sc = Scenario(
        path=Path("two-link arm (report)"),
        kind="robot",
        duration=COSIM_SECONDS,
        step=1e-3,
        joints={"j1": joint, "j2": joint},
        motors={"j1": Sine(0.5, 0.5), "j2": Step(0.3, 1.0)},
        validation_steps=COSIM_STEPS,
        validation_duration=COSIM_SECONDS,
    )
    with run.joint_fmus(sc) as fmus:
        laws = {name: run.law(src, fmus[name]) for name, src in sc.joints.items()}
        val = run.validate(sc, fmus, laws)
        cosim = _frame(run.robot_run(sc, fmus, sc.step, sc.duration, sc.algorithm))
        reference = _frame(run.robot_reference(sc, laws, sc.step, sc.duration, sc.integrator))
    steps = pd.DataFrame(val["steps"]).sort_values("step", ascending=False, ignore_index=True)
    err = steps["max_error"].to_numpy()
    steps["order"] = np.concatenate([[np.nan], np.log2(err[:-1] / err[1:])])
    ok = bool(
        (steps["max_error_same_step"] <= COSIM_SAME_STEP).all()
        and (steps["order"].iloc[1:] >= COSIM_ORDER).all()
    )
    figs = [
        plot_convergence(
            steps[["step", "max_error", "max_error_same_step"]].rename(
                columns={
                    "max_error": f"against RK4 at {min(COSIM_STEPS) / 4:g} s",
                    "max_error_same_step": "against MuJoCo in-engine",
                }
            ),
            ctx.figures / "cosim_convergence.png",
            "rad",
        ),
        plot_timeseries(
            cosim,
            ctx.figures / "cosim_arm.png",
            ["robot.j1.q", "robot.j2.q", "j1.theta.f", "j2.theta.f"],
            reference=reference,
        ),
    ]
    summary = (
        f"two-link arm, Gauss-Seidel, {COSIM_SECONDS:g} s: error against the fine reference "
        + ", ".join(f"{r.max_error:.2g} rad at {r.step:g} s" for r in steps.itertuples())
        + f" (order {steps['order'].iloc[1:].min():.2f} or better); against the same spring-damper inside "
        f"MuJoCo at most {steps['max_error_same_step'].max():.1g} rad. Reference: {val['reference']}"
    )
    return CheckResult("Co-simulation convergence", ok, summary, steps, figs)


#: the checks `designer validate` runs, in report order
CHECKS: tuple[Callable[[Context], CheckResult], ...] = (
    check_dataset,
    check_table4,
    check_main_effects,
    check_surrogate_loo,
    check_fmu,
    check_identification,
    check_cosim,
)


def run_checks(
    ctx: Context,
    checks: tuple[Callable[[Context], CheckResult], ...] = CHECKS,
    progress: Callable[[float], None] | None = None,
) -> list[CheckResult]:
    """Run each check, timing it; a check that raises fails with the error as its summary."""
    results = []
    for i, check in enumerate(checks):
        start = time.perf_counter()
        try:
            result = check(ctx)
        except DesignerError as exc:
            result = CheckResult(_title(check), False, f"could not run: {exc}")
        result.seconds = time.perf_counter() - start
        results.append(result)
        if progress is not None:
            progress((i + 1) / len(checks))
    return results


def _title(check: Callable) -> str:
    return check.__name__.removeprefix("check_").replace("_", " ").capitalize()


# --- writing -------------------------------------------------------------------------------------


def _fmt(v) -> str:
    if isinstance(v, bool):
        return "yes" if v else "NO"
    if isinstance(v, float):
        return f"{v:.4g}"
    return str(v)


def _markdown(results: list[CheckResult], outdir: Path, header: str) -> str:
    lines = [
        "# flexjoint designer validation report",
        "",
        header,
        "",
        "| check | verdict | summary |",
        "| --- | --- | --- |",
    ]
    lines += [f"| {r.name} | {'PASS' if r.passed else 'FAIL'} | {r.summary} |" for r in results]
    for r in results:
        lines += ["", f"## {r.name}: {'PASS' if r.passed else 'FAIL'}", "", r.summary, ""]
        if r.table is not None and len(r.table):
            cols = list(r.table.columns)
            lines += ["| " + " | ".join(cols) + " |", "|" + " --- |" * len(cols)]
            lines += [
                "| " + " | ".join(_fmt(v) for v in row) + " |" for row in r.table.itertuples(index=False)
            ]
            lines.append("")
        lines += [f"![{r.name}]({p.relative_to(outdir).as_posix()})" for p in r.figures]
    return "\n".join(lines) + "\n"


_CSS = (
    "body{font-family:sans-serif;max-width:1200px;margin:auto;padding:1em;color:#222}"
    "table{border-collapse:collapse;margin:.5em 0}"
    "td,th{border:1px solid #ccc;padding:3px 8px;font-size:13px}"
    ".pass{background:#2a7;color:#fff;padding:1px 6px;border-radius:3px}"
    ".fail{background:#c33;color:#fff;padding:1px 6px;border-radius:3px}img{max-width:100%}"
)


def _html(results: list[CheckResult], outdir: Path, header: str) -> str:
    def verdict(r: CheckResult) -> str:
        return f'<span class="{"pass" if r.passed else "fail"}">{"PASS" if r.passed else "FAIL"}</span>'

    e = html.escape
    parts = [
        "<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>",
        f"<title>flexjoint designer validation</title><style>{_CSS}</style></head><body>",
        "<h1>flexjoint designer validation report</h1>",
        f"<p id='overall' data-passed='{sum(r.passed for r in results)}' data-checks='{len(results)}'>",
        f"{e(header)}</p>",
        "<table><tr><th>check</th><th>verdict</th><th>summary</th></tr>",
    ]
    parts += [
        f"<tr><td><a href='#c{i}'>{e(r.name)}</a></td><td>{verdict(r)}</td><td>{e(r.summary)}</td></tr>"
        for i, r in enumerate(results)
    ]
    parts.append("</table>")
    for i, r in enumerate(results):
        parts.append(f"<h2 id='c{i}' class='check'>{e(r.name)} {verdict(r)}</h2><p>{e(r.summary)}</p>")
        if r.table is not None and len(r.table):
            parts.append("<table><tr>" + "".join(f"<th>{e(str(c))}</th>" for c in r.table.columns) + "</tr>")
            parts += [
                "<tr>" + "".join(f"<td>{e(_fmt(v))}</td>" for v in row) + "</tr>"
                for row in r.table.itertuples(index=False)
            ]
            parts.append("</table>")
        parts += [
            f"<p><img src='{e(p.relative_to(outdir).as_posix())}' alt='{e(r.name)}'></p>" for p in r.figures
        ]
    parts.append("</body></html>")
    return "\n".join(parts)


def write_report(results: list[CheckResult], outdir: Path, seconds: float) -> tuple[Path, Path]:
    """Write report.html and report.md into `outdir` (figures already in `outdir/figures`)."""
    passed = sum(r.passed for r in results)
    header = f"{passed} of {len(results)} checks pass; run took {seconds:.1f} s."
    md, page = outdir / "report.md", outdir / "report.html"
    with atomic_write(md) as fh:
        fh.write(_markdown(results, outdir, header))
    with atomic_write(page) as fh:
        fh.write(_html(results, outdir, header))
    return page, md


def validate(
    outdir: str | Path, table_path: str | Path | None = None, progress: Callable[[float], None] | None = None
) -> tuple[list[CheckResult], Path, Path, float]:
    """Run every check on the table (default: the bundled study) and write the report into `outdir`."""
    start = time.perf_counter()
    outdir = Path(outdir)
    if outdir.exists() and not outdir.is_dir():
        raise DesignerError(f"{outdir} is a file", "give a folder for the report")
    figures = outdir / "figures"
    figures.mkdir(parents=True, exist_ok=True)
    ctx = Context(
        load_table(table_path), figures, "bundled study table" if table_path is None else str(table_path)
    )
    results = run_checks(ctx, progress=progress)
    seconds = time.perf_counter() - start
    page, md = write_report(results, outdir, seconds)
    return results, page, md, seconds
