"""Co-simulation time series: one panel per kind of signal against time, an optional reference overlaid.

Each panel has a title and a y label with the unit (SI, as `designer cosim` writes its columns); each
joint keeps one colour through the figure and each signal one line style, so a joint's link angle,
motor angle and deflection can be told apart in one panel; the legend sits outside the data.
"""

from __future__ import annotations

from collections.abc import Mapping

import pandas as pd
from matplotlib.figure import Figure

from .. import units
from ..errors import DesignerError
from .common import new_figure

#: most panels drawn in one figure
MAX_PANELS = 8
#: colour-blind-safe colours (Okabe and Ito), one per joint (or per curve when there are no joints)
COLOURS = ("#0072B2", "#E69F00", "#009E73", "#CC79A7", "#D55E00", "#56B4E9", "#000000", "#999999")
#: line styles, one per signal in a panel: solid, dashed, dotted, dash-dot, long dash-dot-dot
STYLES = ("-", "--", ":", "-.", (0, (9, 2, 1, 2, 1, 2)))
#: the signals `designer cosim` writes, by the variable name after the last dot: what each one is
#: and the quantity that sets its unit (a length, its rate, its second rate, a load)
SIGNALS: dict[str, tuple[str, str]] = {
    "q": ("angle q", "r"),
    "motor": ("motor angle", "r"),
    "s": ("deflection s", "r"),
    "v": ("deflection rate v", "v"),
    "a": ("acceleration a", "a"),
    "f": ("load f", "F"),
    "tau": ("torque", "F"),
}
_SI = {  # unit of each kind of quantity on translational and rotational axes
    ("r", False): "m", ("r", True): "rad", ("v", False): "m/s", ("v", True): "rad/s",
    ("a", False): "m/s²", ("a", True): "rad/s²", ("F", False): "N", ("F", True): "N.m",
}  # fmt: skip


def signal_unit(column: str, columns: list[str] | None = None) -> str:
    """The SI unit of a `system.variable` column of a co-simulation, or "SI" when the name does not say.

    `j1.theta.f` -> "N.m" (the axis decides), `robot.j1.q` -> "rad" (robot joints are hinges),
    `hub.f` -> the unit of the rig's joint axis found among `columns` (`joint.x.s` -> "N").
    """
    parts = str(column).split(".")
    kind = SIGNALS.get(parts[-1], (None, None))[1]
    if kind is None:
        return "SI"
    if len(parts) >= 3 and parts[-2] in units.AXES:
        return _SI[kind, units.is_rotational(parts[-2])]
    if parts[0] == "robot":
        return _SI[kind, True]
    axes = [c.split(".")[-2] for c in columns or [] if c.count(".") >= 2 and c.split(".")[-2] in units.AXES]
    return _SI[kind, units.is_rotational(axes[0])] if axes else "SI"


def _joint(column: str) -> str:
    """The joint (or system) a column belongs to: 'robot.j1.q' and 'j1.theta.f' -> 'j1'."""
    parts = str(column).split(".")
    return parts[1] if parts[0] == "robot" and len(parts) >= 3 else parts[0]


def by_quantity(columns: list[str]) -> dict[str, list[str]]:
    """Group `system.variable` columns by the variable (the name after the last dot) and its unit, one
    panel each: ['robot.j1.q', 'robot.j2.q', 'j1.theta.f'] -> {'q (rad)': [both q], 'f (N.m)': [...]}."""
    groups: dict[str, list[str]] = {}
    for c in columns:
        groups.setdefault(f"{str(c).rsplit('.', 1)[-1]} ({signal_unit(c, columns)})", []).append(c)
    return groups


def _styles(cols: list[str]) -> dict[str, dict]:
    """Colour per joint, line style per signal; without joints, colour and style per curve (and
    wider lines first) so curves that coincide all show."""
    joints = list(dict.fromkeys(_joint(c) for c in cols))
    signals = list(dict.fromkeys(str(c).rsplit(".", 1)[-1] for c in cols))
    if all("." in str(c) for c in cols) and len(joints) * len(signals) >= len(cols):
        return {
            c: {
                "color": COLOURS[joints.index(_joint(c)) % len(COLOURS)],
                "ls": STYLES[signals.index(str(c).rsplit(".", 1)[-1]) % len(STYLES)],
                "lw": 1.1,
            }
            for c in cols
        }
    return {
        c: {"color": COLOURS[i % len(COLOURS)], "ls": STYLES[i % len(STYLES)], "lw": max(2.6 - 0.4 * i, 0.9)}
        for i, c in enumerate(cols)
    }


def _title(label: str, cols: list[str], columns: list[str]) -> str:
    """What a panel shows: the signals' descriptions (a load named torque or force by its unit), else
    the quantity its y label names ("x.s (m)" -> "deflection s", "error (m)" -> "error"); never the
    curves' names, which the legend gives."""
    variables = list(dict.fromkeys(str(c).rsplit(".", 1)[-1] for c in cols))
    if all(v in SIGNALS for v in variables):
        loads = {signal_unit(c, columns) for c in cols if str(c).endswith(".f")}
        word = {frozenset({"N.m"}): "torque f", frozenset({"N"}): "force f"}.get(frozenset(loads), "load f")
        return ", ".join(word if v == "f" else SIGNALS[v][0] for v in variables)
    quantity = label.split(" (")[0].strip()
    return SIGNALS.get(quantity.rsplit(".", 1)[-1], (quantity,))[0]


def _panels(frame: pd.DataFrame, columns: list[str] | None, time: str) -> dict[str, list[str]]:
    names = columns or [c for c in frame.columns if c != time]
    missing = [c for c in names if c not in frame.columns]
    if missing or not names:
        raise DesignerError(
            f"no column {missing[0] if missing else 'to plot'}", f"choose from {', '.join(frame.columns)}"
        )
    return by_quantity(names)


def plot_timeseries(
    frame: pd.DataFrame,
    *,
    columns: list[str] | None = None,
    time: str = "t",
    reference: pd.DataFrame | None = None,
    panels: Mapping[str, list[str]] | None = None,
    titles: Mapping[str, str] | None = None,
    fig: Figure | None = None,
) -> Figure:
    """Columns of `frame` against `time` (s), one panel per kind of signal with its unit (or as
    `panels` maps a y label to its columns); the same column of `reference` dashed black, where it
    has one. Each panel is titled (`titles` by y label, else from the signals or the y label's
    quantity, never from the curves' names); the legend stands to the right of the data.

    Raises:
        DesignerError: no `time` column, a column not in `frame`, or more than `MAX_PANELS` panels.
    """
    if time not in frame.columns:
        raise DesignerError(
            f"the time series has no '{time}' column", f"it has {', '.join(map(str, frame.columns))}"
        )
    panels = _panels(frame, columns, time) if panels is None else dict(panels)
    wanted = [c for cols in panels.values() for c in cols]
    missing = [c for c in wanted if c not in frame.columns]
    if missing or not wanted:
        raise DesignerError(
            f"no column {missing[0] if missing else 'to plot'}", f"choose from {', '.join(frame.columns)}"
        )
    if len(panels) > MAX_PANELS:
        raise DesignerError(
            f"{len(panels)} kinds of signal is too many for one figure",
            f"pick at most {MAX_PANELS} with columns=",
        )
    fig = new_figure(figsize=(10, 2.1 * len(panels) + 0.9), fig=fig)
    axes = fig.subplots(len(panels), 1, sharex=True, squeeze=False)
    for ax, (label, cols) in zip(axes[:, 0], panels.items(), strict=True):
        for col, style in _styles(cols).items():
            ax.plot(frame[time], frame[col], label=str(col), **style)
            if reference is not None and col in reference.columns:
                ax.plot(
                    reference[time],
                    reference[col],
                    color="k",
                    ls=(0, (3, 3)),
                    lw=0.7,
                    label=f"{col}, reference",
                )
        ax.legend(fontsize=7.5, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False, borderaxespad=0)
        title = (titles or {}).get(label) or _title(label, cols, list(frame.columns))
        ax.set_title(title, fontsize=9, loc="left")
        ax.set_ylabel(label, fontsize=8.5)
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel(f"{time} (s)")
    return fig
