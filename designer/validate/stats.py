"""Checks of the statistics against the study: its Table 4 ANOVA and the directions of Figs 5-6."""

from __future__ import annotations

import pandas as pd

from ..errors import DesignerError
from .checks import CheckResult, Context


def check_table4(ctx: Context) -> CheckResult:
    """Our type III ANOVA of k_x against the study's Table 4: F and p side by side."""
    from ..plots.checks import plot_table4
    from ..plots.common import save_figure
    from ..study.stats import TABLE4_NOTE, compare_table4

    if "k_x" not in ctx.table.columns:
        raise DesignerError("the table has no k_x column", "Table 4 is the ANOVA of k_x: give c_x, k_x")
    cmp = compare_table4(ctx.table)
    fig = save_figure(plot_table4(cmp), ctx.figures / "table4.png")
    ours = {s for s, sig in zip(cmp.source, cmp.significant, strict=True) if sig}
    summary = (
        f"{int(cmp.agrees.sum())} of {len(cmp)} sources agree (F within 10 % where the paper's F > 1, same "
        f"verdict at alpha 0.05); significant: {', '.join(sorted(ours))}. {TABLE4_NOTE}"
    )
    return CheckResult("The study's Table 4 against ours", bool(cmp.agrees.all()), summary, cmp, [fig])


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
    from ..plots.common import save_figure
    from ..plots.effects import main_effects, plot_effects

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
    fig = save_figure(plot_effects(ctx.table, responses=responses), ctx.figures / "main_effects.png")
    summary = (
        f"{int(binding.agrees.sum())} of {len(binding)} directions the study finds significant agree; "
        f"{int(table.agrees.sum())} of {len(table)} stated directions agree in all"
    )
    return CheckResult(
        "Main effects as the study's Figs 5-6", bool(binding.agrees.all()), summary, table, [fig]
    )
