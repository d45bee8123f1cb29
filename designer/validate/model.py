"""Check of the surrogate: leave-one-out accuracy and whether its 95 % PIs cover as often as they claim."""

from __future__ import annotations

import pandas as pd

from .checks import CheckResult, Context

#: a response's LOO coverage fails when a count this low has below this probability for a true 95 % PI
COVERAGE_P = 0.01


def check_surrogate_loo(ctx: Context) -> CheckResult:
    """Leave-one-out metrics per response, and whether its 95 % PIs cover as often as they claim."""
    from scipy.stats import binom

    from ..plots.common import save_figure
    from ..plots.loo import loo_table, plot_loo

    sur = ctx.surrogate
    rows = []
    for resp in sur.responses:
        model = sur.model(resp)
        acc = model.accuracy  # nested leave-one-out where the surrogate has it
        d = loo_table(sur, resp)
        covered, n = int(d.covered.sum()), len(d)
        p_low = float(binom.cdf(covered, n, 0.95))
        rows.append(
            {
                "response": resp,
                "form": model.form,
                "validation": "nested LOO" if model.nested_predictions is not None else "LOO, selected form",
                "Q2": acc["q2"],
                "RMSE": f"{acc['rmse']:.3g} {model.unit}",
                "MAPE %": acc["mape"],
                "PI coverage": f"{covered}/{n} ({covered / n:.0%})",
                "P(count this low)": p_low,
                "coverage ok": p_low >= COVERAGE_P,
                "explains": "some of the variation" if model.predictable else "nothing beyond the mean",
            }
        )
    table = pd.DataFrame(rows)
    fig = save_figure(plot_loo(sur), ctx.figures / "surrogate_loo.png")
    summary = "; ".join(
        f"{r['response']}: {r['form']}, Q2 {r['Q2']:.2f}, 95 % PI covers {r['PI coverage']}" for r in rows
    )
    return CheckResult(
        "Surrogate leave-one-out and PI coverage", bool(table["coverage ok"].all()), summary, table, [fig]
    )
