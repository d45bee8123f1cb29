"""Cleaning a coefficient table the way the study did: sensor failures, then DBSCAN outliers.

Runs whose coefficients are missing or zero (a failed sensor) are dropped first; DBSCAN
(scikit-learn) on the standardised coefficients then drops the points that belong to no cluster.
The study's parameters are eps = 0.5 and min_samples = 5.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..data import coefficient_columns, normalise
from ..errors import DesignerError

EPS = 0.5
MIN_SAMPLES = 5


@dataclass(frozen=True)
class Cleaned:
    """The kept table and one row per dropped run: its position in the input and why."""

    table: pd.DataFrame
    dropped: pd.DataFrame

    def summary(self) -> dict:
        return {
            "kept": len(self.table),
            "dropped": self.dropped.to_dict(orient="records"),
        }


def clean(
    raw: pd.DataFrame, eps: float = EPS, min_samples: int = MIN_SAMPLES, source: str = "table"
) -> Cleaned:
    """Drop runs with NaN or zero coefficients, then DBSCAN noise points; say why for each."""
    from sklearn.cluster import DBSCAN
    from sklearn.preprocessing import StandardScaler

    if eps <= 0 or min_samples < 1:
        raise DesignerError(
            f"eps = {eps:g}, min_samples = {min_samples}", "give eps > 0 and min_samples >= 1"
        )
    cols = coefficient_columns(raw)
    if not cols:
        raise DesignerError(
            f"{source}: no coefficient columns",
            "give c_<axis>, k_<axis> (the table designer identify writes)",
        )
    values = raw[cols].apply(pd.to_numeric, errors="coerce")
    reasons = []
    for row, series in values.iterrows():
        bad = [f"{c} is {'NaN' if pd.isna(v) else 'zero'}" for c, v in series.items() if pd.isna(v) or v == 0]
        if bad:
            reasons.append({"row": int(row) + 1, "reason": "sensor failure: " + ", ".join(bad)})
    sensor_bad = values.isna().any(axis=1) | (values == 0).any(axis=1)
    survivors = raw[~sensor_bad.to_numpy()]
    if len(survivors) == 0:
        raise DesignerError(
            f"{source}: every run has missing or zero coefficients", "check the identification"
        )
    table = normalise(survivors, source=source)
    scaled = StandardScaler().fit_transform(table[cols].to_numpy())
    labels = DBSCAN(eps=eps, min_samples=min_samples).fit_predict(scaled)
    rows = np.flatnonzero(~sensor_bad.to_numpy())
    for pos in np.flatnonzero(labels == -1):
        far = ", ".join(
            f"{c} = {table[c].iloc[pos]:.3g} ({scaled[pos, j]:+.1f} SD)" for j, c in enumerate(cols)
        )
        reasons.append(
            {
                "row": int(rows[pos]) + 1,
                "reason": f"DBSCAN noise: not within {eps:g} SD of a run with {min_samples} neighbours "
                f"({far})",
            }
        )
    dropped = pd.DataFrame(reasons, columns=["row", "reason"]).sort_values("row").reset_index(drop=True)
    return Cleaned(table=table[labels != -1].reset_index(drop=True), dropped=dropped)
