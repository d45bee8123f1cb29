"""Wall time of `designer suggest --k 0.8 --c 2e-3` as a ratio to `python -c "import casadi"`.

Both are timed as fresh processes, interleaved, in the same run (this machine is shared and noisy);
the median of each is reported. Aim: a ratio of 2 or less.

Usage: python benchmarks/bench_suggest.py [--repeat 7]
"""

from __future__ import annotations

import argparse
import shutil
import statistics
import subprocess
import sys
import time


def wall(cmd: list[str]) -> float:
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - t0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7)
    args = parser.parse_args()
    designer = shutil.which("designer")
    suggest = ([designer] if designer else [sys.executable, "-m", "designer_cli.main"]) + [
        "suggest",
        "--k",
        "0.8",
        "--c",
        "2e-3",
    ]
    baseline = [sys.executable, "-c", "import casadi"]
    wall(suggest), wall(baseline)  # warm the file cache
    t_suggest, t_base = [], []
    for _ in range(args.repeat):
        t_suggest.append(wall(suggest))
        t_base.append(wall(baseline))
    s, b = statistics.median(t_suggest), statistics.median(t_base)
    print(f"designer suggest --k 0.8 --c 2e-3: {s * 1e3:.0f} ms (median of {args.repeat})")
    print(f'python -c "import casadi":        {b * 1e3:.0f} ms (median of {args.repeat})')
    print(f"ratio: {s / b:.2f}x (aim <= 2x)")


if __name__ == "__main__":
    main()
