"""Identification against what real rigs add, over many seeds: the figures README's identification
section quotes.

Logs come from tests/physics_logs.py (written from the physics, importing nothing from designer):
the study's middle x joint (k 0.8 N/mm, c 2e-3 N.s/mm, 1 g, 2 mm of motion), the study's chirp
0.2-1.85 Hz, position noise 0.2 % of the amplitude, load noise 2 % of its RMS. Per case: the median
and worst error of k and c, how often the truth lies within 2 reported standard errors, the spread
of the errors over the mean standard error, and what the tool said (the departure it named, the
unknown filter it saw, failures).

    python benchmarks/identify_cases.py [--seeds 20] [--duration 60] [--rate 1000] [--case NAME ...]
"""

import argparse
import sys
import time
from collections import Counter
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from physics_logs import make_log  # noqa: E402

from designer.rig.identify import identify  # noqa: E402

X = {"k": 0.8, "c": 2e-3, "m": 1e-3, "amplitude": 2.0}
FC = 0.02 * 0.8 * 2.0  # 2 % of the peak spring force
WARMUP_TAU = 12.0  # s: a fifth of the default 60 s log
CASES = {
    "clean": ({"x": X}, {}, {}),
    "0.1 % NaN glitches": ({"x": X}, {"glitches": 0.001}, {}),
    "1 % NaN glitches": ({"x": X}, {"glitches": 0.01}, {}),
    "0.1 % zero glitches": ({"x": X}, {"glitches": 0.001, "glitch_value": 0.0}, {}),
    "1 % zero glitches": ({"x": X}, {"glitches": 0.01, "glitch_value": 0.0}, {}),
    "butter2 200 Hz, unknown": ({"x": X}, {"load_filter": (2, 200.0)}, {}),
    "butter2 100 Hz, unknown": ({"x": X}, {"load_filter": (2, 100.0)}, {}),
    "butter2 50 Hz, unknown": ({"x": X}, {"load_filter": (2, 50.0)}, {}),
    "butter2 200 Hz, given": ({"x": X}, {"load_filter": (2, 200.0)}, {"load_filter": "butter2:200Hz"}),
    "butter2 100 Hz, given": ({"x": X}, {"load_filter": (2, 100.0)}, {"load_filter": "butter2:100Hz"}),
    "butter2 50 Hz, given": ({"x": X}, {"load_filter": (2, 50.0)}, {"load_filter": "butter2:50Hz"}),
    "2 % Coulomb friction": ({"x": dict(X, friction=FC)}, {}, {}),
    "0.5 % Coulomb friction": ({"x": dict(X, friction=FC / 4)}, {}, {}),
    "softening spring (-20 % at 2 mm)": ({"x": dict(X, k3=-0.2 * 0.8 / 4)}, {}, {}),
    "stiffening spring (+20 % at 2 mm)": ({"x": dict(X, k3=0.2 * 0.8 / 4)}, {}, {}),
    "viscoelastic (Maxwell 0.04 N/mm, 0.16 s)": ({"x": dict(X, maxwell=(0.04, 0.16))}, {}, {}),
    "k drifts 5 % over the run": ({"x": dict(X, drift=0.05)}, {}, {}),
    "load in kN under the N column": ({"x": X}, {"load_unit": 1e-3}, {}),
    "position in m under the mm column": ({"x": X}, {"position_unit": 1e-3}, {}),
    "load sensor clipping at 80 % of its peak": ({"x": X}, {"load_clip": 0.8}, {}),
    "2 % cross-talk from y's load, 90 deg": (
        {"x": dict(X, crosstalk=("y", 0.02)), "y": dict(X, phase=90)},
        {},
        {},
    ),
    "backlash 2 % of the amplitude, encoder on the motor": ({"x": dict(X, backlash=0.02 * 2.0)}, {}, {}),
    "k falls 5 % as a warm-up (tau 12 s)": ({"x": dict(X, drift=-0.05, drift_tau=WARMUP_TAU)}, {}, {}),
    "2 kHz on a 1 ms clock": ({"x": X}, {"rate": 2000.0, "time_resolution": 1e-3}, {}),
}
#: k at mid-run where k is not constant (s -> N/mm, from the log's duration)
MID_K = {
    "k falls 5 % as a warm-up (tau 12 s)": lambda T: X["k"] * (1 - 0.05 * (1 - np.exp(-T / 2 / WARMUP_TAU))),
}


def _said(res) -> str:
    if not res.ok:
        reason = next(iter(res.failures.values()))
        if "likely" in reason:  # a unit error: the unit it names
            return "failed: a unit error, " + reason[reason.index("likely") :].split(" (")[0]
        return "failed, naming the low-pass" if "low-pass" in reason else "failed: " + reason[:60]
    fit = res.axes["x"]
    parts = []
    if fit.departure is not None:
        parts.append(fit.departure["name"])
    if fit.load_lowpass is not None:
        parts.append(f"low-pass ~{fit.load_lowpass['filter']}")
    if res.notes:
        parts.append("note: " + res.notes[0][:40])
    return " + ".join(parts) or ("other warning" if res.warnings else "no warning")


def run_case(name: str, seeds: int, duration: float, rate: float) -> None:
    axes, log_kw, fit_kw = CASES[name]
    k_err, c_err, k_se, c_se, said, linear, texts = [], [], [], [], Counter(), [], []
    sizes = []
    k_true = MID_K.get(name, lambda T: X["k"])(duration)
    log_kw = {"rate": rate} | log_kw
    start = time.perf_counter()
    for seed in range(seeds):
        res = identify(make_log(axes, duration=duration, seed=1000 + seed, **log_kw), **fit_kw)[0]
        said[_said(res)] += 1
        if res.ok:
            fit = res.axes["x"]
            k_err.append(fit.k - k_true)
            c_err.append(fit.c - X["c"])
            k_se.append(fit.k_se)
            c_se.append(fit.c_se)
            if fit.departure is not None:
                linear.append(
                    (fit.departure["linear_k"] / X["k"] - 1, fit.departure["linear_c"] / X["c"] - 1)
                )
                texts.append(fit.departure["text"])
                sizes.append(fit.departure["value"])
    k_err, c_err, k_se, c_se = map(np.array, (k_err, c_err, k_se, c_se))
    rate = log_kw["rate"]
    print(f"\n{name} ({seeds} seeds, {duration:g} s at {rate:g} Hz, {time.perf_counter() - start:.0f} s)")
    print("  said: " + ", ".join(f"{what} {n}" for what, n in said.most_common()))
    if linear:
        lk, lc = np.median(np.array(linear), axis=0)
        print(f"  the linear fit: k {100 * lk:+.3g} %, c {100 * lc:+.3g} % (medians); first: {texts[0]}")
        print(
            f"  the departure's coefficient: median {np.median(sizes):.4g}, "
            f"{min(sizes):.4g} to {max(sizes):.4g}"
        )
    if k_err.size:
        for q, err, se, truth in (("k", k_err, k_se, k_true), ("c", c_err, c_se, X["c"])):
            cover = np.mean(np.abs(err) <= 2 * se)
            spread = np.sqrt(np.mean(err**2)) / np.mean(se)
            print(
                f"  {q}: median |error| {100 * np.median(np.abs(err)) / truth:.3g} %, worst "
                f"{100 * np.max(np.abs(err)) / truth:.3g} %, within 2 SE {100 * cover:.0f} %, "
                f"RMS error / mean SE {spread:.2f}"
            )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--duration", type=float, default=60.0)
    parser.add_argument("--rate", type=float, default=1000.0)
    parser.add_argument("--case", action="append", choices=list(CASES), help="default: every case")
    args = parser.parse_args()
    for name in args.case or list(CASES):
        run_case(name, args.seeds, args.duration, args.rate)


if __name__ == "__main__":
    main()
