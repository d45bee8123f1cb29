"""Check of a coefficient table: the six factors at tested values, positive coefficients, no gaps."""

from __future__ import annotations

import pandas as pd

from ..study import space
from ..study.data import coefficient_columns, table_hash
from ..units import rig_unit
from .checks import CheckResult, Context


def check_dataset(ctx: Context) -> CheckResult:
    """The table holds the six factors at tested values and positive coefficients, with no gaps."""
    from ..plots.common import save_figure
    from ..plots.heatmap import plot_heatmap

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
    fig = save_figure(plot_heatmap(t, responses=coefs), ctx.figures / "dataset_heatmap.png")
    summary = (
        f"{len(t)} runs from the {ctx.source} (sha256 {table_hash(t)[:12]}), responses {', '.join(coefs)}"
        + ("; " + "; ".join(problems) if problems else "; every factor within its tested range")
    )
    return CheckResult("Dataset summary", not problems and len(t) > 0, summary, pd.DataFrame(rows), [fig])
