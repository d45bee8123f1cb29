"""`designer validate`: run every check (designer.validate.checks) and render the report in HTML and Markdown.

The report is written into a new folder beside the target and swapped in at the end, so an
interrupted run leaves the previous report whole (or no report), never a mix of old and new.
"""

from __future__ import annotations

import base64
import hashlib
import html
import math
import platform
import subprocess
import time
from collections.abc import Callable, Mapping
from datetime import datetime, timezone
from pathlib import Path

from ..files import atomic_folder, atomic_write
from ..study.data import load_table
from .checks import CheckResult, Context, run_checks

#: the checks' raw column names as a reader wants them, with units
COLUMN_NAMES = {
    "F_paper": "F, paper",
    "F": "F, ours",
    "F_diff_pct": "F difference (%)",
    "p_paper": "p, paper",
    "p": "p, ours",
    "step": "macro step (s)",
    "max_error": "max error against RK4 (rad)",
    "max_error_same_step": "max error against MuJoCo, same step (rad)",
    "order": "observed order",
    "figure": "result",
}
#: a caption per figure of the checks (by file name), saying what is drawn and how to read it
CAPTIONS = {
    "dataset_heatmap": "Pearson correlations between the six factors and the responses over the runs "
    "(the study's Fig 13); red positive, blue negative.",
    "table4": "F of each source of k_x (type III, log scale): the paper's Table 4 (grey) against ours on "
    "the bundled Table 3 (blue); the dotted line is F = 1.",
    "main_effects": "Main effects: each response's runs per factor level as box plots, medians in red "
    "(the study's Figs 5-12).",
    "surrogate_loo": "Nested leave-one-out: each run's prediction with its 95 % interval, by a surrogate "
    "fitted (form and penalty chosen) without that run, against the measurement; red where the interval "
    "misses.",
    "fmu_step_response": "Body-interface FMUs (FMI 2 and 3, co-simulation and model exchange) under a step "
    "load against the analytic solution: the solutions coincide (top, wider lines underneath), their errors "
    "below.",
    "identification": "Closed loop: joints simulated on the virtual rig, then identified from the log; "
    "identified over true, minus one, for k (circles) and c (squares), the 1 % band shaded.",
    "ssp_runners": "An exported SSP run in libcosim and in fmpy under a step load: each settles at F/k; with "
    "k doubled in the bound SSV alone the deflection halves in both (the curves of one k coincide).",
    "cosim_convergence": "Two-link arm: largest joint-angle error against macro step, against an RK4 "
    "reference at a quarter of the finest step (first order expected; the dashed guide of slope 1 runs "
    "above the RK4 errors) and against the same spring-damper inside MuJoCo at the same step (round-off).",
    "cosim_arm": "Two-link arm, co-simulated: link angles (top) with the reference dashed, and the joints' "
    "torques (bottom); one colour per joint.",
}


def _fmt(v) -> str:
    if isinstance(v, bool):
        return "yes" if v else "NO"
    if isinstance(v, float):
        return "\u2014" if math.isnan(v) else f"{v:.4g}"
    return str(v)


def _column(name: object) -> str:
    return COLUMN_NAMES.get(str(name), str(name))


def _caption(figure: Path) -> str:
    return CAPTIONS.get(figure.stem, figure.stem.replace("_", " "))


def _code_version() -> str:
    """The git commit of the checkout the package runs from (marked when it has uncommitted changes),
    else a hash of the installed package's files."""
    root = Path(__file__).resolve().parent
    try:
        head = subprocess.run(
            ["git", "-C", str(root.parent), "rev-parse", "--short=12", "HEAD"],
            capture_output=True, text=True, timeout=10,
        )  # fmt: skip
        inside = subprocess.run(
            ["git", "-C", str(root.parent), "ls-files", "--error-unmatch", str(Path(__file__).resolve())],
            capture_output=True, text=True, timeout=10,
        )  # fmt: skip
        if head.returncode == 0 and inside.returncode == 0:
            dirty = subprocess.run(
                ["git", "-C", str(root.parent), "status", "--porcelain", "--", "designer", "fmus", "cli"],
                capture_output=True, text=True, timeout=10,
            ).stdout.strip()  # fmt: skip
            return f"commit {head.stdout.strip()}" + (" with uncommitted changes" if dirty else "")
    except (OSError, subprocess.SubprocessError):
        pass
    digest = hashlib.sha256()
    for f in sorted(p for p in root.rglob("*") if p.is_file() and "__pycache__" not in p.parts):
        digest.update(f.relative_to(root).as_posix().encode() + b"\0" + f.read_bytes())
    return f"package sha256 {digest.hexdigest()[:12]}"


def provenance(ctx: Context | None = None) -> dict[str, str]:
    """What a reader needs to know which run this was: date (UTC), tool version, commit or package
    hash, platform; with the checks' context also the surrogate id and the table's hash and source."""
    from .. import __version__

    out = {
        "date": datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        "tool": f"flexjoint designer {__version__}",
        "code": _code_version(),
        "platform": f"{platform.system()} {platform.machine()}, Python {platform.python_version()}",
    }
    if ctx is not None:
        from ..study.data import table_hash

        out |= {
            "surrogate": ctx.surrogate.id,
            "data": f"{ctx.source}, {len(ctx.table)} runs, sha256 {table_hash(ctx.table)[:12]}",
        }
    return out


def _markdown(results: list[CheckResult], outdir: Path, header: str, about: Mapping[str, str]) -> str:
    lines = [
        "# flexjoint designer validation report",
        "",
        header,
        "",
        *[f"- {k}: {v}" for k, v in about.items()],
        "",
        "| check | verdict | summary |",
        "| --- | --- | --- |",
    ]
    lines += [f"| {r.name} | {'PASS' if r.passed else 'FAIL'} | {r.summary} |" for r in results]
    for r in results:
        lines += ["", f"## {r.name}: {'PASS' if r.passed else 'FAIL'}", "", r.summary, ""]
        if r.table is not None and len(r.table):
            cols = [_column(c) for c in r.table.columns]
            lines += ["| " + " | ".join(cols) + " |", "|" + " --- |" * len(cols)]
            lines += [
                "| " + " | ".join(_fmt(v) for v in row) + " |" for row in r.table.itertuples(index=False)
            ]
            lines.append("")
        for p in r.figures:
            lines += [f"![{r.name}]({p.relative_to(outdir).as_posix()})", "", f"*{_caption(p)}*", ""]
    return "\n".join(lines) + "\n"


_CSS = (
    "body{font-family:sans-serif;max-width:1200px;margin:auto;padding:1em;color:#222}"
    "table{border-collapse:collapse;margin:.5em 0}"
    "td,th{border:1px solid #ccc;padding:3px 8px;font-size:13px}"
    ".pass{background:#2a7;color:#fff;padding:1px 6px;border-radius:3px}"
    ".fail{background:#c33;color:#fff;padding:1px 6px;border-radius:3px}img{max-width:100%;height:auto}"
    "figure{margin:1em 0}figcaption{font-size:13px;color:#444;max-width:900px}"
    "dl{display:grid;grid-template-columns:max-content 1fr;gap:2px 12px;font-size:13px}"
    "dt{color:#555}dd{margin:0}"
    ".wide{overflow-x:auto;max-width:100%}"
)


def _data_uri(png: Path) -> str:
    """The picture inside the page (so report.html travels alone)."""
    return "data:image/png;base64," + base64.b64encode(png.read_bytes()).decode("ascii")


def _html(results: list[CheckResult], outdir: Path, header: str, about: Mapping[str, str]) -> str:
    def verdict(r: CheckResult) -> str:
        return f'<span class="{"pass" if r.passed else "fail"}">{"PASS" if r.passed else "FAIL"}</span>'

    e = html.escape
    parts = [
        "<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>",
        "<meta name='viewport' content='width=device-width, initial-scale=1'>",
        f"<title>flexjoint designer validation</title><style>{_CSS}</style></head><body>",
        "<h1>flexjoint designer validation report</h1>",
        f"<p id='overall' data-passed='{sum(r.passed for r in results)}' data-checks='{len(results)}'>",
        f"{e(header)}</p>",
        "<dl id='provenance'>"
        + "".join(f"<dt>{e(k)}</dt><dd>{e(v)}</dd>" for k, v in about.items())
        + "</dl>",
        "<div class='wide'><table><tr><th>check</th><th>verdict</th><th>summary</th></tr>",
    ]
    parts += [
        f"<tr><td><a href='#c{i}'>{e(r.name)}</a></td><td>{verdict(r)}</td><td>{e(r.summary)}</td></tr>"
        for i, r in enumerate(results)
    ]
    parts.append("</table></div>")
    for i, r in enumerate(results):
        parts.append(f"<h2 id='c{i}' class='check'>{e(r.name)} {verdict(r)}</h2><p>{e(r.summary)}</p>")
        if r.table is not None and len(r.table):
            parts.append(
                "<div class='wide'><table><tr>"
                + "".join(f"<th>{e(_column(c))}</th>" for c in r.table.columns)
                + "</tr>"
            )
            parts += [
                "<tr>" + "".join(f"<td>{e(_fmt(v))}</td>" for v in row) + "</tr>"
                for row in r.table.itertuples(index=False)
            ]
            parts.append("</table></div>")
        parts += [
            f"<figure><img src='{_data_uri(p)}' alt='{e(_caption(p))}'>"
            f"<figcaption>{e(_caption(p))} ({e(p.name)})</figcaption></figure>"
            for p in r.figures
        ]
    parts.append("</body></html>")
    return "\n".join(parts)


def write_report(
    results: list[CheckResult], outdir: Path, seconds: float, *, about: Mapping[str, str] | None = None
) -> tuple[Path, Path]:
    """Write report.html (figures embedded, one file that travels) and report.md (figures linked)
    into `outdir` (figures already in `outdir/figures`); `about`: the run's `provenance`."""
    passed = sum(r.passed for r in results)
    header = f"{passed} of {len(results)} checks pass; run took {seconds:.1f} s."
    about = provenance() if about is None else about
    md, page = outdir / "report.md", outdir / "report.html"
    with atomic_write(md) as fh:
        fh.write(_markdown(results, outdir, header, about))
    with atomic_write(page) as fh:
        fh.write(_html(results, outdir, header, about))
    return page, md


def validate(
    outdir: str | Path,
    *,
    table: str | Path | None = None,
    progress: Callable[[float], None] | None = None,
) -> tuple[list[CheckResult], Path, Path, float]:
    """Run every check on `table` (a path or DataFrame; None: the bundled study) and write the report.

    Returns:
        (results, report.html, report.md, seconds). The figures go to `outdir/figures`.

    Raises:
        DesignerError: `outdir` is a file or cannot be written, or the table is malformed.
    """
    start = time.perf_counter()
    source = "bundled study table" if table is None else str(table)
    data = load_table(table)
    with atomic_folder(outdir) as tmp:
        figures = tmp / "figures"
        figures.mkdir()
        ctx = Context(data, figures, source)
        results = run_checks(ctx, progress=progress)
        seconds = time.perf_counter() - start
        write_report(results, tmp, seconds, about=provenance(ctx))
        # the figures' paths as they will be once the folder is in place
        for r in results:
            r.figures = [Path(outdir) / p.relative_to(tmp) for p in r.figures]
    out = Path(outdir)
    return results, out / "report.html", out / "report.md", seconds
