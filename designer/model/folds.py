"""Cross-validation fits of one response: each form fitted to the runs without some rows, cached."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from .forms import design_matrix
from .prediction import Prediction
from .ridge import Fit, fit_arrays


def point_metrics(y: np.ndarray, value: np.ndarray) -> dict[str, float]:
    """RMSE, MAPE (%) and Q2 of predictions `value` of the runs `y`."""
    err = y - value
    return {
        "rmse": float(np.sqrt(np.mean(err**2))),
        "mape": float(100 * np.mean(np.abs(err / y))),
        "q2": float(1 - np.sum(err**2) / np.sum((y - y.mean()) ** 2)),
    }


def metrics(y: np.ndarray, pred: Prediction) -> dict[str, float]:
    """`point_metrics` and the share of runs inside their 95 % PI."""
    inside = (y >= pred.low) & (y <= pred.high)
    return point_metrics(y, pred.value) | {"coverage95": float(np.mean(inside))}


class Folds:
    """Fits of each form to subsets of one response's runs, cached by the rows left out.

    Nested leave-one-out fits every form to the runs without {i, j} for each pair, once from
    outer fold i and once from j; the cache makes that one fit. A fit depends only on the rows it
    sees (in table order), so a cached fit is the same numbers a fresh call gives.
    """

    def __init__(
        self,
        X: Mapping[str, np.ndarray],
        y: np.ndarray,
        forms: tuple[str, ...],
        printed: Mapping[str, np.ndarray] | None = None,
    ) -> None:
        self.y = y
        self.Z = {form: design_matrix(form, X) for form in forms}
        #: each form's design matrix of the runs as printed (`forms.as_printed`), where `predict`
        #: evaluates a design: the held-out run of nested leave-one-out is predicted there
        self.Z_printed = self.Z if printed is None else {form: design_matrix(form, printed) for form in forms}
        self._cache: dict[tuple[str, frozenset[int]], Fit] = {}

    def fit(self, form: str, out: frozenset[int]) -> Fit:
        key = (form, out)
        if key not in self._cache:
            keep = np.ones(len(self.y), dtype=bool)
            keep[list(out)] = False
            self._cache[key] = fit_arrays(form, self.Z[form][keep], self.y[keep])
        return self._cache[key]

    def loo(self, form: str, rows: np.ndarray, out: frozenset[int] = frozenset()) -> np.ndarray:
        """Predicted value of each of `rows` from a fit to the runs without it (and without `out`)."""
        return np.array([self.fit(form, out | {int(i)}).value(self.Z[form][i : i + 1])[0] for i in rows])

    def loo_interval(self, form: str, rows: np.ndarray) -> Prediction:
        """As `loo`, with each prediction's 95 % PI."""
        preds = [self.fit(form, frozenset({int(i)})).predict(self.Z[form][i : i + 1]) for i in rows]
        return Prediction(*(np.array([p[k][0] for p in preds]) for k in range(3)))
