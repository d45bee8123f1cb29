"""Which departure from the linear joint the log supports: friction, a nonlinear spring, viscoelastic
damping, or a drift of k in time, each fitted and tested on its own.

The linear fit's band tables (`nonlinear`) say that k or c is not constant, but four different
physics move them: Coulomb friction in the clamp (its first harmonic is a damping falling as
1 / (amplitude x frequency), so a linear fit takes it for a larger c), a stiffening or softening
spring (k depends on the deflection), viscoelastic damping (c falls with frequency), and k drifting
in time (temperature, creep: along a chirp it takes a fake mass). Each candidate adds one column to
the linear model's design, on the same filtered rows:

- friction: sign(r') formed at the series rate and filtered as the load is (`band.nonlinear_columns`),
  coefficient Fc (N or N.mm);
- spring: (r - mean r)^3, likewise, coefficient k3 (N/mm^3 or N.mm/rad^3);
- viscoelastic: r' x ln(f / f_mid), f the motion's instantaneous frequency: c's slope per e-fold;
- drift: r x (time scaled to [-1, 1] over the log): half k's change over the run.

Each is tested by the HAC Wald statistic of its coefficient. Among those beyond `Z_CRIT`, the one
whose model leaves the least residual is named. Along one chirp time and frequency go together: a
k that depends only on frequency looks like a drift; viscoelastic damping moves c too, a drift does not.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

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
ADOPTED = ("friction", "drift")


@dataclass(frozen=True)
class Departure:
    """One candidate's test: its coefficient and standard error (rig units), z, p, and the fit."""

    name: str
    value: float
    se: float
    z: float
    p: float
    rss: float
    solution: Solution

    def to_dict(self) -> dict:
        return {"value": self.value, "se": self.se, "z": self.z, "p": self.p, "rss": self.rss}


def columns(spec: bandlib.Spectra, ch: bandlib.Channels) -> dict[str, np.ndarray]:
    """The candidates' extra columns on the grid of `ch` (scaled units)."""
    sign, cube = bandlib.nonlinear_columns(spec, ch.pass_edge)
    band = spec.band
    mid = np.sqrt(band.low * band.high)
    freq = np.clip(ch.inst_freq, band.low, band.high)
    record = max((spec.samples - 1) / spec.rate, 1e-300)  # the log's span (the grid runs on into padding)
    ramp = 2 * ch.t / record - 1
    return {
        "friction": sign,
        "spring": cube,
        "viscoelastic": ch.x[:, 1] * np.log(freq / mid),
        "drift": (ch.x[:, 2] + ch.r_line) * ramp,  # the deflection: the line taken out of r is in the load
    }


def _units(spec: bandlib.Spectra, scale: float) -> dict[str, float]:
    """Scaled coefficient -> rig units per candidate (`scale` = scale_f / scale_r)."""
    return {
        "friction": spec.scale_f,
        "spring": scale / spec.scale_r**2,
        "viscoelastic": scale,
        "drift": scale,
    }


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
    Raises:
        numpy.linalg.LinAlgError: a candidate's design is singular.
    """
    p = x.shape[1]
    padded = np.zeros((p + 2, p + 2))
    padded[:p, :p] = noise
    to_rig = _units(spec, scale)
    cols = columns(spec, ch)
    # a slow quadratic below the band: a drifting position offset times the drift's ramp is one
    bend = (2 * ch.t / max(ch.t[ch.keep].max(), 1e-300) - 1) ** 2
    out = {}
    for name, col in cols.items():
        sol = solve(np.column_stack([x, bend, col]), ch.y, ch.keep, padded, lags)
        beta, se = float(sol.beta[p + 1]), float(sol.se[p + 1])
        z = beta / se if se > 0 else 0.0
        out[name] = Departure(
            name=name,
            value=beta * to_rig[name],
            se=se * to_rig[name],
            z=z,
            p=math.erfc(abs(z) / math.sqrt(2)),  # two-sided normal tail
            rss=sol.rss,
            solution=sol,
        )
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
    else:
        change = 200 * v / k_lin
        text = (
            f"k drifts in time: {change:+.2g} % from the start to the end of the run (temperature, creep; "
            f"along one chirp a k that depends only on frequency looks the same); k is the mid-run value "
            f"from the model with the drift (the linear fit gave {k_lin:.4g} {ku})"
        )
    return out | {"text": text}
