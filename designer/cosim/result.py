"""The result of one co-simulation, in memory (what `Session.run` and `designer.cosim.run` return)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import DesignerError
from .scenario import Scenario

if TYPE_CHECKING:
    import pandas as pd


@dataclass(frozen=True)
class Result:
    """One co-simulation, in memory.

    `time` has shape (n,) in s; `values` shape (n, len(columns)), columns `system.variable` in SI
    (`robot.j1.q` rad, `j1.theta.f` N.m, ...). `metrics` per joint (see README), `validation` when
    asked, `laws` the SI m, c, k, offset each joint FMU ran with, `notes` what the reader should know.
    """

    scenario: Scenario
    time: np.ndarray
    columns: list[str]
    values: np.ndarray
    metrics: dict[str, Any]
    laws: dict[str, dict[str, float]]
    validation: dict[str, Any] | None = None
    notes: tuple[str, ...] = field(default_factory=tuple)
    #: what ran the loop: "kernel" (compiled) or "python" (the reference master)
    engine: str = "python"

    def column(self, name: str) -> np.ndarray:
        """The signal `name`, shape (n,).

        Raises:
            DesignerError: no such column.
        """
        if name not in self.columns:
            raise DesignerError(f"the result has no column '{name}'", f"it has: {', '.join(self.columns)}")
        return self.values[:, self.columns.index(name)]

    def to_frame(self) -> pd.DataFrame:
        """The time series as a DataFrame: column `t` [s], then the signals in SI."""
        import pandas as pd

        frame = pd.DataFrame(self.values, columns=self.columns)
        frame.insert(0, "t", self.time)
        return frame

    def summary(self) -> dict[str, Any]:
        """Plain data for JSON: the scenario file, kind, step, metrics, validation and notes."""
        sc = self.scenario
        out = {
            "scenario": None if sc.path is None else str(sc.path),
            "kind": sc.kind,
            "step": sc.step,
            "engine": self.engine,
            "metrics": self.metrics,
            "notes": list(self.notes),
        }
        if self.validation is not None:
            out["validation"] = self.validation
        return out
