"""Honest accuracy of the surrogate: nested leave-one-out, influential runs, lack-of-fit test.

Leave-one-out of the chosen form is optimistic, because the form was chosen by looking at those
same errors. Nested leave-one-out repeats the whole procedure (form and ridge penalty chosen
again) without each run and predicts that run: the accuracy a user can expect of `fit` on data
like this. The held-out run is predicted as `Surrogate.predict` predicts a design, as printed (a
section the walls fill is solid: 100 % whatever the nominal infill), so the figure is the accuracy of
what `predict` does: the same numbers as fitting on the other runs and calling `predict` at the run.
With replicated runs (equal factor settings), the pure error they measure splits the
residual into pure error and lack of fit, the classic response-surface test (Montgomery, Design
and Analysis of Experiments, sec. 6.8 / 11.2).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..study import space
from .folds import Folds, point_metrics
from .prediction import Prediction
from .ridge import Fit

#: a run is influential when leaving it out moves the chosen form's LOO Q2 by more than this
INFLUENCE_Q2 = 0.05


@dataclass(frozen=True)
class Selection:
    """The outcome of the selection procedure on some runs: the form and every form's LOO."""

    form: str
    fit: Fit
    #: every form's LOO predicted values over the runs, shape (n,)
    loo: dict[str, np.ndarray]
    n_params: dict[str, int]


def select_on(
    folds: Folds, rows: np.ndarray, forms: tuple[str, ...], out: frozenset[int] = frozenset()
) -> Selection:
    """Run the selection procedure on `rows` (the runs without `out`): LOO per form, one-SE rule.

    The one-standard-error rule (Breiman et al., Hastie et al.) on paired squared LOO errors: a
    richer form must beat a simpler one by more than the noise of the comparison, so a response
    the factors do not explain falls back to the mean instead of a form that fits noise.
    """
    y = folds.y[rows]
    preds = {form: folds.loo(form, rows, out) for form in forms}
    sq = {form: (y - p) ** 2 for form, p in preds.items()}
    best = min(forms, key=lambda f: sq[f].mean())
    n_params = {form: folds.Z[form].shape[1] for form in forms}

    def within_one_se(form: str) -> bool:
        d = sq[form] - sq[best]
        return form == best or d.mean() <= d.std(ddof=1) / np.sqrt(len(y))

    chosen = min((f for f in forms if within_one_se(f)), key=lambda f: (n_params[f], forms.index(f)))
    return Selection(chosen, folds.fit(chosen, out), preds, n_params)


def nested_loo(
    folds: Folds, full: Selection, forms: tuple[str, ...]
) -> tuple[Prediction, list[dict[str, Any]]]:
    """Predict each run from the whole selection procedure run on the others.

    Args:
        folds: the response's fits, cached by the rows left out (shared with the full selection).
        full: the selection on all runs.
        forms: the forms the procedure chooses from.

    Returns:
        (the nested predictions, shape (n,), and the influential
        runs as [{"row", "form", "q2", "delta_q2", "press_share"}] with `row` 0-based, `q2` the LOO
        Q2 of the form chosen without that run over the remaining runs, and `press_share` the
        run's share of the chosen form's LOO squared error on all runs).
    """
    y = folds.y
    n = len(y)
    full_q2 = point_metrics(y, full.loo[full.form])["q2"]
    sq = (y - full.loo[full.form]) ** 2
    value, low, high = np.empty(n), np.empty(n), np.empty(n)
    influence = []
    for i in range(n):
        rows = np.delete(np.arange(n), i)
        sel = select_on(folds, rows, forms, out=frozenset({i}))
        p = sel.fit.predict(folds.Z_printed[sel.form][i : i + 1])
        value[i], low[i], high[i] = p[0][0], p[1][0], p[2][0]
        q2 = point_metrics(y[rows], sel.loo[sel.form])["q2"]
        if sel.form != full.form or abs(q2 - full_q2) > INFLUENCE_Q2:
            share = float(sq[i] / sq.sum())
            influence.append(
                {"row": i, "form": sel.form, "q2": q2, "delta_q2": q2 - full_q2, "press_share": share}
            )
    return Prediction(value, low, high), influence


def replicate_groups(X: Mapping[str, np.ndarray]) -> np.ndarray:
    """Group label per run: runs with equal settings of all six factors share one, shape (n,)."""
    rows = np.column_stack([np.asarray(X[n], dtype=float) for n in space.FACTOR_NAMES])
    return np.unique(rows, axis=0, return_inverse=True)[1].ravel()


def lack_of_fit(
    X: Mapping[str, np.ndarray], y: np.ndarray, Z: np.ndarray, fit: Fit, log: bool
) -> dict[str, float] | None:
    """Pure-error and lack-of-fit F test of a fit, in its fit space; None without replicates.

    SS_pe sums the squared deviations of replicated runs from their group means (n - m dof for m
    distinct designs); SS_lof = SSE - SS_pe with the fit's residual dof (n - trace of the ridge hat
    matrix) less n - m; F = (SS_lof / df_lof) / (SS_pe / df_pe) against F(df_lof, df_pe). A small
    p-value says the form misses structure the replicates show is there.
    """
    from scipy.stats import f as f_dist

    groups = replicate_groups(X)
    m, n = groups.max() + 1, len(y)
    if m == n:
        return None
    yt = np.log(y) if log else np.asarray(y, dtype=float)
    means = np.bincount(groups, weights=yt) / np.bincount(groups)
    ss_pe = float(np.sum((yt - means[groups]) ** 2))
    sse = float(np.sum((yt - Z @ fit.coef) ** 2))
    df_pe, df_lof = float(n - m), fit.dof - (n - m)
    out = {
        "replicated_designs": int(np.sum(np.bincount(groups) > 1)),
        "df_pure_error": df_pe,
        "ss_pure_error": ss_pe,
        "ss_lack_of_fit": sse - ss_pe,
        "df_lack_of_fit": df_lof,
    }
    if df_lof <= 0 or ss_pe <= 0:
        return out | {"f": None, "p_value": None}
    F = ((sse - ss_pe) / df_lof) / (ss_pe / df_pe)
    return out | {"f": float(F), "p_value": float(f_dist.sf(F, df_lof, df_pe))}
