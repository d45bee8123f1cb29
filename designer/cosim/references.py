"""Motor references: the angle a motor imposes and its rate, as functions of time (rad, rad/s)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..chirp import Chirp
from ..errors import DesignerError
from ..files import check_table_file


@dataclass(frozen=True)
class Step:
    """A step of `amplitude` rad at time `at` s from `initial` rad."""

    amplitude: float
    at: float = 0.0
    initial: float = 0.0

    def __call__(self, t: float) -> tuple[float, float]:
        return (self.initial + self.amplitude if t >= self.at else self.initial), 0.0


@dataclass(frozen=True)
class Sine:
    """offset + amplitude sin(2 pi frequency t + phase)."""

    amplitude: float
    frequency: float
    offset: float = 0.0
    phase: float = 0.0

    def __call__(self, t: float) -> tuple[float, float]:
        w = 2.0 * math.pi * self.frequency
        return (
            self.offset + self.amplitude * math.sin(w * t + self.phase),
            self.amplitude * w * math.cos(w * t + self.phase),
        )


@dataclass(frozen=True)
class Trajectory:
    """A trajectory sampled in a CSV file (columns t and q): linear between samples, held outside."""

    t: np.ndarray
    q: np.ndarray

    @classmethod
    def from_csv(cls, path: str | Path, column: str = "q") -> Trajectory:
        """Read columns `t` (s) and `column` (rad) from a CSV file."""
        import pandas as pd

        path = Path(path)
        if not path.is_file():
            raise DesignerError(f"trajectory file {path} does not exist", "give the path of a CSV file")
        check_table_file(path, parquet=False)  # binary, UTF-16, ';' or tab separated: named
        try:
            df = pd.read_csv(path)
        except (ValueError, UnicodeDecodeError) as exc:  # pandas' ParserError is a ValueError
            raise DesignerError(
                f"trajectory file {path} is not a comma-separated table ({str(exc).splitlines()[0]})",
                "give a CSV file with a header row t,q and one sample per row",
            ) from None
        for col in ("t", column):
            if col not in df.columns:
                raise DesignerError(
                    f"trajectory file {path} has no column '{col}'",
                    f"it has: {', '.join(map(str, df.columns))}",
                )
        t = df["t"].to_numpy(float)
        q = df[column].to_numpy(float)
        if len(t) < 2 or not np.all(np.diff(t) > 0) or not np.all(np.isfinite(q)):
            raise DesignerError(
                f"trajectory file {path} is not a usable trajectory",
                "give at least two rows with strictly increasing t and finite angles",
            )
        return cls(t=t, q=q)

    def __call__(self, t: float) -> tuple[float, float]:
        i = int(np.searchsorted(self.t, t, side="right")) - 1
        if i < 0:
            return float(self.q[0]), 0.0
        if i >= len(self.t) - 1:
            return float(self.q[-1]), 0.0
        rate = (self.q[i + 1] - self.q[i]) / (self.t[i + 1] - self.t[i])
        return float(self.q[i] + rate * (t - self.t[i])), float(rate)


Reference = Step | Sine | Chirp | Trajectory
