"""Main-effect boxplots: each response against each factor's levels, medians marked (study Figs 5-12)."""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from ..study import space
from .common import new_figure, response_label, value_formatter


def main_effects(table: pd.DataFrame, responses: list[str]) -> pd.DataFrame:
    """Per response, factor and level: run count and median (rig units), the numbers the boxes show."""
    rows = []
    for resp in responses:
        for f in space.FACTORS:
            for level, group in table.groupby(f.name)[resp]:
                rows.append(
                    {
                        "response": resp,
                        "factor": f.name,
                        "level": float(level),
                        "n": int(group.size),
                        "median": float(group.median()),
                    }
                )
    return pd.DataFrame(rows)


def plot_effects(table: pd.DataFrame, *, responses: list[str], fig: Figure | None = None) -> Figure:
    """One row of boxplots per response (rig units), one panel per factor; red lines are the medians."""
    ncol = len(space.FACTORS)
    fig = new_figure(figsize=(2.5 * ncol, 2.9 * len(responses) + 0.4), fig=fig)
    axes = fig.subplots(len(responses), ncol, squeeze=False, sharey="row")
    rng = np.random.default_rng(0)  # fixed jitter: the same table gives the same picture
    for i, resp in enumerate(responses):
        for j, f in enumerate(space.FACTORS):
            ax = axes[i, j]
            groups = [(level, g[resp].to_numpy()) for level, g in table.groupby(f.name)]
            ax.boxplot(
                [g for _, g in groups],
                positions=range(len(groups)),
                widths=0.55,
                medianprops={"color": "red", "linewidth": 2},
                flierprops={"marker": ""},
            )
            for k, (_, g) in enumerate(groups):
                ax.plot(k + rng.uniform(-0.12, 0.12, g.size), g, ".", color="0.35", ms=3, alpha=0.7)
            ax.plot(range(len(groups)), [np.median(g) for _, g in groups], "r--", lw=0.8)
            ax.set_xticks(range(len(groups)), [f"{level:g}" for level, _ in groups])
            ax.set_xlabel(f"{f.name} ({f.unit})")
            ax.tick_params(labelsize=9)
            if j == 0:
                ax.set_ylabel(response_label(resp))
                ax.yaxis.set_major_formatter(value_formatter())
            ax.grid(axis="y", alpha=0.3)
    fig.suptitle(f"Main effects on {', '.join(responses)} ({len(table)} runs; red: medians)")
    return fig
