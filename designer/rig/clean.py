"""Cleaning a coefficient table the way the study did: sensor failures, then DBSCAN outliers.

Runs whose coefficients are missing or zero (a failed sensor) are dropped first; DBSCAN
(scikit-learn) on the standardised coefficients then drops the points that belong to no cluster.
The study's parameters are eps = 0.5 and min_samples = 5. Every table the tool writes reads here
(extra columns such as `r2_x`, `nrmse_x`, `log` from `identify` are kept as they are).

Cleaning computes; it never decides to write. `Cleaned.drop_share` and `Cleaned.explanation` let the
caller refuse a result that would throw most of the data away (the CLI refuses above `MAX_DROP`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from .. import units
from ..errors import DesignerError
from ..study import space
from ..study.data import canonical_columns, check_text_cells, coefficient_columns, normalise

EPS = 0.5
MIN_SAMPLES = 5
#: largest share of the runs a clean may drop before the CLI refuses to write the result
MAX_DROP = 0.2


@dataclass(frozen=True)
class Cleaned:
    """The kept table, one row per dropped run (its 1-based row in the input and why), the number of
    input runs, and plain sentences saying what DBSCAN did on these data."""

    table: pd.DataFrame
    dropped: pd.DataFrame
    runs: int
    explanation: list[str] = field(default_factory=list)

    @property
    def drop_share(self) -> float:
        """Dropped runs over input runs (0..1)."""
        return len(self.dropped) / self.runs if self.runs else 0.0

    def summary(self) -> dict:
        return {
            "runs": self.runs,
            "kept": len(self.table),
            "drop_share": self.drop_share,
            "dropped": self.dropped.to_dict(orient="records"),
            "dbscan": self.explanation,
        }


def _sensor_failures(values: pd.DataFrame) -> tuple[np.ndarray, list[dict]]:
    """Rows whose coefficients are NaN or zero, and their reasons."""
    reasons = []
    for row, series in values.iterrows():
        bad = [f"{c} is {'NaN' if pd.isna(v) else 'zero'}" for c, v in series.items() if pd.isna(v) or v == 0]
        if bad:
            reasons.append({"row": int(row) + 1, "reason": "sensor failure: " + ", ".join(bad)})
    return (values.isna().any(axis=1) | (values == 0).any(axis=1)).to_numpy(), reasons


def _explain(
    table: pd.DataFrame, cols: list[str], labels: np.ndarray, cores: int, eps: float, min_samples: int
):
    """What DBSCAN did on these runs, in sentences: the rule, the scale of eps per column, the outcome."""
    n = len(table)
    lines = [
        f"DBSCAN on {', '.join(cols)} of {n} runs, each column scaled to mean 0 and SD 1: a run is a core "
        f"run when {min_samples} runs (itself included) lie within {eps:g} SD of it; runs within {eps:g} SD "
        "of a core run join its cluster; the others are noise and dropped."
    ]
    for c in cols:
        sd, mean = table[c].std(ddof=0), table[c].mean()
        rel = f" ({100 * eps * sd / mean:.2g} % of its mean)" if mean else ""
        unit = units.rig_unit(*c.split("_", 1))
        lines.append(f"{eps:g} SD of {c} is {eps * sd:.3g} {unit}{rel} on these runs.")
    clusters = len(set(labels[labels >= 0]))
    noise = int((labels == -1).sum())
    lines.append(f"Result: {cores} core runs, {clusters} cluster(s), {noise} noise run(s).")
    return lines


def clean(
    raw: pd.DataFrame, *, eps: float = EPS, min_samples: int = MIN_SAMPLES, source: str = "table"
) -> Cleaned:
    """Drop runs with NaN or zero coefficients, then DBSCAN noise points; say why for each.

    Args:
        raw: a coefficient table (the six factors, c_<axis>, k_<axis>, optionally m_<axis> and any
            other columns, which are carried along), one row per run.
        eps: DBSCAN radius in standard deviations of the standardised coefficients.
        min_samples: DBSCAN core size, runs within eps including the run itself.
        source: the table's name for messages.

    Returns:
        Cleaned: the kept runs (normalised, index 0..n-1), the dropped rows with reasons, the input
        run count and the explanation of what DBSCAN did.

    Raises:
        DesignerError: bad eps/min_samples, no coefficient columns, no rows, or a malformed table.
    """
    from sklearn.cluster import DBSCAN
    from sklearn.preprocessing import StandardScaler

    if not (np.isfinite(eps) and eps > 0) or min_samples < 1:
        raise DesignerError(
            f"eps = {eps:g}, min_samples = {min_samples}", "give eps > 0 and min_samples >= 1"
        )
    raw = canonical_columns(raw, source=source)
    cols = coefficient_columns(raw)
    if not cols:
        raise DesignerError(
            f"{source}: no coefficient columns",
            "give c_<axis>, k_<axis> (the table designer identify writes)",
        )
    if len(raw) == 0:
        raise DesignerError(f"{source}: the table has no runs", "give a table with at least one data row")
    raw = raw.reset_index(drop=True)
    check_text_cells(raw, [c for c in (*space.FACTOR_NAMES, *cols) if c in raw.columns], source)
    sensor_bad, reasons = _sensor_failures(raw[cols].apply(pd.to_numeric, errors="coerce"))
    rows = np.flatnonzero(~sensor_bad)
    if len(rows) == 0:
        dropped = pd.DataFrame(reasons, columns=["row", "reason"])
        explanation = ["Every run has missing or zero coefficients: nothing is left for DBSCAN."]
        return Cleaned(raw.iloc[:0], dropped, len(raw), explanation)
    table = normalise(raw.iloc[rows], source=source)
    if len(table) < min_samples:
        explanation = [
            f"DBSCAN skipped: with {len(table)} runs, fewer than min_samples = {min_samples}, no run could "
            "be a core run and DBSCAN would call every run noise; only sensor failures were removed."
        ]
        dropped = pd.DataFrame(reasons, columns=["row", "reason"])
        return Cleaned(table, dropped, len(raw), explanation)
    scaled = StandardScaler().fit_transform(table[cols].to_numpy())
    db = DBSCAN(eps=eps, min_samples=min_samples).fit(scaled)
    labels = db.labels_
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
    explanation = _explain(table, cols, labels, len(db.core_sample_indices_), eps, min_samples)
    return Cleaned(table[labels != -1].reset_index(drop=True), dropped, len(raw), explanation)
