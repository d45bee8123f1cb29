"""How true the calibrated intervals are on simulated printers, without the loop's choices.

For each printer (tests/printers.py, `--truth drawn` or `spline`): print once or three times near a
random design, calibrate, and compare log k's calibrated prediction with the truth at designs around
it (standardized errors z = (log k_true - mu) / s: sd 1 and 95 % inside +-t95 when the intervals are
right). Then, as the loop does: print the study's recommendation for a target, calibrate, and take
z at the new recommendation and at designs near it that were not chosen (a larger sd at the chosen
ones than at their neighbours would be the cost of choosing the best of many).

Usage: python benchmarks/calibration_check.py [--truth drawn|spline] [--scale S] [--printers 30]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import printers as truth  # noqa: E402

import designer  # noqa: E402

FACTORS = list(truth.FACTORS)
HALF = {f: (hi - lo) / 2 for f, (lo, hi) in truth.RANGES.items()}


def _around(centre: dict, n: int, scale: float, rng) -> pd.DataFrame:
    """n designs scattered around `centre` (sd `scale` of each range's half-width), same levels."""
    moved = {f: np.clip(centre[f] + rng.normal(0, scale * HALF[f], n), *truth.RANGES[f]) for f in HALF}
    return pd.DataFrame(moved | {f: centre[f] for f in truth.LEVELS})[FACTORS]


def _z(model, printer, designs: pd.DataFrame) -> np.ndarray:
    mu, s = model.log_moments({f: designs[f].to_numpy() for f in FACTORS})
    return (np.log(printer.k(designs)) - mu) / s


def _line(name: str, z: list, t95: float) -> str:
    z = np.asarray(z)
    inside = np.mean(abs(z) < t95)
    return f"{name}: sd {z.std():.2f}, mean {z.mean():+.2f}, inside the 95 % interval {inside:.2f}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--truth", choices=("drawn", "spline"), default="drawn")
    parser.add_argument("--scale", type=float, default=truth.DEPARTURE_SCALE, help="a drawn departure's size")
    parser.add_argument("--printers", type=int, default=30)
    args = parser.parse_args()
    study = designer.Surrogate.load()
    t95 = study.model("k_x").t95
    rng = np.random.default_rng(5)
    around_runs: dict[int, list] = {1: [], 3: []}
    chosen, neighbours, first = [], [], {}
    for p in range(args.printers):
        printer = truth.Printer(3000 + p, drawn=args.truth == "drawn", scale=args.scale)
        centre = {f: rng.uniform(*truth.RANGES[f]) for f in truth.RANGES}
        centre |= {f: rng.choice(truth.LEVELS[f]) for f in truth.LEVELS}
        for n in (1, 3):
            model = designer.calibrate(study, printer.prints(_around(centre, n, 0.15, rng), rng)).model("k_x")
            around_runs[n].extend(_z(model, printer, _around(centre, 30, 0.3, rng)))
        for k in (0.45, 0.7, 1.0):
            if k not in first:
                first[k] = designer.suggest(study, k=k, top=1).candidates[0].params
            calibrated = designer.calibrate(study, printer.prints(pd.DataFrame([first[k]])[FACTORS], rng))
            rec = designer.suggest(calibrated, k=k, top=1).candidates[0].params
            model = calibrated.model("k_x")
            chosen.extend(_z(model, printer, pd.DataFrame([rec])[FACTORS]))
            neighbours.extend(_z(model, printer, _around(rec, 10, 0.1, rng)))
    size = f" (scale {args.scale:g})" if args.truth == "drawn" else ""
    print(f"{args.truth} truth{size}, {args.printers} printers, log k standardized errors")
    for n, z in around_runs.items():
        print(_line(f"  {n} print(s) near a random design, designs around it", z, t95))
    print(_line("  one print at the study's recommendation, at the new recommendation", chosen, t95))
    print(_line("  ... at designs near the new recommendation, not chosen", neighbours, t95))


if __name__ == "__main__":
    main()
