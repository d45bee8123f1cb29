"""Correlation heat map between the factors and the responses (study Fig 13)."""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from ..study.stats import correlation
from .common import new_figure


def plot_heatmap(table: pd.DataFrame, *, responses: list[str], fig: Figure | None = None) -> Figure:
    """Annotated heat map of the Pearson correlations of factors and responses, -1 (blue) to 1 (red)."""
    corr = correlation(table, responses)
    n = len(corr)
    fig = new_figure(figsize=(0.75 * n + 2.5, 0.75 * n + 1.5), fig=fig)
    ax = fig.subplots()
    im = ax.imshow(corr.to_numpy(), cmap="coolwarm", vmin=-1, vmax=1)
    ax.set_xticks(range(n), corr.columns, rotation=45, ha="right")
    ax.set_yticks(range(n), corr.index)
    for (i, j), v in np.ndenumerate(corr.to_numpy()):
        if np.isfinite(v):
            ax.text(
                j, i, f"{v:.2f}", ha="center", va="center", fontsize=8, color="white" if abs(v) > 0.6 else "k"
            )
    fig.colorbar(im, ax=ax, label="Pearson correlation")
    ax.set_title(f"Factor and response correlations ({len(table)} runs)")
    return fig
