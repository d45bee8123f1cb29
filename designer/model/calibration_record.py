"""What a calibrated surrogate keeps of the user's runs: their columns, and the table built on demand.

`Surrogate.calibration` is a mapping: "columns" (the six factors and the measured responses, arrays
of equal length, NaN where a response was not measured), "printer_sd", and "table", those columns as
a pandas DataFrame. The design loop recalibrates hundreds of times on imagined runs and reads only
the columns; importing pandas and building a DataFrame each time cost most of `designer next`'s
second (issue 38), so the table is built only when something reads it.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np


class CalibrationRecord(dict):
    """{"columns", "printer_sd"}, and "table" (a DataFrame of the columns) made on first read."""

    def __init__(self, columns: Mapping[str, np.ndarray], printer_sd: float) -> None:
        super().__init__(columns=dict(columns), printer_sd=printer_sd)

    def __missing__(self, key: str) -> Any:
        if key != "table":
            raise KeyError(key)
        import pandas as pd

        self["table"] = pd.DataFrame(self["columns"])
        return self["table"]

    @property
    def n_runs(self) -> int:
        """How many runs of the user's the calibration holds."""
        return len(next(iter(self["columns"].values()), []))
