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


#: the checks `designer validate` runs, in report order
CHECKS: tuple[Callable[[Context], CheckResult], ...] = (
    check_dataset,
    check_main_effects,
    check_surrogate_loo,
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
