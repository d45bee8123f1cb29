"""Rig logs written from the physics, independently of `designer` (no code shared with it).

The study's rig imposes a linear chirp on the specimen: r(t) = A sin(phi(t)) with
phi = 2 pi (f0 t + (f1 - f0) t^2 / (2 T)). The load on the specimen is whatever its equation of
motion needs, F = m r'' + c r' + k r (+ k3 r^3 for a stiffening spring, k3 < 0 a softening one,
+ the force of a Maxwell arm k2, tau for viscoelastic, frequency-dependent damping, integrated as an
ODE, + Coulomb friction Fc sign(r') in the clamp, + a drift of k in time, k (1 + d (t/T - 1/2)), or
an exponential warm-up, k (1 + d (1 - exp(-t / tau)))). With `servo`, the motion is not imposed but
comes from the hub pulling the specimen through a stiff spring and damper, solved as an ODE; with
`backlash`, the drive has a dead band: the encoder on the motor logs the chirp, the specimen moves
only once the play is taken up. The sensors then add what real rigs add: white noise on position
and load, offsets and linear drift, timestamps with jitter or rounded to a coarse resolution, a
delay of the load channel, dropouts (both channels NaN, or the load stuck at zero), single-sample
glitches of the load (NaN or an exact zero), the load sensor's own analogue Butterworth low-pass
(scipy.signal), its saturation at a rail, cross-talk from another axis's load, and columns logged
in another unit than the schema's (kN labelled N, m labelled mm).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.signal import butter, cont2discrete, lfilter, lsim

LOADS = {"x": "Fx", "y": "Fy", "z": "Fz", "theta": "Ttheta", "phi": "Tphi", "psi": "Tpsi"}
#: kg (kg.m^2) -> the log's inertia coefficient: N per mm/s^2 is 1000 kg, N.mm per rad/s^2 1e-3 kg.m^2
INERTIA = {"x": 1e-3, "y": 1e-3, "z": 1e-3, "theta": 1e3, "phi": 1e3, "psi": 1e3}


def sweep(t, f0: float, f1: float, T: float, amplitude: float, phase_deg: float = 0.0):
    """The imposed chirp and its first two time derivatives (closed form); `phase_deg` shifts it."""
    rate = (f1 - f0) / T  # Hz per second
    angle = 2.0 * np.pi * (f0 * t + 0.5 * rate * t * t) + np.radians(phase_deg)
    speed = 2.0 * np.pi * (f0 + rate * t)  # d angle / dt
    r = amplitude * np.sin(angle)
    dr = amplitude * speed * np.cos(angle)
    ddr = amplitude * (2.0 * np.pi * rate * np.cos(angle) - speed * speed * np.sin(angle))
    return r, dr, ddr


def _maxwell(t, dr: np.ndarray, k2: float, tau: float) -> np.ndarray:
    """Force of a spring k2 in series with a damper k2 tau, driven by the deflection rate r'(t).

    f' = k2 r' - f / tau, integrated exactly for r' linear between samples (scipy's lsim).
    """
    system = ([[-1.0 / tau]], [[k2]], [[1.0]], [[0.0]])
    return lsim(system, dr, t)[1]


def _servo(t, spec: dict, f0: float, f1: float, T: float, m: float) -> tuple[np.ndarray, np.ndarray]:
    """Specimen pulled by the hub through stiffness K = 20 k and damping C: returns r(t), F(t).

    m r'' + c r' + k r = K (q - r) + C (q' - r'), a linear ODE driven by the hub's q and q',
    integrated exactly for inputs linear between samples (scipy's lsim).
    """
    c, k, A = spec["c"], spec["k"], spec["amplitude"]
    big_k = 20.0 * k
    big_c = 2.0 * np.sqrt(big_k * m)
    a = [[0.0, 1.0], [-(k + big_k) / m, -(c + big_c) / m]]
    b = [[0.0, 0.0], [big_k / m, big_c / m]]
    q, dq, _ = sweep(t, f0, f1, T, A)
    _, _, state = lsim((a, b, np.eye(2), np.zeros((2, 2))), np.column_stack([q, dq]), t)
    r, dr = state.T
    return r, big_k * (q - r) + big_c * (dq - dr)


def _load(t, spec: dict, f0: float, f1: float, T: float, axis: str) -> tuple[np.ndarray, np.ndarray]:
    """True position and load at the sampling instants t (the load at t - skew comes separately)."""
    m = spec.get("m", 0.0) * INERTIA[axis]
    if spec.get("servo"):
        return _servo(t, spec, f0, f1, T, m)
    r, dr, ddr = sweep(t, f0, f1, T, spec["amplitude"], spec.get("phase", 0.0))
    s, ds, dds = r, dr, ddr
    if "backlash" in spec:  # the specimen moves only outside the dead band |r| < play / 2
        half = spec["backlash"] / 2
        engaged = np.abs(r) > half
        s, ds, dds = np.where(engaged, r - half * np.sign(r), 0.0), dr * engaged, ddr * engaged
    drift = spec.get("drift", 0.0)
    if "drift_tau" in spec:
        k = spec["k"] * (1.0 + drift * (1.0 - np.exp(-t / spec["drift_tau"])))
    else:
        k = spec["k"] * (1.0 + drift * (t / T - 0.5))
    load = m * dds + spec["c"] * ds + k * s + spec.get("k3", 0.0) * s**3
    load = load + spec.get("friction", 0.0) * np.sign(ds)
    if "maxwell" in spec:
        k2, tau = spec["maxwell"]
        load = load + _maxwell(t, ds, k2, tau)
    return r, load


#: oversampling of the continuous-time load noise that a sensor's analogue filter sees
OVERSAMPLE = 8


def _sensor_filter(t, load, noise_sd, load_filter, rng) -> np.ndarray:
    """The load plus broadband noise through an analogue Butterworth, then sampled at t.

    The noise is white up to OVERSAMPLE x the sampling rate (noise_sd per sample below the
    original Nyquist, so the in-band level is that of the unfiltered case): the filter acts on a
    continuous signal and what passes above Nyquist aliases, as in a real sensor and ADC.
    """
    fine = np.linspace(t[0], t[-1], (t.size - 1) * OVERSAMPLE + 1)
    signal = np.interp(fine, t, load) + noise_sd * np.sqrt(OVERSAMPLE) * rng.standard_normal(fine.size)
    b, a = butter(load_filter[0], 2 * np.pi * load_filter[1], analog=True)
    # exact for input linear between the fine samples (as lsim), as a recursive filter: fast
    bd, ad, _ = cont2discrete((b, a), (fine[-1] - fine[0]) / (fine.size - 1), method="foh")
    return np.interp(t, fine, lfilter(np.ravel(bd), ad, signal))


def make_log(
    axes: dict[str, dict],
    *,
    duration: float,
    rate: float,
    f0: float = 0.2,
    f1: float = 1.85,
    position_noise: float = 0.002,
    load_noise: float = 0.02,
    skew_s: float = 0.0,
    jitter: float = 0.0,
    dropouts: float = 0.0,
    offsets: bool = False,
    time_scale: float = 1.0,
    glitches: float = 0.0,
    glitch_value: float = np.nan,
    load_filter: tuple[int, float] | None = None,
    load_clip: float | None = None,
    time_resolution: float | None = None,
    load_unit: float = 1.0,
    position_unit: float = 1.0,
    seed: int = 0,
) -> pd.DataFrame:
    """A log in the rig schema (t [s], coordinates mm or rad, loads N or N.mm).

    axes: {axis: {"k", "c", "m" (kg or kg.m^2), "amplitude", optional "k3", "maxwell": (k2, tau),
    "servo": True, "friction": Fc (N or N.mm), "drift": d (k changes by the fraction d from start to
    end, linearly in time), "drift_tau": tau (s; with it k changes by d as 1 - exp(-t / tau), a
    warm-up), "backlash": play (mm or rad: the dead band's full width; the encoder is on the motor),
    "phase": deg (the chirp's phase), "crosstalk": (other axis, fraction) (this load sensor also
    reads that fraction of the other axis's load), "still": True (logged, not moving: position and
    load only noise)} in rig units. position_noise: white noise as a fraction of the amplitude;
    load_noise: as a fraction of the load's RMS. skew_s: the load channel lags by this much. jitter: sampling
    instants move by up to this fraction of the interval. dropouts: fraction of samples in 40 ms
    segments, alternately NaN in both channels and the load stuck at zero. offsets: add sensor
    offsets and linear drift. time_scale: multiplies the t column (1e9 writes nanoseconds).
    glitches: fraction of load samples replaced, one by one at random, by `glitch_value` (NaN or 0).
    load_filter: (order, cutoff Hz) of an analogue Butterworth the load (with its noise) goes through.
    load_clip: the load sensor saturates at this fraction of its largest reading (both rails).
    time_resolution: t is rounded to this many seconds (a logger's coarse clock).
    load_unit, position_unit: the logged loads and positions are multiplied by these (1e-3: the load
    logged in kN, or the position in m, under the schema's N and mm columns).
    """
    rng = np.random.default_rng(seed)
    n = int(round(duration * rate)) + 1
    t = np.arange(n) / rate
    if jitter:
        t = t + rng.uniform(-jitter / 2, jitter / 2, n) / rate
        t[0] = 0.0
    cols = {"t": t * time_scale}
    if time_resolution:
        cols["t"] = np.round(t / time_resolution) * time_resolution * time_scale
    seg = max(int(0.04 * rate), 6)
    starts = rng.integers(0, n - seg, size=int(round(dropouts * n / seg)))
    truth = {}
    for axis, spec in axes.items():
        if spec.get("still"):
            truth[axis] = np.zeros(n), np.zeros(n)
        else:
            r, load = _load(t, spec, f0, f1, duration, axis)
            if skew_s:
                load = _load(np.clip(t - skew_s, 0.0, None), spec, f0, f1, duration, axis)[1]
            truth[axis] = r, load
    for axis, spec in axes.items():
        r, load = truth[axis]
        rms = spec["k"] * spec["amplitude"] if spec.get("still") else np.sqrt(np.mean(load**2))
        if "crosstalk" in spec:
            other, fraction = spec["crosstalk"]
            load = load + fraction * truth[other][1]
        r = r + position_noise * spec["amplitude"] * rng.standard_normal(n)
        if load_filter is None:
            load = load + load_noise * rms * rng.standard_normal(n)
        else:
            load = _sensor_filter(t, load, load_noise * rms, load_filter, rng)
        if load_clip is not None:
            rail = load_clip * np.max(np.abs(load))
            load = np.clip(load, -rail, rail)
        if glitches:
            rows = rng.choice(np.arange(1, n - 1), size=int(glitches * n), replace=False)
            load[rows] = glitch_value
        if offsets:
            r = r + 0.05 * spec["amplitude"] + 0.01 * spec["amplitude"] * t / duration
            rms = np.sqrt(np.mean(load**2))
            load = load - 0.1 * rms + 0.03 * rms * t / duration
        for i, s in enumerate(starts):
            if i % 2:
                load[s : s + seg] = 0.0
            else:
                r[s : s + seg] = np.nan
                load[s : s + seg] = np.nan
        cols[axis], cols[LOADS[axis]] = r * position_unit, load * load_unit
    return pd.DataFrame(cols)
