"""Co-simulation time series: one panel per signal against time, an optional reference overlaid."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from ..errors import DesignerError
from .common import save_figure

#: most panels drawn in one figure
MAX_PANELS = 8


def plot_timeseries(
    frame: pd.DataFrame,
    path: str | Path,
    columns: list[str] | None = None,
    time: str = "t",
    reference: pd.DataFrame | None = None,
) -> Path:
    """Each column of `frame` against `time` (s); the same column of `reference` dashed, where it has one."""
    import matplotlib.pyplot as plt

    if time not in frame.columns:
        raise DesignerError(
            f"the time series has no '{time}' column", f"it has {', '.join(map(str, frame.columns))}"
        )
    columns = columns or [c for c in frame.columns if c != time]
    missing = [c for c in columns if c not in frame.columns]
    if missing or not columns:
        raise DesignerError(
            f"no column {missing[0] if missing else 'to plot'}", f"choose from {', '.join(frame.columns)}"
        )
    if len(columns) > MAX_PANELS:
        raise DesignerError(
            f"{len(columns)} signals is too many for one figure", f"pick at most {MAX_PANELS} with --columns"
        )
    fig, axes = plt.subplots(
        len(columns), 1, sharex=True, figsize=(9, 1.9 * len(columns) + 0.8), squeeze=False
    )
    for ax, col in zip(axes[:, 0], columns, strict=True):
        ax.plot(frame[time], frame[col], lw=0.9, label="co-simulation")
        if reference is not None and col in reference.columns:
            ax.plot(reference[time], reference[col], "k--", lw=0.8, label="reference")
            ax.legend(fontsize=7, loc="upper right")
        ax.set_ylabel(col, fontsize=8)
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel(f"{time} (s)")
    fig.tight_layout()
    return save_figure(fig, path)
