"""A sensor saturated at a rail: many samples at exactly a channel's largest or smallest value.

A load cell or encoder past its range reads its rail, the same number for every sample beyond it:
the peaks of the signal are cut flat. A fit through clipped peaks takes them for a softening spring
(a load clipped at 80 % of its peak once read as "softening spring, secant -25 %", k -9 %). A noisy
analogue reading repeats a value almost never, and an ADC's counts repeat every value about as often
as its neighbours; a rail is an extreme value that holds many samples and many times as many as the
next value inside it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: an extreme value is a rail when at least this share of the finite samples sit exactly on it ...
RAIL_SHARE = 0.002
#: ... and at least this many times as many as on the next value inside it (an ADC's neighbouring
#: count); and at least this many samples in all
RAIL_CONTRAST = 10.0
RAIL_SAMPLES = 5


@dataclass(frozen=True)
class Rail:
    """One rail of a channel: the value it reads and the share of the finite samples on it."""

    value: float
    share: float


def rails(values: np.ndarray) -> list[Rail]:
    """The rails of a channel, largest value first (zero is never one: a zero run is a dropout)."""
    finite = values[np.isfinite(values)]
    out = []
    if finite.size < RAIL_SAMPLES or finite.max() == finite.min():  # a constant is no rail
        return out
    for extreme, inside in ((finite.max(), np.less), (finite.min(), np.greater)):
        on = int(np.count_nonzero(finite == extreme))
        if extreme == 0 or on < max(RAIL_SAMPLES, RAIL_SHARE * finite.size):
            continue
        rest = finite[inside(finite, extreme)]
        if rest.size:
            neighbour = rest.max() if inside is np.less else rest.min()
            if on < RAIL_CONTRAST * np.count_nonzero(rest == neighbour):
                continue
        out.append(Rail(float(extreme), on / finite.size))
    return out


def on_rails(values: np.ndarray, found: list[Rail]) -> np.ndarray:
    """The samples of a channel that sit on one of its rails."""
    out = np.zeros(values.shape, dtype=bool)
    for rail in found:
        out |= values == rail.value
    return out


def describe(column: str, unit: str, found: list[Rail]) -> str:
    """The rails of a column in words: their values and the share of samples on them."""
    share = sum(r.share for r in found)
    where = " and ".join(f"{r.value:.4g} {unit}" for r in found)
    return (
        f"the {column} sensor saturates: {100 * share:.2g} % of its samples sit exactly at "
        f"{'its rails' if len(found) > 1 else 'a rail'} ({where}), the clipped peaks of the signal"
    )
