"""Identify a 2200 s, 1 kHz, six-axis rig log (CSV and Parquet) against pandas only reading it.

Each measurement is a separate Python process, timed from outside (wall time, start-up and imports
included) and asked for its own peak RSS (getrusage of the process, which counts pyarrow's memory
pool, unlike tracemalloc). The two contenders alternate, round after round, so drifts of a shared
machine hit both alike. Aim: identify <= 2x pandas' wall time and <= 1.5x its peak RSS.

    python benchmarks/bench_identify.py [--duration 2200] [--rounds 3]
"""

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from designer.rig.logs import write_log
from designer.rig.simulate import simulate

AXES = ("x", "y", "z", "theta", "phi", "psi")
COEF = {
    a: {"m": 0.001 if a in "xyz" else 1e-7, "c": 2e-3 * (i + 1), "k": 0.3 * (i + 1)}
    for i, a in enumerate(AXES)
}
_REPORT = (
    "import json, resource; print(json.dumps({'rss_kib': resource.getrusage(resource.RUSAGE_SELF).ru_maxrss"
)
PANDAS = {
    ".csv": "import sys, pandas as pd; pd.read_csv(sys.argv[1])\n" + _REPORT + "}))",
    ".parquet": "import sys, pandas as pd; pd.read_parquet(sys.argv[1])\n" + _REPORT + "}))",
}
IDENTIFY = (
    "import sys, json\n"
    "from designer.rig.identify import identify\n"
    "res = identify([sys.argv[1]])[0]\n"
    "coef = json.loads(sys.argv[2])\n"
    "err = max(max(abs(f.k / coef[a]['k'] - 1), abs(f.c / coef[a]['c'] - 1)) for a, f in res.axes.items())\n"
    + _REPORT
    + ", 'ok': res.ok, 'axes': len(res.axes), 'worst_error': err}))"
)


def _run(code: str, *args: str) -> tuple[float, dict]:
    """Wall time of a fresh `python -c code args` and the JSON it prints last."""
    t0 = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True, check=True)
    wall = time.perf_counter() - t0
    return wall, json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--duration", type=float, default=2200.0)
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args()
    df = simulate(COEF, duration=args.duration, noise=0.01, dropouts=0.001, seed=1)
    print(f"log: {len(df)} rows x {df.shape[1]} columns ({args.duration:g} s at 1 kHz, six axes)")
    with tempfile.TemporaryDirectory() as tmp:
        paths = [write_log(df, Path(tmp) / f"log{suffix}") for suffix in (".csv", ".parquet")]
        del df
        for path in paths:
            base, ours, info = [], [], {}
            for _ in range(args.rounds):
                base.append(_run(PANDAS[path.suffix], str(path)))
                wall, info = _run(IDENTIFY, str(path), json.dumps(COEF))
                ours.append((wall, info))
            bw, ow = (statistics.median(w for w, _ in runs) for runs in (base, ours))
            br, orss = (statistics.median(d["rss_kib"] for _, d in runs) / 1024 for runs in (base, ours))
            print(
                f"{path.suffix[1:]:8s} ({path.stat().st_size / 2**20:.0f} MiB) pandas read {bw:6.2f} s "
                f"{br:5.0f} MiB | identify {ow:6.2f} s {orss:5.0f} MiB | wall {ow / bw:4.2f}x, "
                f"peak RSS {orss / br:4.2f}x | ok {info['ok']}, {info['axes']} axes, "
                f"worst k/c error {100 * info['worst_error']:.3f} % (medians of {args.rounds} rounds)"
            )


if __name__ == "__main__":
    main()
