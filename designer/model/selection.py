"""The selection of a response's form by leave-one-out, with the honest (nested) accuracy beside it.

Every usable form is fitted and cross-validated; the one-standard-error rule picks the simplest form
the data cannot tell from the best. `designer.model.validation` repeats the procedure without each
run for the accuracy a user can expect.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ..study import space
from .folds import Folds, metrics
from .forms import FORMS, as_printed, design_matrix
from .prediction import Prediction, ResponseSurface
from .validation import lack_of_fit, nested_loo, select_on


def usable_forms(X: Mapping[str, np.ndarray], forms: tuple[str, ...] = FORMS) -> tuple[str, ...]:
    """The forms with fewer terms than the runs have distinct designs (the rest cannot be tested)."""
    rows = np.column_stack([np.asarray(X[n], dtype=float) for n in space.FACTOR_NAMES])
    distinct = len(np.unique(rows, axis=0))
    return tuple(f for f in forms if design_matrix(f, {k: v[:1] for k, v in X.items()}).shape[1] < distinct)


def leave_one_out(form: str, X: Mapping[str, np.ndarray], y: np.ndarray, response: str) -> Prediction:
    """Predict each run from a fit to all the others (penalty re-chosen inside every fold)."""
    y = np.asarray(y, dtype=float)
    return Folds(X, y, (form,)).loo_interval(form, np.arange(len(y)))


def select(
    X: Mapping[str, np.ndarray],
    y: np.ndarray,
    response: str,
    forms: tuple[str, ...] = FORMS,
    *,
    nested: bool = True,
) -> ResponseSurface:
    """Fit every usable form and keep the one the selection procedure picks (see `validation.select_on`).

    `loo` holds the chosen form's leave-one-out figures (optimistic: the form was chosen by
    looking at them); with `nested`, `loo_nested` holds those of the whole procedure repeated
    without each run (form and penalty chosen inside every outer fold; the run predicted as
    printed, as `predict` does), and `influence` the runs
    whose removal changes the chosen form or moves the chosen form's Q2 by more than 0.05.
    """
    y = np.asarray(y, dtype=float)
    forms = usable_forms(X, forms)
    folds = Folds(X, y, forms, printed=as_printed(dict(X)))
    rows = np.arange(len(y))
    sel = select_on(folds, rows, forms)
    model = ResponseSurface(response, sel.form).set_fit(sel.fit, y)
    loo = {f: folds.loo_interval(f, rows) for f in forms}
    model.loo = metrics(y, loo[sel.form])
    model.loo_predictions = loo[sel.form]
    model.candidates = {f: metrics(y, loo[f]) | {"n_params": sel.n_params[f]} for f in forms}
    if nested:
        model.nested_predictions, model.influence = nested_loo(folds, sel, forms)
        model.loo_nested = metrics(y, model.nested_predictions)
    model.lack_of_fit = lack_of_fit(X, y, folds.Z[sel.form], sel.fit, sel.form == "powerlaw")
    return model
