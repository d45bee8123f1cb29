"""Predicted against observed under leave-one-out, with each prediction's 95 % interval.

Nested leave-one-out where the surrogate has it (the form and penalty chosen again without each run:
the honest figure), else the selected form's own leave-one-out, labelled as such. Of a calibrated
surrogate (`designer.calibrate`), a first row shows the user's own prints, each predicted by the
calibrated model from every other run (`CalibratedSurface.own_loo`), above the study's runs.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from .common import new_figure, response_label, value_formatter

#: the user's prints are drawn as the profiler page draws them: orange diamonds
OWN_COLOR = "tab:orange"


def loo_table(surrogate, response: str) -> pd.DataFrame:
    """Per training run: observed, LOO prediction and its 95 % PI, and whether the PI covers the run."""
    model = surrogate.model(response)
    pred = model.nested_predictions or model.loo_predictions
    table = surrogate.table
    return _table(
        table["run"].to_numpy(int) if "run" in table else np.arange(1, len(table) + 1),
        table[response].to_numpy(float),
        pred,
    )


def own_loo_table(surrogate, response: str) -> pd.DataFrame | None:
    """Of a surrogate calibrated with measured values of `response`: per print of the user's (`run`:
    its place among those measured prints, from 1, in the runs table's order), observed, the
    prediction from every other run with it left out and its 95 % PI, and whether the PI covers it.
    None when the surrogate is not calibrated on `response`."""
    model = surrogate.model(response)
    if not hasattr(model, "own_loo") or not model.own.sum():
        return None
    observed = model.observed[model.own > 0]
    return _table(np.arange(1, len(observed) + 1), observed, model.own_loo())


def _table(run: np.ndarray, observed: np.ndarray, pred) -> pd.DataFrame:
    return pd.DataFrame(
        {
            "run": run,
            "observed": np.asarray(observed, float),
            "predicted": np.asarray(pred.value, float),
            "lo": np.asarray(pred.low, float),
            "hi": np.asarray(pred.high, float),
        }
    ).assign(covered=lambda d: (d.observed >= d.lo) & (d.observed <= d.hi))


def your_prints(n: int) -> str:
    """'your print' or 'your 3 prints'."""
    return "your print" if n == 1 else f"your {n} prints"


def own_accuracy(d: pd.DataFrame) -> dict[str, float]:
    """The figures of a leave-one-out table: runs, median absolute error (%), 95 % PI coverage, RMSE."""
    err = d.predicted - d.observed
    return {
        "n": len(d),
        "mape": 100 * float(np.median(np.abs(err) / d.observed)),
        "coverage95": float(d.covered.mean()),
        "rmse": float(np.sqrt(np.mean(err**2))),
    }


def plot_loo(surrogate, *, responses: list[str] | None = None, fig: Figure | None = None) -> Figure:
    """One panel per response (default: all): LOO predictions with PI bars against the measurements.

    k and c are not negative: an interval reaching below 0 (c's, whose form is fitted without a log)
    is cut at 0 and marked, both axes start at 0, and each run the interval misses is labelled with
    its run number. Of a calibrated surrogate, a first row shows the user's prints (orange diamonds,
    each predicted from the others by the calibrated model), the study's runs below it."""
    responses = surrogate.responses if responses is None else responses
    own = {r: own_loo_table(surrogate, r) for r in responses}
    rows = 2 if any(d is not None for d in own.values()) else 1
    fig = new_figure(
        figsize=((5.2 if rows == 1 else 6.0) * len(responses), 4.8 * rows + 0.4 * (rows - 1)), fig=fig
    )
    axes = fig.subplots(rows, len(responses), squeeze=False)
    for col, resp in enumerate(responses):
        model = surrogate.model(resp)
        if rows == 2:
            d = own[resp]
            if d is None:
                axes[0][col].set_axis_off()
                axes[0][col].text(0.5, 0.5, f"no print of yours measured {resp}", ha="center", va="center")
            else:
                _panel(
                    axes[0][col],
                    d,
                    resp,
                    ylabel=f"predicted from your other runs {response_label(resp)}",
                    title=_own_title(resp, d),
                    colors=(OWN_COLOR, "tab:red"),
                    marker="D",
                    name="your print",
                )
        d = loo_table(surrogate, resp)
        nested = model.nested_predictions is not None
        loo = model.accuracy
        whose = "the study's runs (its printer), the study surrogate's leave-one-out\n" if rows == 2 else ""
        _panel(
            axes[rows - 1][col],
            d,
            resp,
            ylabel=f"{'nested ' if nested else ''}leave-one-out prediction {response_label(resp)}",
            title=f"{whose}{resp}: {model.form}, {'nested ' if nested else 'selected form, '}"
            f"Q2 {loo['q2']:.2f}, RMSE {loo['rmse']:.3g} {model.unit}\n"
            f"95 % PI coverage {loo['coverage95']:.0%} of {len(d)} runs",
            colors=("tab:blue", "tab:red"),
            marker="o",
            name="run",
        )
    return fig


def _own_title(resp: str, d: pd.DataFrame) -> str:
    """The title of a panel of the user's prints: whose runs, how predicted, and the figures."""
    acc = own_accuracy(d)
    how = (
        "each predicted by the calibrated model\nfrom the others"
        if len(d) > 1
        else "predicted by the calibrated model\nfrom the study's runs alone"
    )
    return (
        f"{resp}: {your_prints(len(d))}, {how}: median error {acc['mape']:.0f} %, "
        f"95 % PI covers {int(d.covered.sum())} of {len(d)}"
    )


def _panel(
    ax: Axes, d: pd.DataFrame, resp: str, *, ylabel: str, title: str, colors: tuple, marker: str, name: str
) -> None:
    """Observed against predicted with PI bars: covered runs in colors[0], missed ones in colors[1]
    and labelled `name N`; intervals cut at 0 marked."""
    mine = name != "run"
    covers = "your print, PI covers it" if mine else "PI covers the run"
    misses = "your print, PI misses it" if mine else "PI misses it"
    for covered, color, label in ((True, colors[0], covers), (False, colors[1], misses)):
        s = d[d.covered == covered]
        if mine and not len(s):
            continue
        ax.errorbar(
            s.observed,
            s.predicted,
            yerr=[s.predicted - s.lo.clip(lower=0.0), s.hi - s.predicted],
            fmt=marker,
            ms=4 if marker == "o" else 6,
            color=color,
            ecolor=color,
            elinewidth=0.8,
            alpha=0.8,
            label=f"{label} ({len(s)})",
        )
    cut = d[d.lo < 0]
    if len(cut):
        ax.plot(
            cut.observed, np.zeros(len(cut)), "v", ms=5, color="0.3", label=f"interval cut at 0 ({len(cut)})"
        )
    lim = [0.0, 1.04 * max(d.observed.max(), d.hi.max())]
    placed: list[tuple[float, float]] = []
    for r in (d if mine else d[~d.covered]).itertuples():  # the user's few prints: each named
        # a label whose point lies close to one already labelled steps down a line per such neighbour
        at = (r.observed / lim[1], r.predicted / lim[1])
        below = sum(abs(at[0] - u) < 0.12 and abs(at[1] - v) < 0.04 for u, v in placed)
        placed.append(at)
        ax.annotate(
            f"{name} {r.run}",
            (r.observed, r.predicted),
            xytext=(5, 3 - 10 * below),
            textcoords="offset points",
            fontsize=7.5,
            color=colors[0] if r.covered else colors[1],
            bbox={"fc": "white", "ec": "none", "alpha": 0.8, "pad": 0.6},
            zorder=1.5,  # under the markers: a label never hides another run
        )
    ax.plot(lim, lim, "k--", lw=0.8, label="predicted = observed")
    ax.set_xlim(lim)
    ax.set_ylim(lim)
    ax.set_xlabel(f"observed {response_label(resp)}")
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)
    ax.xaxis.set_major_formatter(value_formatter())
    ax.yaxis.set_major_formatter(value_formatter())
    ax.tick_params(labelsize=9)
    ax.grid(alpha=0.3)
    ax.legend(
        fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncols=2 if mine else 3, frameon=False
    )
