"""Which departure from the linear joint the log supports: friction, a nonlinear spring, viscoelastic
damping, a drift of k in time, backlash in the drive, or cross-talk from another axis's load, each
fitted and tested on its own.

The linear fit's band tables (`nonlinear`) say that k or c is not constant, but different physics
move them: Coulomb friction in the clamp (its first harmonic is a damping falling as
1 / (amplitude x frequency), so a linear fit takes it for a larger c), a stiffening or softening
spring (k depends on the deflection), viscoelastic damping (c falls with frequency), k drifting
in time (temperature, creep: along a chirp it takes a fake mass), a dead band in the drive seen by
an encoder on the motor (the specimen stands still while the motor crosses the play: a secant
stiffness rising with amplitude, which a cubic spring fits only roughly), and the load sensor
reading a share of another axis's load (out of phase, a damping falling with frequency). Each
candidate adds one column to the linear model's design, on the same filtered rows:

- friction: sign(r') formed at the series rate and filtered as the load is (`band.nonlinear_columns`),
  coefficient Fc (N or N.mm);
- spring: (r - mean r)^3, likewise, coefficient k3 (N/mm^3 or N.mm/rad^3);
- viscoelastic: r' x ln(f / f_mid), f the motion's instantaneous frequency: c's slope per e-fold;
- drift: r x g(time), g -1 at the start, 0 at mid-run and 1 at the end of the log: a straight line,
  or exponential settling exp(-t / tau) (a warm-up) with tau the best of `SETTLING`; the
  coefficient is half k's change over the run, and k's own the mid-run value;
- backlash: sign(r - mean r), formed and filtered as friction's: coefficient -k x half the play;
- crosstalk: another axis's load, through the same filter (`band.another_load`): the share of it
  this load sensor reads.

Each is tested by the HAC Wald statistic of its coefficient. Among those beyond `Z_CRIT`, the one
whose model leaves the least residual is named. Along one chirp time and frequency go together: a
k that depends only on frequency looks like a drift; viscoelastic damping moves c too, a drift does not.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from .. import units
from . import band as bandlib
from .regress import Solution, solve

#: |coefficient| / standard error beyond which a departure counts as present (two-sided p about 1e-5)
Z_CRIT = 4.5
#: the same level as a p-value, for the band tables' equality tests when no candidate is found (at
#: their own 1 % they flag about one clean log in 40)
P_CRIT = math.erfc(Z_CRIT / math.sqrt(2))
#: departures whose model gives the headline m, c, k (the linear ones are then biased: friction
#: doubles c, a drift takes a fake mass and moves k); a nonlinear spring or viscoelastic damping keeps
#: the linear fit's k and c, the averages over this excitation that a linear joint model can carry
ADOPTED = ("friction", "drift", "backlash", "crosstalk")
#: the candidates, in words
CANDIDATES = "friction, a cubic spring, viscoelastic damping, a drift of k, backlash or cross-talk"
#: another axis's load whose course this axis's motion explains beyond this R2 (the same chirp in
#: phase) is no cross-talk candidate: its share cannot be told apart from this axis's k and c
CROSSTALK_R2 = 0.99
#: time constants of the exponential settling a drift may follow, as fractions of the log's length
#: (besides a straight line)
SETTLING = (0.03, 0.05, 0.08, 0.12, 0.2, 0.3, 0.5, 0.8, 1.2, 2.0)


@dataclass(frozen=True)
class Departure:
    """One candidate's test: its coefficient and standard error (rig units), z, p, and the fit;
    `detail` says which form it took (a drift's `tau_s`, None for a straight line; cross-talk's
    source column `from`)."""

    name: str
    value: float
    se: float
    z: float
    p: float
    rss: float
    solution: Solution
    detail: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        return {"value": self.value, "se": self.se, "z": self.z, "p": self.p, "rss": self.rss} | self.detail


def settling_shapes(s: np.ndarray) -> list[tuple[float, np.ndarray]]:
    """Per u in SETTLING, exp(-s / u) (s the time over the log's length) scaled to -1 at the start,
    0 at mid-run and 1 at the end, as the straight line 2 s - 1 of `columns` is (so a coefficient is
    half k's change over the run, and k's own is its mid-run value)."""
    return [(u, (np.exp(-s / u) - np.exp(-0.5 / u)) * 2 / np.expm1(-1 / u)) for u in SETTLING]


def columns(spec: bandlib.Spectra, ch: bandlib.Channels) -> dict[str, np.ndarray]:
    """The candidates' extra columns on the grid of `ch` (scaled units); the drift's, a straight
    line (`_drift` tries the others)."""
    sign, cube, dead = bandlib.nonlinear_columns(spec, ch.pass_edge)
    band = spec.band
    mid = np.sqrt(band.low * band.high)
    freq = np.clip(ch.inst_freq, band.low, band.high)
    return {
        "friction": sign,
        "spring": cube,
        "viscoelastic": ch.x[:, 1] * np.log(freq / mid),
        "drift": (ch.x[:, 2] + ch.r_line) * (2 * ch.t / _record(spec) - 1),
        "backlash": dead,
    }


def _record(spec: bandlib.Spectra) -> float:
    """The log's span, s (the grid runs on into padding)."""
    return max((spec.samples - 1) / spec.rate, 1e-300)


def _units(spec: bandlib.Spectra, scale: float) -> dict[str, float]:
    """Scaled coefficient -> rig units per candidate (`scale` = scale_f / scale_r)."""
    return {
        "friction": spec.scale_f,
        "spring": scale / spec.scale_r**2,
        "viscoelastic": scale,
        "drift": scale,
        "backlash": spec.scale_f,
    }


def _one(name, col, x, y, keep, noise, lags, to_rig, detail=None) -> Departure:
    """Fit the design `x` plus `col` and test its coefficient."""
    sol = solve(np.column_stack([x, col]), y, keep, noise, lags)
    beta, se = float(sol.beta[-1]), float(sol.se[-1])
    z = beta / se if se > 0 else 0.0
    return Departure(
        name=name,
        value=beta * to_rig,
        se=se * to_rig,
        z=z,
        p=math.erfc(abs(z) / math.sqrt(2)),  # two-sided normal tail
        rss=sol.rss,
        solution=sol,
        detail=detail or {},
    )


def _explained(x: np.ndarray, column: np.ndarray, keep: np.ndarray) -> float:
    """R2 of `column` on the columns of `x` (ordinary least squares over the kept rows)."""
    beta, *_ = np.linalg.lstsq(x[keep], column[keep], rcond=None)
    resid = column[keep] - x[keep] @ beta
    centred = column[keep] - column[keep].mean()
    return 1.0 - float(resid @ resid) / max(float(centred @ centred), 1e-300)


def _behind_dead_band(
    spec: bandlib.Spectra,
    ch: bandlib.Channels,
    base: np.ndarray,
    noise: np.ndarray,
    lags: int,
    found: Departure,
    sign: np.ndarray,
) -> Departure:
    """The backlash test with the model behind the dead band it sizes: m, c, k on the specimen's
    own motion (it stands still inside the band, so the damping is not there either: the sign
    column alone leaves c about 1.3 % low at a play of 2 % of the amplitude). The test stays the
    sign column's (`sign`, its column)."""
    k = float(found.solution.beta[2])
    half = -float(found.solution.beta[-1]) / k if k > 0 else 0.0
    if half <= 0 or abs(found.z) <= Z_CRIT:  # no dead band to stand behind
        return found
    x = base.copy()
    x[:, :3] = bandlib.dead_band_motion(spec, ch.pass_edge, half)
    exact = _one(found.name, sign, x, ch.y, ch.keep, noise, lags, 1.0)
    return replace(found, solution=exact.solution)


def _drift(
    spec: bandlib.Spectra,
    ch: bandlib.Channels,
    base: np.ndarray,
    noise: np.ndarray,
    lags: int,
    to_rig: float,
    straight: np.ndarray,
) -> Departure:
    """The drift's test: the `straight` line's column (`columns`), unless the best exponential
    settling (least residual) has a curvature the line does not: its coefficient beside the line's
    beyond Z_CRIT. (Along a chirp a fake mass, r'' = -w(t)^2 r, is also r times a curve in time:
    without that test a straight drift would pass for a slow settling plus a negative mass.)"""
    deflection, record = ch.x[:, 2] + ch.r_line, _record(spec)
    args = (ch.y, ch.keep, noise, lags, to_rig)
    line = _one("drift", straight, base, *args, {"tau_s": None})
    shapes = settling_shapes(ch.t / record)
    # the shape that leaves the least residual beside `base`, by projection (ordinary least
    # squares: one factorisation for all of them), then tested in full
    q, _ = np.linalg.qr(base[ch.keep])
    y = ch.y[ch.keep] - q @ (q.T @ ch.y[ch.keep])
    cols = np.stack([deflection[ch.keep] * g[ch.keep] for _, g in shapes], axis=1)
    cols -= q @ (q.T @ cols)
    explained = (cols.T @ y) ** 2 / np.maximum(np.einsum("ij,ij->j", cols, cols), 1e-300)
    u, shape = shapes[int(np.argmax(explained))]
    best = _one("drift", deflection * shape, base, *args, {"tau_s": u * record})
    if abs(best.z) <= Z_CRIT:  # no settling to speak of
        return line
    padded = np.zeros((noise.shape[0] + 1, noise.shape[0] + 1))
    padded[:-1, :-1] = noise
    both = _one(
        "drift", deflection * shape, np.column_stack([base, straight]), ch.y, ch.keep, padded, lags, 1.0
    )
    return best if abs(both.z) > Z_CRIT else line


def _base(ch: bandlib.Channels, x: np.ndarray, noise: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The linear design plus a slow quadratic below the band (a drifting position offset times a
    drift's ramp is one), and the noise covariance padded for it and one candidate column."""
    p = x.shape[1]
    padded = np.zeros((p + 2, p + 2))
    padded[:p, :p] = noise
    bend = (2 * ch.t / max(ch.t[ch.keep].max(), 1e-300) - 1) ** 2
    return np.column_stack([x, bend]), padded


def test(
    spec: bandlib.Spectra,
    ch: bandlib.Channels,
    x: np.ndarray,
    noise: np.ndarray,
    lags: int,
    scale: float,
) -> dict[str, Departure]:
    """Fit the linear design `x` (rows, p) plus each candidate's column; the tests by name.

    noise: the (p, p) regressor-noise covariance of `x` (the candidates' columns count as exact).
    A drift is tested in each of its shapes (`_drift`); backlash's model is the one behind its
    dead band. Cross-talk is `crosstalk`'s.
    Raises:
        numpy.linalg.LinAlgError: a candidate's design is singular.
    """
    base, padded = _base(ch, x, noise)
    to_rig = _units(spec, scale)
    out = {}
    for name, col in columns(spec, ch).items():
        if name == "drift":
            out[name] = _drift(spec, ch, base, padded, lags, to_rig[name], col)
        elif name == "backlash":
            found = _one(name, col, base, ch.y, ch.keep, padded, lags, to_rig[name])
            out[name] = _behind_dead_band(spec, ch, base, padded, lags, found, col)
        else:
            out[name] = _one(name, col, base, ch.y, ch.keep, padded, lags, to_rig[name])
    return out


def crosstalk(
    spec: bandlib.Spectra,
    ch: bandlib.Channels,
    x: np.ndarray,
    noise: np.ndarray,
    lags: int,
    others: dict[str, tuple[np.ndarray, float, str]],
) -> dict[str, Departure]:
    """Cross-talk tests, "crosstalk from <column>": `others` are other axes' loads on the grid of
    `ch` (`band.another_load`) with their peaks and units, by column name; each is one candidate
    column beside the linear design `x` (as `test`), its coefficient the share of that load this
    load sensor reads. A load this axis's motion explains (the same chirp in phase) is not tested."""
    base, padded = _base(ch, x, noise)
    out = {}
    for col, (load, peak, unit) in others.items():
        detail = {"from": col, "from_unit": unit}
        if _explained(x, load, ch.keep) > CROSSTALK_R2:
            continue  # that axis moves as this one: its load cannot be told from this k and c
        try:
            found = _one("crosstalk", load, base, ch.y, ch.keep, padded, lags, spec.scale_f / peak, detail)
        except np.linalg.LinAlgError:  # the other load is this axis's motion over again: no test
            continue
        out[f"crosstalk from {col}"] = found
    return out


def supported(tests: dict[str, Departure]) -> Departure | None:
    """The departure the data supports: beyond Z_CRIT, and the least residual among those."""
    present = [d for d in tests.values() if abs(d.z) > Z_CRIT]
    return min(present, key=lambda d: d.rss) if present else None


def describe(
    found: Departure, linear: Solution, scale: float, spec: bandlib.Spectra, axis: str, c_bands: list[dict]
) -> dict:
    """The departure named, its size in words and numbers, and the linear fit's c and k beside it.

    c_bands: the rows of the c(frequency) table (`nonlinear.frequency_table`), quoted for damping.
    """
    ku, cu, fu = (units.rig_unit(q, axis) for q in ("k", "c", "F"))
    c_lin, k_lin = float(linear.beta[1]) * scale, float(linear.beta[2]) * scale
    v, se = found.value, found.se
    out = {"name": found.name, "value": v, "se": se, "z": found.z, "linear_c": c_lin, "linear_k": k_lin}
    out |= found.detail
    if found.name == "friction":
        share = 100 * abs(v) / spec.scale_f
        text = (
            f"Coulomb friction: a {'torque' if units.is_rotational(axis) else 'force'} {v:.3g} +/- "
            f"{se:.2g} {fu} against the motion ({share:.2g} % of "
            f"the peak load); m, c, k are from the model with it (the linear fit took it for "
            f"c = {c_lin:.4g} {cu}); c's standard error there runs about a quarter small (on simulated "
            "logs 85 % of fits lie within two of the truth)"
        )
    elif found.name == "spring":
        k_small = float(found.solution.beta[2]) * scale
        change = 100 * v * spec.scale_r**2 / k_small
        kind = "stiffening" if v > 0 else "softening"
        text = (
            f"a {kind} spring: k3 = {v:.3g} +/- {se:.2g} {fu}/{units.rig_unit('r', axis)}^3, the secant "
            f"stiffness {change:+.2g} % at the largest deflection ({spec.scale_r:.3g} "
            f"{units.rig_unit('r', axis)}) against {k_small:.4g} {ku} at small ones; k is the average over "
            "this amplitude and its standard error does not cover the nonlinearity"
        )
    elif found.name == "viscoelastic":
        trend = "falls" if v < 0 else "rises"
        lo, hi = c_bands[0], c_bands[-1]
        text = (
            f"{'viscoelastic damping' if v < 0 else 'damping that rises with frequency'}: c {trend} with "
            f"frequency, from {lo['c']:.3g} {cu} at {lo['from_hz']:.2g}-{lo['to_hz']:.2g} Hz to "
            f"{hi['c']:.3g} at {hi['from_hz']:.2g}-{hi['to_hz']:.2g} Hz ({v:+.2g} {cu} per e-fold of "
            "frequency); c is the average over this excitation and its standard error does not cover the "
            "frequency dependence"
        )
    elif found.name == "drift":
        k_mid = float(found.solution.beta[2]) * scale
        change = 200 * v / (k_mid - v)  # k's change over the run, over its value at the start
        out["change"] = change / 100
        tau = found.detail.get("tau_s")
        course = "in time" if tau is None else f"as a warm-up, settling like exp(-t / {tau:.3g} s),"
        text = (
            f"k drifts {course} {change:+.2g} % from the start to the end of the run (temperature, creep; "
            f"along one chirp a k that depends only on frequency looks the same); k is the mid-run value "
            f"(t = {_record(spec) / 2:.3g} s) from the model with the drift (the linear fit gave "
            f"{k_lin:.4g} {ku})"
        )
    elif found.name == "backlash":
        text = _backlash_text(found, scale, spec, axis, k_lin, out)
    else:
        text = _crosstalk_text(found, axis, c_lin, k_lin)
    return out | {"text": text}


def _backlash_text(
    found: Departure, scale: float, spec: bandlib.Spectra, axis: str, k_lin: float, out: dict
) -> str:
    """A dead band in the drive (or its opposite, a step at the sign change), sized; sets out["play"]."""
    ku, fu, ru = (units.rig_unit(q, axis) for q in ("k", "F", "r"))
    v = found.value
    k_model = float(found.solution.beta[2]) * scale
    play = -2 * v / k_model
    out["play"] = play
    if play > 0:
        return (
            f"backlash: the drive has a dead band of {play:.3g} {ru} ({100 * play / spec.scale_r:.2g} % "
            f"of the motion's peak) between the position sensor and the specimen, which stands still "
            f"while the drive crosses it (an encoder on the motor); m, c, k are from the model with it "
            f"(the linear fit gave k = {k_lin:.4g} {ku}); put the encoder at the specimen or take the "
            "play out of the drive"
        )
    return (
        f"the load steps by {-2 * v:.3g} {fu} where the deflection changes sign (a preload or a "
        f"snap-through, the opposite of a dead band); m, c, k are from the model with it (the "
        f"linear fit gave k = {k_lin:.4g} {ku})"
    )


def _crosstalk_text(found: Departure, axis: str, c_lin: float, k_lin: float) -> str:
    """Another axis's load read by this axis's sensor, with its share."""
    ku, cu, fu = (units.rig_unit(q, axis) for q in ("k", "c", "F"))
    v, se = found.value, found.se
    source, unit = found.detail["from"], found.detail["from_unit"]
    share = f"{100 * v:.2g} % (+/- {100 * se:.2g} %)" if unit == fu else f"{v:.3g} +/- {se:.2g} {fu}/{unit}"
    return (
        f"cross-talk: the load sensor of {axis} reads {share} of {source}, the load of another axis "
        f"(a departure no material law explains); m, "
        f"c, k are from the model with it (the linear fit took it for c = {c_lin:.4g} {cu}, k = "
        f"{k_lin:.4g} {ku}); decouple the load channels (the sensor's cross-talk matrix)"
    )
