"""Co-simulation time series: one panel per signal against time, an optional reference overlaid."""

from __future__ import annotations

from collections.abc import Mapping

import pandas as pd
from matplotlib.figure import Figure

from ..errors import DesignerError
from .common import new_figure

#: most panels drawn in one figure
MAX_PANELS = 8


def plot_timeseries(
    frame: pd.DataFrame,
    *,
    columns: list[str] | None = None,
    time: str = "t",
    reference: pd.DataFrame | None = None,
    panels: Mapping[str, list[str]] | None = None,
    fig: Figure | None = None,
) -> Figure:
    """Columns of `frame` against `time` (s), one panel each (or grouped: `panels` maps a label to its
    columns); the same column of `reference` dashed, where it has one."""
    if time not in frame.columns:
        raise DesignerError(
            f"the time series has no '{time}' column", f"it has {', '.join(map(str, frame.columns))}"
        )
    if panels is None:
        panels = {c: [c] for c in columns or [c for c in frame.columns if c != time]}
    wanted = [c for cols in panels.values() for c in cols]
    missing = [c for c in wanted if c not in frame.columns]
    if missing or not wanted:
        raise DesignerError(
            f"no column {missing[0] if missing else 'to plot'}", f"choose from {', '.join(frame.columns)}"
        )
    if len(panels) > MAX_PANELS:
        raise DesignerError(
            f"{len(panels)} signals is too many for one figure", f"pick at most {MAX_PANELS} with columns="
        )
    fig = new_figure(figsize=(9, 1.9 * len(panels) + 0.8), fig=fig)
    axes = fig.subplots(len(panels), 1, sharex=True, squeeze=False)
    for ax, (label, cols) in zip(axes[:, 0], panels.items(), strict=True):
        for col in cols:
            ax.plot(frame[time], frame[col], lw=0.9, label=col if len(cols) > 1 else "co-simulation")
            if reference is not None and col in reference.columns:
                ax.plot(reference[time], reference[col], "k--", lw=0.8, label=f"{col} reference")
        if len(cols) > 1 or reference is not None:
            ax.legend(fontsize=7, loc="upper right")
        ax.set_ylabel(label, fontsize=8)
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel(f"{time} (s)")
    return fig
