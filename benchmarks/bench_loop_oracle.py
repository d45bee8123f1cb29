"""How few prints any policy could need on the loop benchmark's printers: a policy that knows their prior.

`bench_loop.py` measures the design loop against simulated printers (`tests/printers.py`). Its goal,
90 % of runs within 3 prints, is only meaningful if the printers allow it: a print tells the next
print how the printer departs from the study only as far as the departure is smooth. This benchmark
answers that question without `designer`: its policy is the Bayes decision of a user who knows
exactly how the benchmark's printers are made (the study physics, its drawn departure field, the
mechanism's parameter ranges, the overall factor's range, the 2.5 % print scatter) and only not which
printer is theirs.

The oracle's belief is a sample of that prior: `--particles` printers of the kind (seeds apart from the
benchmark's), each evaluated on a dense printable grid. The overall factor (uniform in 0.6-1.5) is
integrated exactly on a fine grid of its own, so the particles only need to cover the rest (departure
field and mechanism). After each print the particles are weighted by the likelihood of every print
so far (log-normal scatter of the known size). Each round it prints the grid design of largest
posterior probability of landing within +-10 % of the target (as the loop prints its design #1);
the benchmark's printers, targets, goals and random streams are the loop's (`bench_loop.py`'s seeds),
so the prints to a hit pair run for run with `benchmarks/results/loop_KIND.json`.

The oracle is not an upper bound in the strict sense (it is myopic, its grid is coarser than the
loop's continuous search, its belief is a finite sample: the effective sample size is reported), but
it knows everything the benchmark's truth is drawn from, which no model fitted to the study can.
With `--belief` it pools several kinds' particles: it knows how each kind is made but not which kind
the printer is, as a user does not; its stated P is then Bayes-correct over the pooled kinds, and the
calibration per kind shows what one P can promise for every kind at once.

Usage: python benchmarks/bench_loop_oracle.py --truth extrusion|adhesion|combined|infill|drawn|spline
       [--belief KIND,KIND,...] [--printers 20] [--targets 10] [--particles 600] [--store DIR] [--json]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.special import logsumexp, ndtr

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import printers as truth  # noqa: E402
from bench_loop import TOLERANCE, _goals, calibration_table, make_printer, summary  # noqa: E402

#: grid values per continuous factor: width and height move k most
POINTS = {"density": 5, "length": 4, "width": 8, "height": 8}
#: the overall factor's grid (log space, uniform in the factor itself)
FACTOR_STEPS = 91
#: particles' seeds start here (the benchmark's printers are 1000 + p)
PARTICLE_SEED = 50_000


def oracle_grid() -> pd.DataFrame:
    axes = {n: np.linspace(*truth.RANGES[n], POINTS[n]) for n in truth.RANGES}
    axes |= {n: np.array(v) for n, v in truth.LEVELS.items()}
    mesh = np.meshgrid(*(axes[f] for f in truth.FACTORS), indexing="ij")
    return pd.DataFrame({f: m.ravel() for f, m in zip(truth.FACTORS, mesh, strict=True)})


def particle_logs(kind: str, n: int, grid: pd.DataFrame, scale: float, store: Path | None) -> np.ndarray:
    """(n, designs) log k of n prior printers of the kind at the grid, their overall factor removed
    (read from and written to `store`, a folder, when given: they take about a second each)."""
    path = store / f"particles_{kind}_{n}_{len(grid)}.npy" if store else None
    if path is not None and path.exists():
        return np.load(path)
    out = np.empty((n, len(grid)))
    for j in range(n):
        p = make_printer(PARTICLE_SEED + j, kind, scale, smooth=False)
        out[j] = np.log(p.k(grid)) - np.log(p.factor_k)
    if path is not None:
        store.mkdir(parents=True, exist_ok=True)
        np.save(path, out)
    return out


class Oracle:
    """The posterior over (particle, overall factor) and its probability of a hit at every grid design."""

    def __init__(self, logs: np.ndarray, noise: float):
        self.logs = logs
        self.noise = noise
        f = np.linspace(*truth.PRINTER_FACTORS, FACTOR_STEPS)
        self.b = np.log(f)  # uniform in the factor: equal prior weight per step of f

    def posterior(self, printed: list[int], measured: list[float]) -> tuple[np.ndarray, np.ndarray]:
        """Weights (particles, factor steps) given the prints so far, normalised; and the particles'
        effective sample size."""
        r = np.asarray(measured)[None, :] - self.logs[:, printed]  # (J, n)
        resid = r[:, :, None] - self.b[None, None, :]  # (J, n, B)
        logw = -0.5 * np.sum(resid**2, axis=1) / self.noise**2
        logw -= logsumexp(logw)
        w = np.exp(logw)
        per = w.sum(axis=1)
        return w, float(1.0 / np.sum(per**2))

    def p_hit(self, w: np.ndarray, target: float, candidates: np.ndarray) -> np.ndarray:
        """P(a print lands within the tolerance) at the candidate designs (indices), shape (m,).

        Each particle's factor posterior is moment-matched (its mean and variance on the factor grid,
        exact before the first print only in the limit of a flat prior, see `first_round`), so a
        particle's predictive log k is normal with the print scatter added."""
        lo, hi = np.log(1 - TOLERANCE), np.log(1 + TOLERANCE)
        per = w.sum(axis=1)
        keep = per > 1e-9
        wj = w[keep] / per[keep, None]
        mean = wj @ self.b
        var = wj @ self.b**2 - mean**2
        s = np.sqrt(var + self.noise**2)[:, None]
        d = self.logs[keep][:, candidates] + mean[:, None] - np.log(target)
        p = ndtr((hi - d) / s) - ndtr((lo - d) / s)
        return per[keep] @ p

    def first_round(self, target: float, candidates: np.ndarray) -> np.ndarray:
        """P(hit) before any print: the factor integrated on its grid exactly (its prior is flat in
        the factor, far from normal), in chunks of particles."""
        lo, hi = np.log(1 - TOLERANCE), np.log(1 + TOLERANCE)
        out = np.zeros(len(candidates))
        for j in range(len(self.logs)):
            d = self.logs[j, candidates][:, None] + self.b[None, :] - np.log(target)
            out += (ndtr((hi - d) / self.noise) - ndtr((lo - d) / self.noise)).mean(axis=1)
        return out / len(self.logs)


def run(oracle: Oracle, grid: pd.DataFrame, printer, target: float, fixed: dict, rng, max_prints: int, cache):
    """Prints to a hit, and the (stated P, effective sample size) of each round."""
    mask = np.ones(len(grid), dtype=bool)
    for name, value in fixed.items():
        mask &= np.isclose(grid[name].to_numpy(), value)
    candidates = np.flatnonzero(mask)
    printed, measured, rounds = [], [], []
    key = (target, tuple(sorted(fixed.items())))
    if key not in cache:  # the first print depends on the target and the held settings only
        cache[key] = oracle.first_round(target, candidates)
    ess, weights = float(len(oracle.logs)), None
    for count in range(1, max_prints + 1):
        p = oracle.p_hit(weights, target, candidates) if printed else cache[key]
        i = int(candidates[np.argmax(p)])
        rounds.append((float(p.max()), ess))
        design = grid.iloc[i].to_dict()
        row = printer.prints(pd.DataFrame([design]), rng)
        k = float(row["k_x_N_per_mm"].iloc[0])
        if abs(k / target - 1) <= TOLERANCE:
            return count, rounds
        printed.append(i)
        measured.append(np.log(k))
        weights, ess = oracle.posterior(printed, measured)
    return max_prints + 1, rounds


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--truth", choices=("drawn", "spline", *truth.MECHANISMS), default="drawn")
    parser.add_argument("--printers", type=int, default=20)
    parser.add_argument("--targets", type=int, default=10)
    parser.add_argument("--particles", type=int, default=600)
    parser.add_argument("--max-prints", type=int, default=10)
    parser.add_argument("--seed", type=int, default=1000, help="seed of the first printer")
    parser.add_argument(
        "--belief",
        help="kinds the oracle's prior pools, comma-separated, each with --particles (default: --truth "
        "alone; with several the oracle knows the kinds but not which is the printer's)",
    )
    parser.add_argument("--store", type=Path, help="a folder keeping the particles between runs")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    t0 = time.perf_counter()
    grid = oracle_grid()
    belief = (args.belief or args.truth).split(",")
    logs = np.vstack(
        [particle_logs(kind, args.particles, grid, truth.DEPARTURE_SCALE, args.store) for kind in belief]
    )
    oracle = Oracle(logs, truth.PRINT_NOISE)
    t_particles = time.perf_counter() - t0
    prints, stated, cache = [], [], {}
    for p in range(args.printers):
        printer = make_printer(args.seed + p, args.truth, truth.DEPARTURE_SCALE, smooth=False)
        for i, k in enumerate(np.geomspace(0.35, 1.3, args.targets)):
            _, fixed = _goals(i, float(k))
            if not printer.best(k=k, fixed=fixed, tolerance=TOLERANCE)[1]:
                continue
            rng = np.random.default_rng(10_000 * p + i)  # the loop's stream for this run
            count, rounds = run(oracle, grid, printer, float(k), fixed, rng, args.max_prints, cache)
            prints.append(count)
            stated += [(pr, ess, r + 1, r + 1 == count) for r, (pr, ess) in enumerate(rounds)]
    s = summary(prints, args.max_prints)
    cum = {n: float(np.mean(np.array(prints) <= n)) for n in (1, 2, 3, 4)}
    ess_by_round = {
        r: float(np.median([e for _, e, rr, _ in stated if rr == r]))
        for r in (1, 2, 3, 4)
        if any(rr == r for _, _, rr, _ in stated)
    }
    out = {
        "truth": args.truth,
        "belief": belief,
        "printers": args.printers,
        "particles": args.particles,
        "grid_designs": len(grid),
        "oracle": s,
        "within": cum,
        "median_ess_by_round": ess_by_round,
        "stated_p": calibration_table([(p, hit) for p, _, _, hit in stated]),
        "stated_p_later_prints": calibration_table([(p, hit) for p, _, r, hit in stated if r > 1]),
        # by round: a belief of few effective particles (late rounds) overstates its P
        "stated_p_by_round": {
            str(r): calibration_table([(p, hit) for p, _, rr, hit in stated if min(rr, 4) == r])
            for r in (1, 2, 3, 4)
        },
        "seconds_particles": round(t_particles, 1),
        "seconds": round(time.perf_counter() - t0, 1),
    }
    if args.json:
        print(json.dumps(out, indent=1))
        return
    print(
        f"{args.truth}: oracle median {s['median']:g}, p90 {s['p90']:g}, within 1/2/3/4 prints "
        + " / ".join(f"{100 * v:.1f} %" for v in cum.values())
        + f" ({s['runs']} runs; median effective particles by round {ess_by_round}; {out['seconds']} s)"
    )


if __name__ == "__main__":
    main()
