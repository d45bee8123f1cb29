"""`designer validate`: run every check (designer.checks) and render the report in HTML and Markdown.

The report is written into a new folder beside the target and swapped in at the end, so an
interrupted run leaves the previous report whole (or no report), never a mix of old and new.
"""

from __future__ import annotations

import html
import time
from collections.abc import Callable
from pathlib import Path

from .checks import CheckResult, Context, run_checks
from .data import load_table
from .files import atomic_folder, atomic_write


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
        results = run_checks(Context(data, figures, source), progress=progress)
        seconds = time.perf_counter() - start
        write_report(results, tmp, seconds)
        # the figures' paths as they will be once the folder is in place
        for r in results:
            r.figures = [Path(outdir) / p.relative_to(tmp) for p in r.figures]
    out = Path(outdir)
    return results, out / "report.html", out / "report.md", seconds
