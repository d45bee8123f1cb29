"""Predicted against observed under leave-one-out, with each prediction's 95 % interval.

Nested leave-one-out where the surrogate has it (the form and penalty chosen again without each run:
the honest figure), else the selected form's own leave-one-out, labelled as such.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from .common import new_figure, response_label, value_formatter


def loo_table(surrogate, response: str) -> pd.DataFrame:
    """Per training run: observed, LOO prediction and its 95 % PI, and whether the PI covers the run."""
    model = surrogate.model(response)
    pred = model.nested_predictions or model.loo_predictions
    table = surrogate.table
    observed = table[response].to_numpy(float)
    return pd.DataFrame(
        {
            "run": table["run"].to_numpy(int) if "run" in table else np.arange(1, len(table) + 1),
            "observed": observed,
            "predicted": np.asarray(pred.value, float),
            "lo": np.asarray(pred.low, float),
            "hi": np.asarray(pred.high, float),
        }
    ).assign(covered=lambda d: (d.observed >= d.lo) & (d.observed <= d.hi))


def plot_loo(surrogate, *, responses: list[str] | None = None, fig: Figure | None = None) -> Figure:
    """One panel per response (default: all): LOO predictions with PI bars against the measurements.

    k and c are not negative: an interval reaching below 0 (c's, whose form is fitted without a log)
    is cut at 0 and marked, both axes start at 0, and each run the interval misses is labelled with
    its run number."""
    responses = surrogate.responses if responses is None else responses
    fig = new_figure(figsize=(5.2 * len(responses), 4.8), fig=fig)
    axes = fig.subplots(1, len(responses), squeeze=False)
    for ax, resp in zip(axes[0], responses, strict=True):
        model = surrogate.model(resp)
        d = loo_table(surrogate, resp)
        for covered, color, label in (
            (True, "tab:blue", "PI covers the run"),
            (False, "tab:red", "PI misses it"),
        ):
            s = d[d.covered == covered]
            ax.errorbar(
                s.observed,
                s.predicted,
                yerr=[s.predicted - s.lo.clip(lower=0.0), s.hi - s.predicted],
                fmt="o",
                ms=4,
                color=color,
                ecolor=color,
                elinewidth=0.8,
                alpha=0.8,
                label=f"{label} ({len(s)})",
            )
        cut = d[d.lo < 0]
        if len(cut):
            ax.plot(
                cut.observed,
                np.zeros(len(cut)),
                "v",
                ms=5,
                color="0.3",
                label=f"interval cut at 0 ({len(cut)})",
            )
        for r in d[~d.covered].itertuples():
            ax.annotate(
                f"run {r.run}",
                (r.observed, r.predicted),
                xytext=(5, 3),
                textcoords="offset points",
                fontsize=7.5,
                color="tab:red",
                bbox={"fc": "white", "ec": "none", "alpha": 0.8, "pad": 0.6},
            )
        lim = [0.0, 1.04 * max(d.observed.max(), d.hi.max())]
        ax.plot(lim, lim, "k--", lw=0.8, label="predicted = observed")
        ax.set_xlim(lim)
        ax.set_ylim(lim)
        ax.set_xlabel(f"observed {response_label(resp)}")
        nested = model.nested_predictions is not None
        ax.set_ylabel(f"{'nested ' if nested else ''}leave-one-out prediction {response_label(resp)}")
        loo = model.accuracy
        ax.set_title(
            f"{resp}: {model.form}, {'nested ' if nested else 'selected form, '}Q2 {loo['q2']:.2f}, "
            f"RMSE {loo['rmse']:.3g} {model.unit}\n"
            f"95 % PI coverage {loo['coverage95']:.0%} of {len(d)} runs",
            fontsize=10,
        )
        ax.xaxis.set_major_formatter(value_formatter())
        ax.yaxis.set_major_formatter(value_formatter())
        ax.tick_params(labelsize=9)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncols=3, frameon=False)
    return fig
