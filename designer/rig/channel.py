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


#: the load's noise is taken as low-passed when its power near Nyquist is under this fraction of its
#: power just above the band (white noise: 1 within a few per cent on any log the fit accepts)
ROLL_OFF = 0.6
#: ... and its power near Nyquist under this fraction of its power in the middle of that range
UPPER_ROLL_OFF = 0.8
#: ... and its power in the first three frequency bins at most this multiple of that in the next three
#: (noise: within 1.6 on 20 s logs; leakage of the motion: about 10)
FLAT_START = 2.5
#: samples per segment of the averaged periodogram (Welch) of the load
WELCH_SEGMENT = 2048
#: log-spaced frequency bins of the noise spectrum the filter is fitted to
NOISE_BINS = 24
#: lowest frequency of the noise spectrum, as a multiple of the band's top (above friction's harmonics)
NOISE_FROM = 10.0


@dataclass(frozen=True)
class LowpassEstimate:
    """What the load's noise spectrum says of an unknown low-pass on the load channel.

    `roll_off`: the noise power near Nyquist over that just above the band; `filter`: the
    Butterworth (order 1 to 4) that fits the spectrum best, aliasing included; `delay_s`: its lag
    at the band's middle (the delay that, unaccounted for, shifts c by about -k x delay_s).
    """

    roll_off: float
    filter: LoadFilter
    delay_s: float

    def to_dict(self) -> dict:
        return {"roll_off": self.roll_off, "filter": str(self.filter), "delay_s": self.delay_s}


def _aliased_gain(lowpass: LoadFilter, f: np.ndarray, rate: float) -> np.ndarray:
    """|H|^2 folded into 0..Nyquist from the first two images either side (sampling at `rate`)."""
    w = 2 * np.pi * np.concatenate([np.abs(f + j * rate) for j in range(-2, 3)])
    return (np.abs(lowpass.response(w)) ** 2).reshape(5, f.size).sum(axis=0)


def _fit_shape(f: np.ndarray, p: np.ndarray, rate: float) -> LoadFilter:
    """The Butterworth whose folded |H|^2 (times a level, plus a white floor after it) fits `p` best
    in log power, over orders 1-4 and cutoffs on a log grid up to Nyquist."""
    best, best_score = None, np.inf
    for order in (1, 2, 3, 4):
        for cutoff in np.geomspace(f[0] / 4, rate / 2, 96):
            candidate = LoadFilter(order, float(cutoff))
            h = _aliased_gain(candidate, f, rate)
            a = np.column_stack([h / p, 1.0 / p])  # level x |H|^2 + floor, relative to p
            coef = np.clip(np.linalg.lstsq(a, np.ones_like(p), rcond=None)[0], 0.0, None)
            model = a @ coef * p
            if not (model > 0).all():
                continue
            score = float(np.sum(np.log(model / p) ** 2))
            if score < best_score:
                best, best_score = candidate, score
    return best


def _welch(values: np.ndarray, rate: float) -> tuple[np.ndarray, np.ndarray]:
    """Median periodogram of non-overlapping Hann-windowed segments: frequencies and power.

    (Welch's averaging with the median over segments, a constant ln 2 times the mean for noise:
    the harmonics a chirp sweeps through a line, friction's among them, sit in few segments.)"""
    seg = int(min(WELCH_SEGMENT, 2 ** np.floor(np.log2(max(values.size // 8, 16)))))
    count = values.size // seg
    chunks = values[: count * seg].reshape(count, seg)
    chunks = (chunks - chunks.mean(axis=1, keepdims=True)) * np.hanning(seg)
    power = np.median(np.abs(np.fft.rfft(chunks, axis=1)) ** 2, axis=0)
    return np.arange(power.size) * rate / seg, power


def detect_lowpass(load: np.ndarray, bad: np.ndarray, rate: float, band: tuple[float, float]):
    """An unknown low-pass on the load channel, read from the shape of the load's noise spectrum.

    A sensor's amplifier filters its noise with its signal: white load noise that falls towards
    Nyquist has been low-passed, and the filter's lag biases c. load: the raw samples (`bad`
    ones are ignored); band: the excitation's (low, high) Hz. Returns a LowpassEstimate, or None
    when the noise is white to Nyquist (or there is too little spectrum above the band to tell).
    A filter that acts on the signal but not on the noise (noise added after it) cannot be seen.
    """
    values = np.where(bad, np.nan, load)
    values = values - np.nanmean(values)
    values[~np.isfinite(values)] = 0.0
    freqs, power = _welch(values, rate)
    lo, hi = NOISE_FROM * band[1], 0.95 * rate / 2
    if hi < 4 * lo:
        return None
    edges = np.geomspace(lo, hi, NOISE_BINS + 1)
    which = np.searchsorted(edges, freqs) - 1
    f = np.array([np.sqrt(edges[b] * edges[b + 1]) for b in range(NOISE_BINS) if np.any(which == b)])
    p = np.array([np.mean(power[which == b]) for b in range(NOISE_BINS) if np.any(which == b)])
    if f.size < 8 or not (p > 0).all():
        return None
    roll_off = float(np.median(p[-3:]) / np.median(p[:3]))
    middle = f.size // 2
    still_falling = float(np.median(p[-3:]) / np.median(p[middle - 1 : middle + 2]))
    # a filter's roll-off goes on to Nyquist; harmonics of the motion (friction's square wave
    # falls as 1 / f^2) over a white floor fall in the lower half and flatten out in the upper
    # ... and begins flat: white noise below the cutoff. Without noise (a simulated log) what lies
    # above the band is the window's leakage of the motion, which falls from the band on
    flat_start = float(np.median(p[:3]) / np.median(p[3:6]))
    if roll_off >= ROLL_OFF or still_falling >= UPPER_ROLL_OFF or flat_start > FLAT_START:
        return None
    shape = _fit_shape(f, p, rate)
    if shape is None:
        return None
    mid = 2 * np.pi * np.mean(band)
    dw = 1e-3 * mid
    phase = np.angle(shape.response(np.array([mid + dw]))) - np.angle(shape.response(np.array([mid - dw])))
    # the cutoff to 3 digits: what the spectrum can tell, and what a user would type
    shown = LoadFilter(shape.order, float(f"{shape.cutoff_hz:.3g}"))
    return LowpassEstimate(roll_off=roll_off, filter=shown, delay_s=float(-phase[0] / (2 * dw)))
