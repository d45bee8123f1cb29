"""The load sensor's own dynamics: a known delay and low-pass filter, corrected exactly.

A force/torque sensor (or its amplifier) low-passes its reading; at the rig's frequencies a filter
is a phase lag growing with frequency, which the regression cannot tell from damping: c shifts by
about -k x the filter's group delay (a 2nd-order Butterworth at 200 Hz delays by 1.1 ms, -45 % of the
study's c). Given the filter, the load's spectrum is divided by its frequency response, exactly, in
the band the fit uses (where the response is close to 1 in size, so nothing is amplified).

Filters are written ``butter<order>:<cutoff>Hz``, e.g. ``butter2:200Hz``: an analogue Butterworth
low-pass (the usual anti-aliasing filter of a sensor's amplifier).
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..errors import DesignerError

_FORM = re.compile(r"^\s*butter(?P<order>\d+)\s*:\s*(?P<hz>[0-9.eE+-]+)\s*hz\s*$", re.IGNORECASE)
EXAMPLE = "butter2:200Hz"


@dataclass(frozen=True)
class LoadFilter:
    """An analogue Butterworth low-pass of `order` with its -3 dB point at `cutoff_hz`."""

    order: int
    cutoff_hz: float

    def response(self, w: np.ndarray) -> np.ndarray:
        """H(i w) at angular frequencies `w` (rad/s): unit gain at 0, poles on a circle of radius wc."""
        wc = 2 * np.pi * self.cutoff_hz
        k = np.arange(1, self.order + 1)
        poles = wc * np.exp(1j * np.pi * (2 * k + self.order - 1) / (2 * self.order))
        s = 1j * np.asarray(w, dtype=float)[..., None]
        return np.prod(-poles / (s - poles), axis=-1)

    def __str__(self) -> str:
        return f"butter{self.order}:{self.cutoff_hz:g}Hz"


def parse(text: str | None, *, where: str = "load_filter") -> LoadFilter | None:
    """`butter2:200Hz` -> LoadFilter(2, 200.0); None stays None.

    Raises:
        DesignerError: not of that form, an order outside 1..8, or a cutoff that is not positive.
    """
    if text is None:
        return None
    match = _FORM.match(str(text))
    try:
        order, hz = int(match["order"]), float(match["hz"])
    except (TypeError, ValueError):
        raise DesignerError(f"{where}={text!r} is not a filter", f"write it like {EXAMPLE!r}") from None
    if not 1 <= order <= 8 or not np.isfinite(hz) or hz <= 0:
        raise DesignerError(
            f"{where}={text!r} needs an order from 1 to 8 and a positive cutoff", f"e.g. {EXAMPLE!r}"
        )
    return LoadFilter(order, hz)


def correction(delay_s: float, load_filter: LoadFilter | None) -> Callable[[np.ndarray], np.ndarray]:
    """The factor on the load's spectrum at angular frequencies w that undoes the channel's delay
    (a lag of `delay_s`) and its filter."""

    def factor(w: np.ndarray) -> np.ndarray:
        out = np.exp(1j * w * delay_s)
        return out if load_filter is None else out / load_filter.response(w)

    return factor
