"""What every figure shares: the headless matplotlib backend, response names with units, atomic saving."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import matplotlib

matplotlib.use("Agg")  # no display anywhere: CI, servers, the report

import pandas as pd  # noqa: E402

from .. import units  # noqa: E402
from ..errors import DesignerError  # noqa: E402
from ..files import atomic_path  # noqa: E402

if TYPE_CHECKING:
    from matplotlib.figure import Figure

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


def save_figure(fig: Figure, path: str | Path, dpi: int = 120) -> Path:
    """Save a matplotlib figure atomically and close it; returns the path."""
    import matplotlib.pyplot as plt

    p = check_image_path(path)
    try:
        with atomic_path(p) as tmp:
            fig.savefig(tmp, dpi=dpi, format=p.suffix[1:].lower(), bbox_inches="tight")
    finally:
        plt.close(fig)
    return p
