"""The fit of one axis of a rig log: m, c, k of F = m r'' + c r' + k r (the study's Eq 5).

How, and why (see `band` and `regress` for the details):
- the band that carries the motion is read from the position's spectrum; r, r', r'' and the load
  go through the same low-pass (flat to 1.5 x the band's top), so its gain and phase cancel, and
  position noise above the band never reaches r' and r'';
- the estimator is bias-compensated least squares: the position noise left in the band is measured
  from the out-of-band spectrum and its covariance taken out of the normal equations, so the fit
  stays consistent when r is noisy (ordinary least squares shrinks m and k);
- standard errors are Newey-West (HAC), valid for the coloured residuals that filtering makes;
- m counts as identified only when its standard error is under 10 % of it and the fits at two
  wider derivative bandwidths agree with it within two standard errors; else the result gives the
  mass from geometry;
- a known delay of the load channel is removed exactly (a phase in the frequency domain), and the
  change of c for one sample of skew is always reported (c shifts by about -k x delay);
- an unknown low-pass of the load channel is read from the load's noise spectrum (`channel`): warned
  about with its size, which c's standard error then includes;
- k per amplitude band and c per frequency band test the linear model, and six departures from
  it (friction, a cubic spring, viscoelastic damping, a drift of k that may settle, backlash in the
  drive, cross-talk from another axis's load) are fitted and tested each on its own; the one the
  log supports is named (`departures`), friction, drift, backlash and cross-talk corrected;
- a sensor saturated at its rails is named (`saturation`): its samples there are left out, or the
  axis refused when they are many;
- a log whose fit is impossible (k <= 0, c < 0, R2 < 0.5), or that cannot support a fit (too slow
  a sampling rate, too few cycles, a mostly missing channel, time not in seconds), or whose scale
  is a unit error (`plausibility`: a load in kN, a position in m), is failed with its reason and
  never becomes a row of the coefficient table.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .. import units
from ..mass import specimen_mass
from . import band as bandlib
from . import channel, departures, plausibility, quantization, saturation, sensor_drift
from .logs import LOAD, UNITS, RigLog, missing
from .nonlinear import amplitude_table, frequency_table
from .regress import solve

ESTIMATOR = (
    "bias-compensated least squares (errors-in-variables correction with the position-noise level "
    "measured from the out-of-band spectrum), Newey-West HAC standard errors"
)
#: pass edges of the main fit and of the two wider derivative bandwidths, as multiples of the band's top
PASS_EDGES = (1.5, 2.25, 3.0)
#: m counts as identified when its standard error is at most this fraction of it
M_REL_SE = 0.1
#: Newey-West truncation, in 1 / (filter transition width)
LAG_TRANSITIONS = 1.5
#: sanity limits
MIN_RATE_OVER_BAND = 10.0
MIN_CYCLES = 10.0
#: fewest usable rows of the filtered grid (about 6 per cycle at the band's top)
MIN_ROWS = 60
MIN_VALID = 0.5
MIN_R2 = 0.5
PLAUSIBLE_RATE_HZ = (10.0, 1e6)
PLAUSIBLE_DURATION_S = 1e5
#: warn when one sample of channel skew moves c by more than this fraction: c is then dominated
#: by the channels' timing (below it, the sensitivity is reported with every fit, not warned about)
SKEW_WARN = 1.0
#: a channel with more than this share of its samples on its rails is refused; under it, the
#: samples on the rails are left out of the fit (as dropouts) and a warning names the saturation
MAX_RAIL_SHARE = 0.01


class AxisFailed(Exception):
    """An axis whose log cannot give, or gave, a physically possible fit; the message is the reason."""


class StillAxis(AxisFailed):
    """An axis that is logged but does not move: reported as still, not as a failed log."""


@dataclass(frozen=True)
class AxisFit:
    """One axis: m, c, k in rig units (m in kg or kg.m^2) with HAC standard errors and fit quality."""

    axis: str
    m: float
    c: float
    k: float
    m_se: float
    c_se: float
    k_se: float
    #: R2 and RMS residual over the load's range, both on the band-limited signals
    r2: float
    nrmse: float
    #: rows of the filtered grid in the fit (the band-limited signals resampled at 2.5x the stop edge)
    samples: int
    m_identified: bool
    #: mass from geometry (kg, translational axes with known factors) when m is not identified
    m_geometric: float | None
    #: inertial force against spring force at this excitation (RMS m r'' over RMS k r)
    inertia_ratio: float
    band: dict
    load_delay_s: float
    #: the load sensor's low-pass undone in the fit (e.g. "butter2:200Hz"), or None
    load_filter: str | None
    #: an unknown low-pass the load's noise spectrum shows (`channel.LowpassEstimate.to_dict()` plus
    #: `c_shift`, about -k x its delay: the bias it gives c), or None; c_se includes |c_shift|
    load_lowpass: dict | None
    #: c's standard error from the fit alone (c_se adds an unknown channel lag's shift in quadrature)
    c_se_fit: float
    #: change of c when the load is shifted by one more sample (rig units), and that over |c|
    c_per_sample_skew: float
    c_skew_relative: float
    #: m at the main and the wider derivative bandwidths: {"pass_hz", "m", "m_se"}
    m_bandwidths: list[dict]
    k_amplitude: dict
    c_frequency: dict
    #: each candidate departure's test (`departures.Departure.to_dict()`), by name
    departures: dict
    #: the departure the data supports, named, with its size and the linear fit's c and k, or None
    departure: dict | None
    #: a coarse position encoder's share of the fit (`quantization.Effect.to_dict()`), or None; k_se
    #: and c_se include its shifts, and the departures are tested net of it
    encoder: dict | None
    #: a sensor offset drifting below the band (`sensor_drift.Drift.to_dict()`), filtered out, or None
    sensor_drift: dict | None
    warnings: list[str] = field(default_factory=list)

    def mass(self) -> float | None:
        """The mass to use: the identified one, else the geometric one (None if neither)."""
        return self.m if self.m_identified else self.m_geometric

    def statement(self) -> str:
        """One sentence on the mass, for people."""
        unit = units.rig_unit("m", self.axis)
        fit = f"m = {self.m:.3g} +/- {self.m_se:.2g} {unit}"
        if self.m_identified:
            return f"{fit} (identified: precise, and stable across derivative bandwidths)"
        why = (
            f"m is not identifiable from this excitation ({fit}; inertial force about "
            f"{100 * self.inertia_ratio:.2g} % of the spring force)"
        )
        if self.m_geometric is not None:
            return (
                f"{why}; use the mass from geometry, walls, infill and TPU density: "
                f"{1e3 * self.m_geometric:.3g} g"
            )
        if units.is_rotational(self.axis):
            return f"{why}; take the inertia from CAD"
        return f"{why}; give the specimen's factors in the log's sidecar to get the mass from geometry"

    def to_dict(self) -> dict:
        out = {k: getattr(self, k) for k in self.__dataclass_fields__}
        return out | {"statement": self.statement(), "estimator": ESTIMATOR}


def check_time(log: RigLog) -> None:
    """Fail a log whose sampling rate or duration is implausible in seconds (t in ms, us, ns ...)."""
    lo, hi = PLAUSIBLE_RATE_HZ
    if not lo <= log.rate <= hi or log.duration > PLAUSIBLE_DURATION_S:
        raise AxisFailed(
            f"implausible time units: sampling rate {log.rate:.3g} Hz over {log.duration:.3g} s "
            f"(expected {lo:g} Hz to {hi:g} Hz, at most {PLAUSIBLE_DURATION_S:g} s); t must be in seconds"
        )


def _spectra(log: RigLog, axis: str) -> bandlib.Spectra:
    """Spectra of the axis: block means at about PRE_RATE, or the full rate when the band needs it."""
    r = log.data[axis].to_numpy()
    f = log.data[LOAD[axis]].to_numpy()
    clipped = _saturated(log, axis)
    if clipped and max(sum(r.share for r in found) for _, found in clipped) > MAX_RAIL_SHARE:
        raise AxisFailed(
            "; ".join(saturation.describe(col, UNITS[col], found) for col, found in clipped)
            + ": the fit is refused (a fit through clipped peaks reads them as a softening spring); "
            "record with a sensor range above the peak, or a smaller amplitude"
        )
    valid = 1.0 - log.missing_fraction.get(LOAD[axis], float(missing(f).mean()))
    if valid < MIN_VALID:
        raise AxisFailed(
            f"the load channel {LOAD[axis]} has only {100 * valid:.3g} % valid samples (the rest NaN, "
            "infinite or stuck at zero)"
        )
    usable = 1.0 - np.count_nonzero(log.dropouts[axis]) / log.dropouts[axis].size
    if usable < MIN_VALID:
        raise AxisFailed(
            f"only {100 * usable:.3g} % of the samples are valid (NaN, infinite, stuck or in gaps)"
        )
    factor = max(1, int(log.rate // bandlib.PRE_RATE))
    spec = bandlib.spectra(r, f, log.dropouts[axis], log.rate, factor)
    # the full rate when the band is too high for the block means, or when they show no band (a
    # motion above their rate averages out to noise there)
    if factor > 1 and (spec.band is None or spec.band.high * bandlib.PRE_MARGIN > spec.rate):
        spec = bandlib.spectra(r, f, log.dropouts[axis], log.rate, 1)
    if spec.band is None or not np.isfinite([spec.scale_r, spec.scale_f]).all():
        raise StillAxis(f"no motion on {axis}: the position is constant, only noise, or not finite")
    encoder = quantization.effect(r)  # after the still test: an encoder flickering by a count is still
    if encoder is not None and (coarse := quantization.too_coarse(encoder, axis)) is not None:
        raise AxisFailed(coarse)
    return spec


def _saturated(log: RigLog, axis: str) -> list[tuple[str, list[saturation.Rail]]]:
    """The axis's columns that sit on a rail, with their rails."""
    return [(col, log.rails[col]) for col in (axis, LOAD[axis]) if col in log.rails]


def _design(ch: bandlib.Channels) -> tuple[np.ndarray, np.ndarray]:
    """Columns r'', r', r, constant, trend and their per-row noise covariance."""
    span = max(float(ch.t[-1] - ch.t[0]), 1e-300)
    x = np.column_stack([ch.x, np.ones_like(ch.t), 2 * (ch.t - ch.t[0]) / span - 1])
    noise = np.zeros((5, 5))
    noise[:3, :3] = ch.noise_cov
    return x, noise


def _lags(ch: bandlib.Channels) -> int:
    transition = (bandlib.STOP_RATIO - 1.0) * ch.pass_edge
    return int(np.ceil(LAG_TRANSITIONS / transition * ch.rate))


def _cycles(ch: bandlib.Channels) -> float:
    """Cycles of motion over the kept rows: half the zero crossings of the filtered position."""
    r = ch.x[ch.keep, 2]
    s = np.signbit(r - r.mean())
    return float(np.count_nonzero(s[1:] != s[:-1]) / 2)


def _check_dropouts(spec: bandlib.Spectra, ch: bandlib.Channels) -> None:
    """Fail, naming the dropouts, a log whose gaps (and the rows the filter loses around each) leave
    under MIN_VALID of the record usable: not the excitation's fault."""
    inside = int(np.floor((spec.samples - 1) * ch.t.size / spec.n)) + 1
    usable = ch.keep.sum() / max(inside, 1)
    if usable >= MIN_VALID or not spec.filled.any():
        return
    longest = bandlib.fill_tolerant(spec)
    edges = np.diff(np.concatenate(([0], spec.filled.astype(np.int8), [0])))
    runs = np.flatnonzero(edges == -1) - np.flatnonzero(edges == 1)
    transition = (bandlib.STOP_RATIO - 1.0) * ch.pass_edge
    raise AxisFailed(
        f"dropouts leave only {100 * usable:.2g} % of the record usable: {int((runs > longest).sum())} gaps "
        f"longer than {1e3 * (longest + 1) / spec.rate:.3g} ms (of {100 * spec.filled.mean():.2g} % of the "
        f"samples, after block means of {1e3 / spec.rate:.3g} ms), each costing "
        f"{bandlib.GUARD_TRANSITIONS / transition:.2g} s either side to the filter; the excitation is not "
        "the problem: fix the sensor or its wiring, or record again"
    )


def _fit(spec: bandlib.Spectra, pass_edge: float, correct, *, skew_s: float | None = None):
    """Filter at `pass_edge` and fit; fail a log with too few cycles or usable rows.

    With `skew_s`, the solution's `also_beta` is the fit with the load advanced by that much more.
    """
    ch = bandlib.filtered(spec, pass_edge, correct, skew_s)
    _check_dropouts(spec, ch)
    cycles = _cycles(ch)
    if cycles < MIN_CYCLES:
        raise AxisFailed(f"only {cycles:.3g} cycles of excitation (at least {MIN_CYCLES:g} needed)")
    if ch.keep.sum() < MIN_ROWS:
        raise AxisFailed(
            f"only {int(ch.keep.sum())} usable rows after leaving out the ends and dropouts; record longer"
        )
    x, noise = _design(ch)
    return ch, solve(x, ch.y, ch.keep, noise, _lags(ch), also=ch.y_skew)


def _checked(log: RigLog, axis: str, load_delay_s: float, load_filter: channel.LoadFilter | None):
    """Spectra, the main filtered channels and fit, the load correction, any unknown low-pass of
    one axis and a drifting sensor offset (`sensor_drift`: both channels then high-passed and fitted
    again); raise AxisFailed when the sampling is too slow or the fit impossible."""
    spec = _spectra(log, axis)
    top = spec.band.high
    scale = spec.scale_f / spec.scale_r
    correct = channel.correction(load_delay_s, load_filter)
    ch, main = _fit(spec, PASS_EDGES[0] * top, correct, skew_s=1.0 / log.rate)
    drift = None
    ratio = sensor_drift.residual_ratio(ch, _design(ch)[0], main.beta, top)
    if ratio > sensor_drift.RATIO:
        spec, drift = sensor_drift.remove(spec, ratio, axis, float(main.beta[2]) * scale)
        ch, main = _fit(spec, PASS_EDGES[0] * top, correct, skew_s=1.0 / log.rate)
    if log.rate < MIN_RATE_OVER_BAND * top:
        raise AxisFailed(
            f"sampling rate {log.rate:.4g} Hz is under {MIN_RATE_OVER_BAND:g} x the highest excitation "
            f"frequency {top:.3g} Hz (or the excitation is aliased)"
        )
    m_log, c, k = (float(v) * scale for v in main.beta[:3])
    if not np.isfinite([m_log, c, k, *main.se[:3], main.r2]).all():
        raise AxisFailed("the fit is not finite (values too large or degenerate)")
    lag = _unknown_lowpass(log, axis, spec, load_delay_s, load_filter)
    if k <= 0 or c < 0 or main.r2 < MIN_R2:
        cu = units.rig_unit("c", axis)
        raise AxisFailed(
            f"physically impossible fit: k = {k:.4g} {units.rig_unit('k', axis)}, c = {c:.4g} {cu}, "
            f"R2 = {main.r2:.3g} (needs k > 0, c >= 0, R2 >= {MIN_R2:g})"
            + ("" if lag is None else "; " + _lag_text(lag.to_dict(), k * lag.delay_s, cu))
            + ("" if main.r2 < MIN_R2 else _impossible_cause(log, axis, k, c, spec))
        )
    unit_error = plausibility.scale_failure(axis, k, spec.scale_r, spec.scale_f, log.factors)
    if unit_error is not None:
        raise AxisFailed(unit_error)
    return spec, ch, main, correct, lag, drift


def _impossible_cause(log: RigLog, axis: str, k: float, c: float, spec: bandlib.Spectra) -> str:
    """The log faults a well-fitting (R2 >= MIN_R2) but impossible k or c points to, in words.

    k < 0: the two channels count in opposite directions (a sensor mounted or calibrated the other
    way round): negated, the fit is -k, -c (whose scale is checked too: a flipped load in kN is
    both). k > 0 with c < 0: either the load lags the position
    (c shifts by about -k x delay) or the columns are swapped: the swapped fit is the inverse of the
    transfer k + i w c, i.e. about 1/k and -c/k^2 where w c << k, as at the rig's frequencies.
    """
    ru, fu = units.rig_unit("r", axis), units.rig_unit("F", axis)
    ku, cu = units.rig_unit("k", axis), units.rig_unit("c", axis)
    load = LOAD[axis]
    if k < 0:
        scale = plausibility.scale_failure(axis, -k, spec.scale_r, spec.scale_f, log.factors)
        return (
            f"; with R2 that high, {axis} and {load} count in opposite directions (a sensor mounted or "
            f"calibrated the other way round): with one of them negated the fit gives k = {-k:.4g} {ku}, "
            f"c = {-c:.4g} {cu}; negate that column (or the sensor's calibration factor) and identify again"
            + ("" if scale is None else f"; negated, it is still an {scale}")
        )
    if k == 0 or c >= 0:
        return ""
    delay = -c / k
    return (
        f"; a negative c is no material's: either the load lags the position by at least "
        f"{1e3 * delay:.3g} ms ({delay * log.rate:.3g} samples: the logger's skew or the load sensor's "
        f"filter; give it as load_delay_s or load_filter), or the columns are swapped ({load} holding the "
        f"position in {ru}, {axis} the load in {fu}: exchanged, the fit would give about "
        f"k = {1 / k:.4g} {ku}, c = {-c / k**2:.4g} {cu}); check which column is which"
    )


def _masses(spec: bandlib.Spectra, ch, sol, correct, axis: str) -> tuple[list[dict], bool, bandlib.Channels]:
    """m at the main and the wider derivative bandwidths, and whether they agree within 2 SE."""
    scale = spec.scale_f / spec.scale_r
    wide = [(ch, sol)] + [_fit(spec, p * spec.band.high, correct) for p in PASS_EDGES[1:]]
    rows = [
        {
            "pass_hz": w_ch.pass_edge,
            "m": units.to_si("m_log", axis, float(s.beta[0]) * scale),
            "m_se": units.to_si("m_log", axis, float(s.se[0]) * scale),
        }
        for w_ch, s in wide
    ]
    stable = all(abs(row["m"] - rows[0]["m"]) <= 2 * rows[0]["m_se"] for row in rows[1:])
    return rows, stable, wide[-1][0]


def fit_axis(
    log: RigLog, axis: str, *, load_delay_s: float = 0.0, load_filter: channel.LoadFilter | None = None
) -> AxisFit:
    """Fit one axis of a validated log; raise AxisFailed with the reason when it cannot or should not.

    `load_delay_s` and `load_filter`: the load channel's known delay and low-pass, undone exactly.
    When friction or a drift of k is detected (`departures`), m, c, k come from the model with it.
    """
    spec, ch, main, correct, lag, drift = _checked(log, axis, load_delay_s, load_filter)
    scale = spec.scale_f / spec.scale_r
    x, noise = _design(ch)
    tests = departures.test(spec, ch, x, noise, _lags(ch), scale)
    encoder = quantization.effect(log.data[axis].to_numpy())
    k_lin = float(main.beta[2]) * scale
    faked = [] if encoder is None else [d for d in tests.values() if encoder.fakes(d, k_lin)]
    found = departures.supported(_genuine(tests, faked))
    if found is not None:  # something departs: is it another axis's load?
        others = _other_loads(log, axis, spec, ch, correct)
        tests |= departures.crosstalk(spec, ch, x, noise, _lags(ch), others)
        found = departures.supported(_genuine(tests, faked))
    sol = found.solution if found is not None and found.name in departures.ADOPTED else main
    if found is not None and found.name == "friction" and lag is not None:
        lag = _unknown_lowpass(log, axis, spec, load_delay_s, load_filter, friction=found.value)
    m_log, c, k = (float(v) * scale for v in sol.beta[:3])
    c_se, k_se = (float(v) * scale for v in sol.se[1:3])
    c_channel = 0.0 if lag is None else k * lag.delay_s
    c_skew = float(main.also_beta[1]) * scale - float(main.beta[1]) * scale
    bias = 0.0 if encoder is None else encoder.bias  # k's and c's relative error from the encoder
    m_rows, stable, widest = _masses(spec, ch, sol, correct, axis)
    m, m_se = m_rows[0]["m"], m_rows[0]["m_se"]
    identified = bool(m > 0 and m_se <= M_REL_SE * m and stable)
    amp = amplitude_table(widest, _lags(widest), scale, spec.scale_r)
    freq = frequency_table(ch, float(main.beta[0]), _lags(ch), scale)
    y = ch.y[ch.keep]
    inertia = float(
        np.std(sol.beta[0] * ch.x[ch.keep, 0]) / max(np.std(sol.beta[2] * ch.x[ch.keep, 2]), 1e-300)
    )
    fit = AxisFit(
        axis=axis,
        m=m,
        c=c,
        k=k,
        m_se=m_se,
        c_se=float(np.hypot(np.hypot(c_se, c_channel), c * bias)),
        k_se=float(np.hypot(k_se, k * bias)),
        r2=sol.r2,
        nrmse=float(np.sqrt(sol.rss / sol.rows) / max(float(y.max() - y.min()), 1e-300)),
        samples=sol.rows,
        m_identified=identified,
        m_geometric=None if identified else _geometric(log, axis),
        inertia_ratio=inertia,
        band=spec.band.to_dict()
        | {"filter_pass_hz": ch.pass_edge, "filter_stop_hz": bandlib.STOP_RATIO * ch.pass_edge},
        load_delay_s=load_delay_s,
        load_filter=None if load_filter is None else str(load_filter),
        load_lowpass=None if lag is None else lag.to_dict() | {"c_shift": -c_channel},
        c_se_fit=c_se,
        c_per_sample_skew=c_skew,
        c_skew_relative=abs(c_skew) / c if c > 0 else float("inf"),
        m_bandwidths=m_rows,
        k_amplitude=amp.to_dict(),
        c_frequency=freq.to_dict(),
        departures={name: d.to_dict() for name, d in tests.items()},
        departure=None if found is None else departures.describe(found, main, scale, spec, axis, freq.rows),
        encoder=None if encoder is None else encoder.to_dict(),
        sensor_drift=None if drift is None else drift.to_dict(),
    )
    fit.warnings.extend(plausibility.range_warnings(axis, spec.scale_r, spec.scale_f))
    if drift is not None:
        fit.warnings.append(sensor_drift.describe(drift, axis))
    named = _name_encoder(fit, encoder, faked, k_lin, (c_se, k_se))
    fit.warnings.extend(
        saturation.describe(col, UNITS[col], found) + ": those samples are left out of the fit"
        for col, found in _saturated(log, axis)
    )
    fit.warnings.extend(_warnings(fit, stable, amp.varies and not named, freq.varies and not named, log.rate))
    return fit


def _name_encoder(
    fit: AxisFit, encoder: quantization.Effect | None, faked: list, k_lin: float, fit_se: tuple[float, float]
) -> bool:
    """Add the coarse encoder's warning to `fit` when it made a departure up or moves k or c beyond the
    fit's own 2-SE interval (`fit_se`: c's and k's, without the encoder's share; a 4096-count encoder
    on 0.3 rad moves k 0.014 %, 1.2 SE: in the errors, not worth a warning). Its sentence also says
    the steps vary k and c over the bands, so the caller then skips those warnings; returns whether
    it was named."""
    if encoder is None:
        return False
    faked = [d for d in faked if abs(d.z) > departures.Z_CRIT]
    c_se, k_se = fit_se
    if not (faked or fit.k * encoder.bias > 2 * k_se or fit.c * encoder.bias > 2 * c_se):
        return False
    fit.warnings.append(quantization.describe(encoder, fit.axis, faked, k_lin))
    return True


def _genuine(tests: dict[str, departures.Departure], faked: list) -> dict[str, departures.Departure]:
    """The departure tests less those a coarse encoder's steps alone can make (`faked`)."""
    return {name: d for name, d in tests.items() if d not in faked}


def _other_loads(
    log: RigLog, axis: str, spec: bandlib.Spectra, ch: bandlib.Channels, correct
) -> dict[str, tuple[np.ndarray, float, str]]:
    """The other axes' loads through this axis's filter, with their peaks and units: the sources of
    cross-talk a departure test tries."""
    out = {}
    factor = max(1, int(round(log.rate / spec.rate)))
    for other in log.axes:
        col = LOAD[other]
        values = log.data[col].to_numpy(dtype=np.float64)
        bad = log.dropouts[axis] | ~np.isfinite(values)
        if other != axis and not bad.all():
            column, peak = bandlib.another_load(spec, values, bad, factor, ch.pass_edge, correct)
            out[col] = column, peak, UNITS[col]
    return out


def _unknown_lowpass(
    log: RigLog, axis: str, spec: bandlib.Spectra, delay: float, given, friction: float = 0.0
) -> channel.LowpassEstimate | None:
    """The load channel's unknown low-pass, from its noise spectrum (None when a delay or a filter is
    given, or the noise is white to Nyquist). `friction`: a Coulomb force (rig units) found in the
    load, taken out first (its square wave's harmonics would otherwise pass for a falling spectrum)."""
    if delay or given is not None:
        return None
    load = log.data[LOAD[axis]].to_numpy(dtype=np.float64)
    if friction:
        _, v = bandlib.series_motion(spec, PASS_EDGES[0] * spec.band.high)
        factor = log.rate / spec.rate
        centres = np.arange(v.size) * factor + (factor - 1) / 2
        load = load - friction * np.sign(np.interp(np.arange(load.size), centres, v))
    return channel.detect_lowpass(load, log.dropouts[axis], log.rate, (spec.band.low, spec.band.high))


def _lag_text(lag: dict, shift: float, cu: str, c: float | None = None) -> str:
    """The sentence on an unknown low-pass of the load channel (`LowpassEstimate.to_dict()`), with the
    shift of c it causes and, given c, that shift over c."""
    share = "" if c is None else f" ({100 * shift / c:.2g} % of c; c's standard error includes it)"
    return (
        f"the load's noise falls towards Nyquist (to {100 * lag['roll_off']:.2g} %) as a low-pass at about "
        f"{channel.parse(lag['filter']).cutoff_hz:.3g} Hz would make it (like {lag['filter']}), and the load "
        f"sensor's filter was not given: its lag of about {1e3 * lag['delay_s']:.2g} ms makes c low by about "
        f"{shift:.2g} {cu}{share}; give the sensor's filter (load_filter='{lag['filter']}' if that is it) "
        "or its delay (load_delay_s)"
    )


def _geometric(log: RigLog, axis: str) -> float | None:
    if log.factors is None or units.is_rotational(axis):
        return None
    return specimen_mass(log.factors)


def _unexplained(q: str, over: str, table: dict, unit: str, band: str, average: str) -> str:
    """The sentence on a band table (`nonlinear.BandTable.to_dict()`) whose bands differ with no
    departure to explain it."""
    rows = table["rows"]
    ends = "smallest to the largest" if over == "amplitude" else "lowest to the highest"
    return (
        f"{q} depends on {over} beyond its uncertainty ({rows[0][q]:.4g} to {rows[-1][q]:.4g} {unit} from "
        f"the {ends} {band}, p = {table['p_equal']:.2g}), and none of {departures.CANDIDATES} explains "
        f"it; {q} is {average} average"
    )


def _warnings(fit: AxisFit, stable: bool, k_varies: bool, c_varies: bool, rate: float) -> list[str]:
    """Doubtful but possible fits: skew sensitivity, nonlinearity, an unstable or imprecise m."""
    out = []
    cu, ku = units.rig_unit("c", fit.axis), units.rig_unit("k", fit.axis)
    if fit.load_lowpass is not None:
        out.append(_lag_text(fit.load_lowpass, -fit.load_lowpass["c_shift"], cu, fit.c))
    if fit.c_skew_relative > SKEW_WARN:
        out.append(
            f"c is dominated by the channels' timing: one sample ({1e3 / rate:.3g} ms) of skew between the "
            f"load and position channels changes c by {fit.c_per_sample_skew:+.3g} {cu}, "
            f"{fit.c_skew_relative:.2g} times c: give the known channel delay (load_delay_s) or sample "
            "faster, or c is uncertain by that much"
        )
    if fit.departure is not None:
        out.append(fit.departure["text"])
    if fit.departure is None:
        if k_varies and fit.k_amplitude["p_equal"] < departures.P_CRIT:
            out.append(_unexplained("k", "amplitude", fit.k_amplitude, ku, "deflection band", "an amplitude"))
        if c_varies and fit.c_frequency["p_equal"] < departures.P_CRIT:
            out.append(_unexplained("c", "frequency", fit.c_frequency, cu, "band", "a band"))
    if fit.m > 0 and fit.m_se <= M_REL_SE * fit.m and not stable:
        out.append("m is precise but changes with the derivative bandwidth (biased): not taken as identified")
    if fit.c < 2 * fit.c_se:
        out.append(f"c is within two standard errors of zero ({fit.c:.3g} +/- {fit.c_se:.2g} {cu})")
    if fit.r2 < 0.9:
        out.append(f"R2 = {fit.r2:.3g}: the linear model leaves much of the band-limited load unexplained")
    return out
