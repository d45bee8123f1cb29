"""The band that carries the motion, and the band-limited filter r, r', r'' and the load share.

Two stages. First, block means: the log is averaged over blocks of `factor` samples down to about
`PRE_RATE` (a boxcar filter plus decimation; its gain and phase are the same on every channel, so
they cancel in the regression, and block means of white noise stay white). Dropout blocks are
filled by a cubic spline through the valid ones (and left out of the fit later, unless the gap is so
short that the fill is exact to a tenth of the noise). Second, one FFT per
channel: the excitation band is read from the position's power spectrum, and the filter is a
zero-phase low-pass, flat to `pass_edge` and raised-cosine to zero at 1.5 x `pass_edge`; r' and r''
are iw and -w^2 times the filtered position spectrum, a known channel delay is the exact phase
exp(i w delay) on the load, and the filtered channels come back on a coarse grid by an inverse FFT
of the kept bins. Content below the band (sensor offset, drift) passes the low-pass and is fitted
as a constant and a linear trend: a high-pass with a sharp enough edge under 0.2 Hz would ring for
tens of seconds at each end and around every dropout.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

#: target rate of the block-mean stage, Hz
PRE_RATE = 100.0
#: the block-mean stage is used only when its rate is at least this multiple of the band's top
PRE_MARGIN = 10.0
#: spectral flatness above which a position is only noise (white noise 0.56, a chirp under 0.02)
STILL_FLATNESS = 0.3
#: fraction of the record tapered (half at each end) in the periodogram that finds the band
TAPER = 0.04
#: stop edge over pass edge of the low-pass
STOP_RATIO = 1.5
#: rate of the filtered grid over the stop edge
GRID_RATIO = 2.5
#: rows within this many 1 / (transition width) of an end or of a filled sample are left out
GUARD_TRANSITIONS = 2.5
#: a filled gap whose cubic fill errs by under this fraction of the amplitude is kept in the fit
FILL_TOLERANCE = 1e-4
#: samples averaged at each end to take out the straight line that joins the ends before the FFT
END_SAMPLES = 5


def fast_len(n: int) -> int:
    """The smallest 5-smooth length (2^a 3^b 5^c) at least n: an FFT size numpy transforms fast."""
    best = 1 << max(n - 1, 0).bit_length()
    p5 = 1
    while p5 < best:
        p35 = p5
        while p35 < best:
            size = p35
            while size < n:
                size *= 2
            best = min(best, size)
            p35 *= 3
        p5 *= 5
    return best


@dataclass(frozen=True)
class Band:
    """The excitation band, Hz: where the position's power above the noise floor lies."""

    low: float
    high: float

    def to_dict(self) -> dict:
        return {"low_hz": self.low, "high_hz": self.high}


@dataclass(frozen=True)
class Spectra:
    """The block-mean series of one axis and the spectra the filtered channels are built from.

    `position` and `load` are rfft bins (length n // 2 + 1) of the series, scaled to unit peak
    (`scale_r`, `scale_f` give the rig units back); `filled` marks series samples that were
    interpolated; `noise_var` is the white position-noise variance per series sample (scaled),
    read from the median out-of-band power.
    """

    rate: float
    n: int
    samples: int
    position: np.ndarray
    load: np.ndarray
    filled: np.ndarray
    scale_r: float
    scale_f: float
    noise_var: float
    band: Band | None
    #: the straight line taken out of the position before the FFT, at its first and last sample
    r_line: tuple[float, float] = (0.0, 0.0)

    @property
    def freqs(self) -> np.ndarray:
        return np.arange(self.position.size) * self.rate / self.n


@dataclass(frozen=True)
class Channels:
    """Filtered columns on the coarse grid: `x` is (rows, 3) r'', r', r; `y` the load; `keep` the usable rows.

    `noise_cov` (3 x 3) is the covariance of the filtered position noise in the three columns per row.
    """

    x: np.ndarray
    y: np.ndarray
    t: np.ndarray
    keep: np.ndarray
    noise_cov: np.ndarray
    rate: float
    pass_edge: float
    #: instantaneous frequency of the filtered motion per row, Hz (from its analytic signal)
    inst_freq: np.ndarray
    #: the line taken out of the position before filtering, per row: r + r_line is the deflection
    r_line: np.ndarray
    #: the load with one more skew (see `filtered`), or None
    y_skew: np.ndarray | None = None


def block_means(values: np.ndarray, bad: np.ndarray, factor: int) -> tuple[np.ndarray, np.ndarray]:
    """Means over consecutive blocks of `factor` samples (a trailing partial block is dropped).

    A block's mean is over its good samples: a scattered glitch costs its own sample, not the
    block (the block's time centre moves by under half a sample). Returns the means and which blocks
    have fewer than half their samples good; those means are meaningless until filled.
    (A matrix-vector product and the sparse bad rows: one pass over the samples each.)
    """
    blocks = values.size // factor
    if factor == 1:
        return values.astype(np.float64, copy=True), bad.copy()
    rows = np.flatnonzero(bad[: blocks * factor])
    if rows.size:
        values = values[: blocks * factor].copy()
        values[rows] = 0.0
    means = values[: blocks * factor].reshape(blocks, factor) @ np.full(factor, 1.0 / factor)
    lost = np.bincount(rows // factor, minlength=blocks)
    if rows.size:
        means *= factor / np.maximum(factor - lost, 1)
    return means, lost > factor // 2


def fill(values: np.ndarray, bad: np.ndarray) -> None:
    """Replace the `bad` entries in place: the cubic through the two good samples either side.

    (Held flat past the ends.) Over a gap of a few samples of a slow signal the cubic's error is
    of the fourth order in the gap's length; the rows near longer gaps are left out of the fit.
    """
    if not bad.any():
        return
    good = np.flatnonzero(~bad)
    rows = np.flatnonzero(bad)
    values[rows] = np.interp(rows, good, values[good])
    j = np.searchsorted(good, rows)
    inner = (j >= 2) & (j <= good.size - 2)
    if not inner.any():
        return
    x = rows[inner].astype(np.float64)
    nodes = good[np.stack([j[inner] + d for d in (-2, -1, 0, 1)])].astype(np.float64)
    ys = values[nodes.astype(np.int64)]
    out = np.zeros_like(x)
    for a in range(4):
        weight = np.ones_like(x)
        for b in range(4):
            if b != a:
                weight *= (x - nodes[b]) / (nodes[a] - nodes[b])
        out += weight * ys[a]
    values[rows[inner]] = out


def _ends_line(values: np.ndarray) -> tuple[float, float]:
    """Subtract, in place, the straight line through the means of the first and last few samples.

    Returns the line's values at the first and the last sample.
    """
    k = min(END_SAMPLES, values.size // 2)
    a, b = float(values[:k].mean()), float(values[-k:].mean())
    values -= a + (b - a) * np.linspace(0.0, 1.0, values.size)
    return a, b


def estimate_band(power: np.ndarray, rate: float, n: int, floor: float) -> Band | None:
    """The band of the position's power above the noise floor; None when there is none.

    The top is the 99.5 % quantile of that power (it sets the filter, so it errs high). The bottom
    is where the power density, smoothed over 0.02 Hz, first reaches a tenth of its median over the
    middle 80 % of the power (the 1 % quantile when that median is zero, as between the lines of a
    multisine): a chirp's power spreads a little below its start, which a quantile would count.
    """
    excess = np.clip(power[1:] - floor, 0.0, None)
    total = float(excess.sum())
    if not np.isfinite(total) or total <= 0:
        return None
    cumulative = np.cumsum(excess) / total
    q_lo, q10, q90, hi = (int(np.searchsorted(cumulative, q)) for q in (0.01, 0.1, 0.9, 0.995))
    level = float(np.median(excess[q10 : q90 + 1]))
    lo = q_lo
    if level > 0:
        width = max(1, int(0.02 * n / rate))
        smooth = np.convolve(excess[: q10 + 1], np.full(width, 1.0 / width), mode="same")
        lo = int(np.argmax(smooth >= 0.1 * level))
    return Band(low=(lo + 1) * rate / n, high=(max(hi, lo) + 1) * rate / n)


def _noise_floor(power: np.ndarray, rate: float, n: int, top: float) -> float:
    """Median periodogram over the bins from 1.2 x `top` to 0.9 x Nyquist, as a mean (white noise)."""
    lo = int(np.ceil(1.2 * top * n / rate))
    hi = int(0.9 * power.size)
    region = power[lo:hi] if hi - lo >= 16 else power[-max(power.size // 4, 1) :]
    return float(np.median(region) / np.log(2.0))


def _flatness(power: np.ndarray) -> float:
    """Spectral flatness, geometric over arithmetic mean of a periodogram: about 0.56 for white
    noise (exponentially distributed bins), near 0 for any excitation, even an aliased one."""
    positive = power[power > 0]
    if positive.size < 2:
        return 0.0
    return float(np.exp(np.mean(np.log(positive))) / np.mean(positive))


def _band_and_noise(r: np.ndarray, rate: float) -> tuple[Band | None, float]:
    """Excitation band and white-noise variance per sample, from a tapered periodogram.

    The taper (cosine over the first and last 2 % of the record) keeps the ends of the record
    from leaking power below the band, while leaving most of a chirp's start and end, where its
    lowest and highest frequencies are, at full weight. The noise floor is the median power well
    above the band, and the noise variance that floor over the window's sum of squares.
    """
    window = np.ones(r.size)
    edge = int(TAPER / 2 * r.size)
    if edge:
        window[:edge] = 0.5 * (1 - np.cos(np.pi * np.arange(edge) / edge))
        window[r.size - edge :] = window[:edge][::-1]
    n = fast_len(r.size)
    spectrum = np.fft.rfft((r - r.mean()) * window, n=n)
    power = spectrum.real**2 + spectrum.imag**2
    if _flatness(power[1:]) > STILL_FLATNESS:  # only noise: a logged axis that does not move
        return None, 0.0
    rough = estimate_band(power, rate, n, 0.0)
    if rough is None:
        return None, 0.0
    floor = _noise_floor(power, rate, n, STOP_RATIO * 3.0 * rough.high)
    return estimate_band(power, rate, n, floor), floor / float(window @ window)


def spectra(r: np.ndarray, f: np.ndarray, bad: np.ndarray, rate: float, factor: int) -> Spectra:
    """Block means, fill, unit scaling, end-line removal and one FFT of position and load."""
    rb, bad_r = block_means(r, bad, factor)
    fb, _ = block_means(f, bad, factor)
    fill(rb, bad_r), fill(fb, bad_r)
    scale_r = float(np.max(np.abs(rb))) or 1.0
    scale_f = float(np.max(np.abs(fb))) or 1.0
    rb /= scale_r
    fb /= scale_f
    srate = rate / factor
    band, noise_var = _band_and_noise(rb, srate)
    r_line = _ends_line(rb)
    _ends_line(fb)
    n = fast_len(rb.size)
    pos, load = np.fft.rfft(rb, n=n), np.fft.rfft(fb, n=n)
    return Spectra(
        rate=srate,
        n=n,
        samples=rb.size,
        position=pos,
        load=load,
        filled=bad_r,
        scale_r=scale_r,
        scale_f=scale_f,
        noise_var=noise_var,
        band=band,
        r_line=r_line,
    )


def lowpass(freqs: np.ndarray, pass_edge: float) -> np.ndarray:
    """Zero-phase gain: 1 up to `pass_edge`, raised cosine to 0 at STOP_RATIO x `pass_edge`."""
    stop = STOP_RATIO * pass_edge
    x = np.clip((freqs - pass_edge) / (stop - pass_edge), 0.0, 1.0)
    return 0.5 * (1.0 + np.cos(np.pi * x))


def _long_gaps(filled: np.ndarray, longest: int) -> np.ndarray:
    """The filled samples in runs of more than `longest` consecutive ones."""
    edges = np.diff(np.concatenate(([0], filled.astype(np.int8), [0])))
    starts, ends = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    out = np.zeros(filled.shape, dtype=bool)
    for a, b in zip(starts[ends - starts > longest], ends[ends - starts > longest], strict=True):
        out[a:b] = True
    return out


def fill_tolerant(spec: Spectra) -> int:
    """The longest run of filled series samples whose cubic fill is exact enough to keep in the fit.

    The cubic through two samples either side of a gap of g errs by at most
    (w h)^4 / 24 x ((g + 1) / 2)^2 ((g + 3) / 2)^2 of the amplitude in the gap's middle, with w
    the band's top in rad/s and h the sample interval: kept while that is under FILL_TOLERANCE
    (a tenth of the usual position noise), such a gap needs no guard.
    """
    wh = 2 * np.pi * spec.band.high / spec.rate
    g = 0
    while wh**4 / 24 * ((g + 2) / 2) ** 2 * ((g + 4) / 2) ** 2 <= FILL_TOLERANCE and g < 64:
        g += 1
    return g


def _guard(filled: np.ndarray, n: int, nd: int, samples: int, reach: int) -> np.ndarray:
    """Grid rows within `reach` rows of a (marked) filled series sample or of either end of the record."""
    edges = np.zeros(nd + 1, dtype=np.int32)
    rows = np.unique(np.round(np.flatnonzero(filled) * nd / n).astype(np.int64))
    np.add.at(edges, np.clip(rows - reach, 0, nd), 1)
    np.add.at(edges, np.clip(rows + reach + 1, 0, nd), -1)
    near = np.cumsum(edges[:-1]) > 0
    last = int(np.floor((samples - 1) * nd / n))
    near[: reach + 1] = True
    near[max(last - reach, 0) :] = True
    return near


def _grid(spec: Spectra, pass_edge: float) -> tuple[int, int]:
    """The rfft bins the low-pass at `pass_edge` keeps, and the (even) length of the filtered grid."""
    stop = STOP_RATIO * pass_edge
    bins = min(int(np.ceil(stop * spec.n / spec.rate)) + 1, spec.position.size)
    nd = min(fast_len(max(int(np.ceil(GRID_RATIO * stop * spec.n / spec.rate)), 2 * bins)), spec.n)
    return bins, nd + nd % 2


def series_motion(spec: Spectra, pass_edge: float) -> tuple[np.ndarray, np.ndarray]:
    """r and r' through the low-pass at `pass_edge`, at the series samples (scaled units)."""
    gain = spec.position * lowpass(spec.freqs, pass_edge)
    r = np.fft.irfft(gain, n=spec.n)[: spec.samples]
    v = np.fft.irfft(2j * np.pi * spec.freqs * gain, n=spec.n)[: spec.samples]
    return r, v


def _interval_sign(v: np.ndarray) -> np.ndarray:
    """The mean of sign(v) over each sample's interval with v linear in it, so a zero crossing
    between samples counts by where it falls."""
    step = np.abs(np.gradient(v))
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(step > 0, np.clip(2 * v / step, -1.0, 1.0), np.sign(v))


def nonlinear_columns(spec: Spectra, pass_edge: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Coulomb friction's sign(r'), the cubic spring's (r - mean r)^3 and a dead band's
    sign(r - mean r), formed at the series rate from the band-limited motion and then filtered
    exactly as the load is (so their harmonics above the pass edge go where the load's go), on the
    grid of `filtered(spec, pass_edge)`. Scaled units (r in units of `scale_r`).
    """
    bins, nd = _grid(spec, pass_edge)
    r, v = series_motion(spec, pass_edge)
    a, b = spec.r_line
    deflection = r + a + (b - a) * np.linspace(0.0, 1.0, spec.samples)
    deflection -= deflection.mean()
    rows = np.stack([_interval_sign(v), deflection**3, _interval_sign(deflection)])
    cols = np.fft.rfft(rows, n=spec.n, axis=1)[:, :bins]
    out = np.fft.irfft(cols * lowpass(spec.freqs[:bins], pass_edge), n=nd, axis=1) * (nd / spec.n)
    return out[0], out[1], out[2]


def dead_band_motion(spec: Spectra, pass_edge: float, half_play: float) -> np.ndarray:
    """r'', r', r of the specimen behind a dead band of +/- `half_play` (scaled units) about the
    motion's centre, the position sensor before it: sign(d) max(|d| - half_play, 0) of the
    band-limited deflection d, formed at the series rate, then filtered and differentiated as the
    position is (`filtered`); (grid rows, 3), the columns of `Channels.x`."""
    bins, nd = _grid(spec, pass_edge)
    r, _ = series_motion(spec, pass_edge)
    a, b = spec.r_line
    deflection = r + a + (b - a) * np.linspace(0.0, 1.0, spec.samples)
    deflection -= deflection.mean()
    specimen = np.sign(deflection) * np.maximum(np.abs(deflection) - half_play, 0.0)
    freqs = spec.freqs[:bins]
    w = 2 * np.pi * freqs
    pos = np.fft.rfft(specimen, n=spec.n)[:bins] * lowpass(freqs, pass_edge)
    return (np.fft.irfft(np.stack([-(w**2) * pos, 1j * w * pos, pos]), n=nd, axis=1) * (nd / spec.n)).T


def another_load(
    spec: Spectra,
    values: np.ndarray,
    bad: np.ndarray,
    factor: int,
    pass_edge: float,
    correct: Callable[[np.ndarray], np.ndarray] | None = None,
) -> tuple[np.ndarray, float]:
    """Another channel of the log (another axis's load) through exactly what the load of `spec`
    went through: block means over the same blocks, the fill, the end line, the low-pass at
    `pass_edge` and `correct`, on the grid of `filtered(spec, pass_edge)`; in units of its peak.

    bad: the samples to leave out (this axis's dropouts and the channel's own); factor: the block
    length of `spec`'s block means. Returns the column and the peak it is in units of.
    """
    series, lost = block_means(values, bad, factor)
    series = series[: spec.samples]
    fill(series, lost[: spec.samples])
    peak = float(np.max(np.abs(series))) or 1.0
    series /= peak
    _ends_line(series)
    bins, nd = _grid(spec, pass_edge)
    w = 2 * np.pi * spec.freqs[:bins]
    spectrum = np.fft.rfft(series, n=spec.n)[:bins] * lowpass(spec.freqs[:bins], pass_edge)
    if correct is not None:
        spectrum = spectrum * correct(w)
    return np.fft.irfft(spectrum, n=nd) * (nd / spec.n), peak


def filtered(
    spec: Spectra,
    pass_edge: float,
    correct: Callable[[np.ndarray], np.ndarray] | None = None,
    skew_s: float | None = None,
) -> Channels:
    """r'', r', r and the load through the low-pass at `pass_edge` Hz, the load's spectrum times
    `correct(w)` (w in rad/s: the channel's known delay and filter undone; None: as logged).

    With `skew_s`, `y_skew` is that load advanced by `skew_s` as well.
    """
    stop = STOP_RATIO * pass_edge
    bins, nd = _grid(spec, pass_edge)
    freqs = spec.freqs[:bins]
    w = 2 * np.pi * freqs
    gain = lowpass(freqs, pass_edge)
    pos = spec.position[:bins] * gain
    load = spec.load[:bins] * gain * (1.0 if correct is None else correct(w))
    rows = [-(w**2) * pos, 1j * w * pos, pos, load]
    if skew_s is not None:
        rows.append(load * np.exp(1j * w * skew_s))
    cols = np.fft.irfft(np.stack(rows), n=nd, axis=1) * (nd / spec.n)
    grid_rate = nd * spec.rate / spec.n
    a, b = spec.r_line
    # analytic signal z of the filtered motion and its derivative: f = Im(z' conj z) / (2 pi |z|^2)
    one_sided = np.zeros((2, nd), dtype=complex)
    one_sided[:, :bins] = 2 * np.stack([pos, 1j * w * pos])
    one_sided[:, 0] /= 2
    z, dz = np.fft.ifft(one_sided, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        inst = (dz * z.conj()).imag / (2 * np.pi * (z.real**2 + z.imag**2))
    reach = int(np.ceil(GUARD_TRANSITIONS / (stop - pass_edge) * grid_rate))
    keep = ~_guard(_long_gaps(spec.filled, fill_tolerant(spec)), spec.n, nd, spec.samples, reach)
    keep[int(np.floor((spec.samples - 1) * nd / spec.n)) + 1 :] = False
    # covariance of white noise through gain x (iw)^p, p = 2, 1, 0: sum over the two-sided spectrum
    response = np.stack([-(w**2) * gain, 1j * w * gain, gain])
    weights = np.full(bins, 2.0)
    weights[0] = 1.0
    cov = (response * weights) @ response.conj().T
    noise_cov = spec.noise_var * cov.real / spec.n
    return Channels(
        x=cols[:3].T,
        y=cols[3],
        y_skew=cols[4] if skew_s is not None else None,
        t=np.arange(nd) / grid_rate,
        keep=keep,
        noise_cov=noise_cov,
        rate=grid_rate,
        pass_edge=pass_edge,
        inst_freq=np.nan_to_num(inst),
        r_line=a + (b - a) * np.arange(nd) * (spec.n / nd) / max(spec.samples - 1, 1),
    )
