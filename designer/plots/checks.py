"""Figures of the validation checks: Table 4 side by side, identified against true, error against step."""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from .common import new_figure


def plot_table4(compare: pd.DataFrame, *, fig: Figure | None = None) -> Figure:
    """F of each source, the paper's Table 4 beside ours (`stats.compare_table4`), log scale."""
    x = np.arange(len(compare))
    fig = new_figure(figsize=(8, 4), fig=fig)
    ax = fig.subplots()
    ax.bar(x - 0.2, compare["F_paper"], 0.4, label="paper's Table 4", color="0.6")
    ax.bar(x + 0.2, compare["F"], 0.4, label="ours (bundled Table 3)", color="tab:blue")
    ax.axhline(1.0, color="k", lw=0.6, ls=":")
    ax.set_yscale("log")
    ax.set_xticks(x, compare["source"])
    ax.set_ylabel("F of k_x (type III)")
    for i, ok in enumerate(compare["agrees"]):
        ax.annotate("" if ok else "differs", (i, max(compare["F"].iloc[i], compare["F_paper"].iloc[i])))
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3, axis="y")
    return fig


def plot_identification(rows: pd.DataFrame, *, tolerance_pct: float, fig: Figure | None = None) -> Figure:
    """Relative error of identified k and c per coefficient set, with the tolerance band (%)."""
    x = np.arange(len(rows))
    fig = new_figure(figsize=(8, 3.8), fig=fig)
    ax = fig.subplots()
    ax.axhspan(-tolerance_pct, tolerance_pct, color="tab:green", alpha=0.12, label=f"+/- {tolerance_pct:g} %")
    ax.plot(x - 0.1, rows["k error %"], "o", label="k")
    ax.plot(x + 0.1, rows["c error %"], "s", label="c")
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xticks(x, rows["set"], fontsize=8)
    ax.set_ylabel("identified / true - 1 (%)")
    ax.set_title("Virtual rig -> identification, closed loop")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    return fig


def plot_convergence(steps: pd.DataFrame, *, unit: str, fig: Figure | None = None) -> Figure:
    """Error (in `unit`) against macro step (s), log-log, every column of `steps` but "step" a line."""
    fig = new_figure(figsize=(6, 4.2), fig=fig)
    ax = fig.subplots()
    h = steps["step"].to_numpy()
    for col in steps.columns.drop("step"):
        ax.loglog(h, np.maximum(steps[col].to_numpy(), 1e-18), "o-", label=col)
    first = steps.columns.drop("step")[0]
    # the slope-1 guide twice above the first series' smallest-step error, drawn over the data: on
    # the data it would hide under a first-order series' markers
    guide = 2 * steps[first].iloc[-1] * h / h[-1]
    ax.loglog(
        h,
        guide,
        color="0.25",
        ls=(0, (6, 3)),
        lw=1.3,
        zorder=5,
        label="first order (slope 1)",
    )
    ax.set_xlabel("macro step (s)")
    ax.set_ylabel(f"max error ({unit})")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3, which="both")
    return fig
