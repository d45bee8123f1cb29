"""What every figure shares: response names with units, a figure of its own, atomic saving.

No process-global state: figures are `matplotlib.figure.Figure` objects with their own Agg canvas
(no pyplot, no backend switch), so importing or plotting changes nothing for the caller's own
matplotlib use; saving is a separate call.
"""

from __future__ import annotations

import math
from pathlib import Path

import pandas as pd
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.ticker import Formatter

from .. import units
from ..errors import DesignerError
from ..files import atomic_path

#: the image formats figures may be saved in
FORMATS = (".png", ".svg", ".pdf")


def response_label(column: str) -> str:
    """Axis label of a coefficient column with its rig unit: 'k_x' -> 'k_x (N/mm)'."""
    quantity, axis = column.split("_", 1)
    return f"{column} ({units.rig_unit(quantity, axis)})"


def responses_for(table: pd.DataFrame, quantities: list[str] | None, axis: str | None) -> list[str]:
    """The coefficient columns to plot: the given quantities on the given axis, or all of the table."""
    present = [c for c in table.columns if c.split("_", 1)[0] in units.QUANTITIES and "_" in c]
    present = [c for c in present if c.split("_", 1)[1] in units.AXES]
    if axis is not None:
        units.check_axis(axis)
        present = [c for c in present if c.split("_", 1)[1] == axis]
    if quantities:
        present = [c for c in present if c.split("_", 1)[0] in quantities]
    if not present:
        wanted = ", ".join(f"{q}_{axis or '<axis>'}" for q in (quantities or ["c", "k"]))
        raise DesignerError(f"the table has no column {wanted}", "choose a response and axis the table has")
    return present


def check_image_path(path: str | Path) -> Path:
    """The output path, checked to name an image format matplotlib and pyvista both write."""
    p = Path(path)
    if p.suffix.lower() not in FORMATS:
        raise DesignerError(
            f"cannot write a figure to '{p.name}'", f"end the file name in {', '.join(FORMATS)}"
        )
    return p


def decimals_for(ticks: tuple[float, ...]) -> int:
    """The fewest decimals that print every tick exactly: (0.5, 1) -> 1, (0.25, 0.5) -> 2, (0.0005,) -> 4."""
    step = min((abs(b - a) for a, b in zip(ticks, ticks[1:], strict=False)), default=0.0) or max(
        (abs(t) for t in ticks), default=1.0
    )
    d = max(0, -math.floor(math.log10(step) + 1e-9)) if step else 0
    while d < 12 and any(abs(round(t, d) - t) > 1e-6 * step for t in ticks):
        d += 1
    return d


class _StepFormatter(Formatter):
    """Tick labels with the decimals the ticks need: c in N.s/mm reads 0.0015 (not 0.0), k 0.25 (not 0.2)."""

    ticks: tuple[float, ...] = ()

    def set_locs(self, locs) -> None:
        self.ticks = tuple(float(v) for v in locs)

    def __call__(self, x: float, pos: int | None = None) -> str:
        ticks = self.ticks or (float(x),)
        step = abs(ticks[1] - ticks[0]) if len(ticks) > 1 else abs(x)
        return "0" if step and abs(x) < 1e-9 * step else f"{x:.{decimals_for(ticks)}f}"


def value_formatter() -> Formatter:
    """A tick formatter for response axes whose values may be small (see `decimals_for`)."""
    return _StepFormatter()


def new_figure(*, figsize: tuple[float, float], fig: Figure | None = None) -> Figure:
    """The caller's empty figure `fig`, or a new one of `figsize` inches with its own Agg canvas, in
    constrained layout (legends and labels stay inside).

    Raises:
        DesignerError: `fig` already holds axes.
    """
    if fig is not None:
        if fig.axes:
            raise DesignerError("fig= already holds axes", "pass an empty Figure, or none for a new one")
        fig.set_layout_engine("constrained")
        return fig
    fig = Figure(figsize=figsize, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def save_figure(fig: Figure, path: str | Path, *, dpi: int = 120) -> Path:
    """Write a figure atomically as PNG, SVG or PDF (by suffix); returns the path.

    Raises:
        DesignerError: the suffix is not an image format, or the folder is missing.
    """
    p = check_image_path(path)
    with atomic_path(p) as tmp:
        fig.savefig(tmp, dpi=dpi, format=p.suffix[1:].lower())
    return p
