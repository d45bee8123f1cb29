"""The design loop against simulated printers: prints until a recommended joint lands on target.

Truth: `tests/printers.py` (independent of `designer`): smooth k and c over the six settings, each
printer's own factors in 0.6-1.5, 2.5 % print-to-print scatter. `--truth spline`: k is the spline
through the study's runs (the smoothest surface through them, calmer between the runs than any real
one); `--truth drawn` (default): each printer's log k adds its own draw of a smooth departure field,
about zero at the study's runs and, between them, as large as the study surrogate's nested
cross-validation says it errs there (`--scale` times that of a Gaussian process fitted to the study;
default printers.DEPARTURE_SCALE). `--truth extrusion|adhesion|infill|combined`: a drawn truth (the
study's physics, as rough between the runs as its cross-validation measures) through a printer
mechanism (width and height offsets, layer and raster dependent bonds, another infill's density law,
or all three; printers.MECHANISMS); with `--smooth`, the mechanism on the spline instead. Per
printer and target (targets log-spaced across the study's measured k; every third run also has a c
goal, every third holds raster at 0 deg), these policies, each counting prints until one lands within
+-10 % of every predictable target (k; c is not predictable from the factors):

- `loop`: calibrate to the runs so far (`designer.calibrate`), `designer.next_prints(n=1)`: print
  what it proposes (the recommendation, design #1; "print design #1" once its P >= 0.9, or the
  nearest design when the calibrated model finds the target out of reach); every print is measured,
  so the first print within the tolerance ends the run (as for the baseline);
- `one-shot`: the study surrogate's recommendation, printed once (hit or not);
- `augment`: `doe --augment` (3 prints near the target), refit on the study plus the user's runs,
  suggest, print the recommendation; repeated while it misses (`--augment N` printers; default 0);
- `baseline`: the textbook bar, written without `designer`'s model: a scikit-learn Gaussian process
  (Matern 5/2 + white noise) on the user's log k minus the shipped surrogate's log prediction, and
  expected improvement on |log k - log target| over the printable grid; it prints the grid design of
  largest expected improvement (the surrogate's nearest to the target first) until one lands.

Every round, the loop's recommendation is also printed hypothetically (its own random stream, not
added to the runs), so every stated P is checked, including the stop signal's ("print design #1").

Reported: median and 90th percentile of prints to a hit for reachable targets (a printable design
lands in truth), runs that never hit within --max-prints count as above it; the share of printers
one-shot hits; the calibration of the stated P (recommendations grouped by stated P in bins of
0.2, realised hit rate per bin) and of the stop signal; the loop against the baseline on the same
printers and targets (mean prints, wins, ties).

Usage: python benchmarks/bench_loop.py [--printers 20] [--targets 10] [--max-prints 10] [--quick]
       [--truth drawn|spline|extrusion|adhesion|infill|combined] [--scale S] [--json]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import printers as truth  # noqa: E402

import designer  # noqa: E402
from designer.study.doe import plan_next

TOLERANCE = 0.10
CANONICAL = {"k_x_N_per_mm": "k_x", "c_x_Ns_per_mm": "c_x"}


def _goals(i: int, k: float) -> tuple[dict, dict]:
    """Goals of run i: k always; every third a c goal (the study's mean c), every third raster held."""
    goals = {"k": k} | ({"c": 2.2e-3} if i % 3 == 1 else {})
    return goals, ({"raster": 0.0} if i % 3 == 2 else {})


def _lands(printer: truth.Printer, design: dict, rng, targets: dict) -> tuple[bool, pd.DataFrame]:
    run = printer.prints(pd.DataFrame([design]), rng)
    measured = {"k": run["k_x_N_per_mm"].iloc[0], "c": run["c_x_Ns_per_mm"].iloc[0]}
    return all(abs(measured[q] / v - 1) <= TOLERANCE for q, v in targets.items()), run


def _predictable(sug) -> dict:
    return {q: t.value for q, t in sug.targets.items() if sug.predictability[q]["predictable"]}


def loop(study, printer, goals, fixed, rng, max_prints, stated):
    """Prints until a printed recommendation lands; `stated` gets (P, hit, round, stop) of every round's
    recommendation, printed hypothetically from its own stream."""
    runs = pd.DataFrame()
    check = np.random.default_rng([printer.seed, int(1e4 * goals["k"]), 7])
    for count in range(1, max_prints + 1):
        surrogate = designer.calibrate(study, runs)
        nxt = designer.next_prints(surrogate, **goals, fixed=fixed, n=1, tolerance=TOLERANCE)
        rec, p_now, stop = nxt.recommendation, nxt.p_now, nxt.stop
        # no print proposed (stop, or the calibrated model finds the target out of reach): the
        # recommendation itself, the nearest design
        design = nxt.prints[0].params if nxt.prints else rec.params
        targets = {q: v for q, v in goals.items() if q == "k"}
        stated.append((p_now, _lands(printer, rec.params, check, targets)[0], count, stop))
        hit, run = _lands(printer, design, rng, targets)
        if hit:  # the user measures every print: one within the tolerance is a joint that meets it
            return count
        runs = pd.concat([runs, run], ignore_index=True)
    return max_prints + 1


def expected_improvement(mean: np.ndarray, sd: np.ndarray, best: float) -> np.ndarray:
    """E[max(best - |D|, 0)] for D ~ N(mean, sd^2): the expected improvement on the distance |D|
    (in closed form: the two linear pieces of best - |z| on [-best, 0] and [0, best])."""
    from scipy.stats import norm

    sd = np.maximum(sd, 1e-12)

    def piece(a: float, c: float, alpha: float, beta: float) -> np.ndarray:
        lo, hi = (a - mean) / sd, (c - mean) / sd
        return (alpha + beta * mean) * (norm.cdf(hi) - norm.cdf(lo)) - beta * sd * (
            norm.pdf(hi) - norm.pdf(lo)
        )

    return piece(0.0, best, best, -1.0) + piece(-best, 0.0, best, 1.0)


def coded_grid(grid: pd.DataFrame) -> np.ndarray:
    """The benchmark's own coding of a grid: continuous factors over their ranges, levels over theirs."""
    cols = [(grid[n] - (lo + hi) / 2) / ((hi - lo) / 2) for n, (lo, hi) in truth.RANGES.items()]
    cols += [(grid[n] - np.mean(v)) / ((max(v) - min(v)) / 2) for n, v in truth.LEVELS.items()]
    return np.column_stack(cols)


def baseline(study, printer, goals, fixed, rng, max_prints, cache):
    """The textbook bar (module docstring): a GP on log k's departure from the surrogate, EI on |log k -
    log target| over the printable grid."""
    from sklearn.gaussian_process import GaussianProcessRegressor
    from sklearn.gaussian_process.kernels import ConstantKernel, Matern, WhiteKernel

    key = tuple(sorted(fixed.items()))
    if key not in cache:
        grid = truth.grid(fixed)
        mu0 = np.log(study.predict(grid, allow_extrapolation=True)["k_x"].value)
        cache[key] = (grid, coded_grid(grid), mu0)
    grid, Z, mu0 = cache[key]
    target = np.log(goals["k"])
    printed, measured = [], []
    for count in range(1, max_prints + 1):
        if not printed:
            i = int(np.argmin(np.abs(mu0 - target)))
        else:
            kernel = ConstantKernel(0.1, (1e-3, 10.0)) * Matern(1.0, (0.1, 10.0), nu=2.5)
            kernel += WhiteKernel(1e-3, (1e-6, 1e-1))
            gp = GaussianProcessRegressor(kernel, n_restarts_optimizer=2, random_state=0)
            gp.fit(Z[printed], np.array(measured) - mu0[printed])
            mean, sd = gp.predict(Z, return_std=True)
            best = float(np.min(np.abs(np.array(measured) - target)))
            i = int(np.argmax(expected_improvement(mu0 + mean - target, sd, best)))
        hit, run = _lands(printer, grid.iloc[i].to_dict(), rng, {"k": goals["k"]})
        if hit:
            return count
        printed.append(i)
        measured.append(float(np.log(run["k_x_N_per_mm"].iloc[0])))
    return max_prints + 1


def one_shot(study, printer, goals, fixed, rng, cache, stated):
    key = (tuple(sorted(goals.items())), tuple(sorted(fixed.items())))
    if key not in cache:
        cache[key] = designer.suggest(study, **goals, fixed=fixed, top=1, tolerance=TOLERANCE).candidates[0]
    rec = cache[key]
    hit, _ = _lands(printer, rec.params, rng, {"k": goals["k"]})
    stated.append((rec.p_within, hit, 1, False))
    return hit


def augment(study, table, printer, goals, fixed, rng, max_prints):
    runs, count, surrogate = pd.DataFrame(), 0, study
    while count < max_prints:
        try:
            plan, _ = plan_next(surrogate, n=3, targets={"k": goals["k"]})
        except designer.DesignerError:  # the refitted model no longer reaches the target
            return max_prints + 1
        designs = plan[list(truth.FACTORS)].to_dict("records")
        printed = printer.prints(pd.DataFrame(designs), rng)
        runs = pd.concat([runs, printed], ignore_index=True)
        count += len(designs)
        mine = runs.rename(columns={v: k for k, v in truth.COLUMNS.items()} | CANONICAL)
        both = pd.concat([table[list(truth.FACTORS) + ["k_x", "c_x"]], mine], ignore_index=True)
        surrogate = designer.Surrogate().fit(both, nested=False)
        rec = designer.suggest(surrogate, **goals, fixed=fixed, top=1, tolerance=TOLERANCE).candidates[0]
        count += 1
        hit, run = _lands(printer, rec.params, rng, {"k": goals["k"]})
        if hit:
            return count
        runs = pd.concat([runs, run], ignore_index=True)
    return max_prints + 1


def calibration_table(stated) -> list[dict]:
    """Recommendations grouped by stated P (bins of 0.2): count, mean stated P, realised hit rate."""
    rows = []
    for lo in np.arange(0.0, 1.0, 0.2):
        top = lo + 0.2 + (1e-9 if lo >= 0.8 else 0.0)
        inside = [(p, hit) for p, hit, *_ in stated if p is not None and lo <= p < top]
        if inside:
            rows.append(
                {
                    "stated": f"{lo:.1f}-{lo + 0.2:.1f}",
                    "n": len(inside),
                    "mean_stated": float(np.mean([p for p, _ in inside])),
                    "realised": float(np.mean([hit for _, hit in inside])),
                }
            )
    return rows


def summary(prints: list[int], max_prints: int) -> dict:
    a = np.array(prints, dtype=float)
    return {
        "runs": len(a),
        "prints": [int(x) for x in a],  # per run, in the order printers x targets (the baseline's too)
        "median": float(np.median(a)),
        "p90": float(np.percentile(a, 90, method="higher")),
        "never": int(np.sum(a > max_prints)),
    }


def stop_signal(stated) -> dict:
    """The stop signal's claims ("print design #1", P >= the stop level) and how often they landed."""
    claims = [(p, hit) for p, hit, _, stop in stated if stop]
    return {
        "n": len(claims),
        "mean_stated": float(np.mean([p for p, _ in claims])) if claims else None,
        "realised": float(np.mean([hit for _, hit in claims])) if claims else None,
    }


def paired(loop_prints: list[int], baseline_prints: list[int]) -> dict:
    a, b = np.array(loop_prints, dtype=float), np.array(baseline_prints, dtype=float)
    return {
        "loop_mean": float(a.mean()),
        "baseline_mean": float(b.mean()),
        "loop_wins": int(np.sum(a < b)),
        "baseline_wins": int(np.sum(a > b)),
        "ties": int(np.sum(a == b)),
    }


def make_printer(seed: int, kind: str, scale: float, smooth: bool) -> truth.Printer:
    if kind in truth.MECHANISMS:
        return truth.Printer(seed, mechanism=kind, drawn=not smooth, scale=scale)
    return truth.Printer(seed, drawn=kind == "drawn", scale=scale)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--printers", type=int, default=20)
    parser.add_argument("--targets", type=int, default=10)
    parser.add_argument("--max-prints", type=int, default=10)
    parser.add_argument("--augment", type=int, default=0, help="printers run through the augment baseline")
    parser.add_argument("--quick", action="store_true", help="3 printers x 3 targets (a smoke run)")
    parser.add_argument("--json", action="store_true")
    parser.add_argument("--seed", type=int, default=1000, help="seed of the first printer")
    parser.add_argument(
        "--truth",
        choices=("drawn", "spline", *truth.MECHANISMS),
        default="drawn",
        help="drawn: each printer's k departs from the spline between the study's runs; spline: it does "
        "not; a mechanism: the spline's physics through that printer mechanism",
    )
    parser.add_argument(
        "--scale",
        type=float,
        default=truth.DEPARTURE_SCALE,
        help="a drawn departure's size, relative to the process fitted to the study",
    )
    parser.add_argument(
        "--smooth", action="store_true", help="mechanism printers on the spline instead of a drawn truth"
    )
    args = parser.parse_args()
    if args.quick:
        args.printers, args.targets, args.augment = 3, 3, 0
    study = designer.Surrogate.load()
    table = designer.load_table()
    targets = np.geomspace(0.35, 1.3, args.targets)
    results = {"loop": [], "one_shot": [], "augment": [], "baseline": []}
    stated_loop, stated_one = [], []
    cache: dict = {}
    grids: dict = {}
    unreachable = 0
    t0 = time.perf_counter()
    for p in range(args.printers):
        printer = make_printer(args.seed + p, args.truth, args.scale, args.smooth)
        for i, k in enumerate(targets):
            goals, fixed = _goals(i, float(k))
            if not printer.best(k=k, fixed=fixed, tolerance=TOLERANCE)[1]:
                unreachable += 1
                continue
            rng = np.random.default_rng(10_000 * p + i)
            results["loop"].append(loop(study, printer, goals, fixed, rng, args.max_prints, stated_loop))
            results["one_shot"].append(one_shot(study, printer, goals, fixed, rng, cache, stated_one))
            rng = np.random.default_rng([10_000 * p + i, 2])
            results["baseline"].append(baseline(study, printer, goals, fixed, rng, args.max_prints, grids))
            if p < args.augment:
                results["augment"].append(augment(study, table, printer, goals, fixed, rng, args.max_prints))
    out = {
        "truth": args.truth,
        "scale": args.scale if args.truth == "drawn" or not args.smooth else None,
        "smooth": args.smooth,
        "printers": args.printers,
        "targets_per_printer": args.targets,
        "unreachable_skipped": unreachable,
        "loop": summary(results["loop"], args.max_prints),
        "baseline": summary(results["baseline"], args.max_prints),
        "paired": paired(results["loop"], results["baseline"]),
        "augment": summary(results["augment"], args.max_prints) if results["augment"] else None,
        "one_shot_hit_share": float(np.mean(results["one_shot"])),
        "stated_p_loop": calibration_table(stated_loop),
        "stop_signal": stop_signal(stated_loop),
        "stated_p_loop_first_print": calibration_table([s for s in stated_loop if s[2] == 1]),
        "stated_p_loop_later_prints": calibration_table([s for s in stated_loop if s[2] > 1]),
        "stated_p_one_shot": calibration_table(stated_one),
        "seconds": round(time.perf_counter() - t0, 1),
    }
    if args.json:
        print(json.dumps(out, indent=1))
        return
    runs = out["loop"]["runs"]
    seconds = out["seconds"]
    print(f"{args.truth} truth: {runs} reachable runs ({unreachable} unreachable skipped), {seconds} s")
    for name in ("loop", "baseline", "augment"):
        s = out[name]
        if s:
            print(
                f"{name:9s} prints to a hit: median {s['median']:g}, p90 {s['p90']:g} "
                f"(never within {args.max_prints}: {s['never']} of {s['runs']})"
            )
    pair = out["paired"]
    print(
        f"paired: loop {pair['loop_mean']:.2f} prints on average, baseline {pair['baseline_mean']:.2f}; "
        f"loop fewer {pair['loop_wins']}, baseline fewer {pair['baseline_wins']}, ties {pair['ties']}"
    )
    print(f"one-shot  hits in {100 * out['one_shot_hit_share']:.0f} % of runs")
    stop = out["stop_signal"]
    if stop["n"]:
        print(f"stop signal: stated {stop['mean_stated']:.2f}, landed {stop['realised']:.2f} (n={stop['n']})")
    for name in (
        "stated_p_loop",
        "stated_p_loop_first_print",
        "stated_p_loop_later_prints",
        "stated_p_one_shot",
    ):
        rows = [
            f"P {r['stated']} (mean {r['mean_stated']:.2f}): {r['realised']:.2f} (n={r['n']})"
            for r in out[name]
        ]
        print(f"{name}: " + "; ".join(rows))


if __name__ == "__main__":
    main()
