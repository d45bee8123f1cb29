"""Identify a 2200 s, 1 kHz, six-axis virtual-rig log in CSV and Parquet.

Prints the time to read, validate and identify as a ratio to pandas reading the same file alone
(measured in the same run; aim <= 2x), the peak memory, and the identification error.
"""

import argparse
import resource
import tempfile
import time
import tracemalloc
from pathlib import Path

import pandas as pd

from designer.rig.identify import identify
from designer.rig.logs import write_log
from designer.rig.simulate import simulate

AXES = ("x", "y", "z", "theta", "phi", "psi")
COEF = {
    a: {"m": 0.001 if a in "xyz" else 1e-7, "c": 2e-3 * (i + 1), "k": 0.3 * (i + 1)}
    for i, a in enumerate(AXES)
}


def _best(fn, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--duration", type=float, default=2200.0)
    ap.add_argument("--repeat", type=int, default=2)
    args = ap.parse_args()
    df = simulate(COEF, duration=args.duration, noise=0.01, dropouts=0.001, seed=1)
    print(f"log: {len(df)} rows x {df.shape[1]} columns ({args.duration:g} s at 1 kHz, six axes)")
    with tempfile.TemporaryDirectory() as tmp:
        for suffix, reader in ((".csv", pd.read_csv), (".parquet", pd.read_parquet)):
            path = write_log(df, Path(tmp) / f"log{suffix}")
            identify(path), reader(path)  # warm up: imports are not part of the comparison
            base = _best(lambda p=path, r=reader: r(p), args.repeat)
            ours = _best(lambda p=path: identify(p), args.repeat)
            tracemalloc.start()
            res = identify(path)
            peak = tracemalloc.get_traced_memory()[1]
            tracemalloc.stop()
            err = max(
                max(abs(res.axes[a].k / COEF[a]["k"] - 1), abs(res.axes[a].c / COEF[a]["c"] - 1))
                for a in AXES
            )
            print(
                f"{suffix[1:]:8s} pandas read {base:6.2f} s | read+validate+identify {ours:6.2f} s | "
                f"ratio {ours / base:5.2f}x | peak traced memory {peak / 2**20:6.0f} MiB "
                f"(file {path.stat().st_size / 2**20:.0f} MiB) | worst k/c error {100 * err:.3f} %"
            )
    print(f"process max RSS {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**10:.0f} MiB")


if __name__ == "__main__":
    main()
