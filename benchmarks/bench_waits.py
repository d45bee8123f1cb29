"""Where users wait: every row of issue 38's table as a ratio against its anchor, in one interleaved run.

Each row times a command users wait for against an anchor measured the same way, as whole fresh
processes (start-up and imports included): wall time, CPU time (user + system, from wait4) and peak
RSS. Round after round every anchor runs right before its subject, so a change of load on the
shared machine hits both alike; the figures are medians over rounds of the per-round ratios, printed
beside the load average (1 min) seen at the start and end of the run.

| row | subject | anchor | goal |
| --- | --- | --- | --- |
| identify_csv | `designer identify LOG.csv` (2200 s, 6 axes, 1 kHz) | `pandas.read_csv` | wall 2x, RSS 1.2x |
| identify_parquet | `designer identify LOG.parquet` | `pandas.read_parquet(LOG.parquet)` | wall <= 2x |
| next | `designer next --k 0.8` | `import casadi` | wall <= 4x |
| calibrate | `designer calibrate runs.csv` (3 runs) | `import casadi` | wall <= 4x |
| next_surrogate | `designer next --k 0.8 --surrogate mine.json` | `import casadi` | wall <= 4x |
| suggest | `designer suggest --k 0.8 --c 2e-3` | `import casadi` | wall <= 2x |
| sweep | FMU sweep path, cases/s (benchmarks/bench_sweep.py) | bare `mujoco.rollout` | README quotes it |

The project's own modules are timed from their compiled bytecode, as users run them: `pip install`
compiles it (and Python writes it on a first run), but an editable install under
PYTHONDONTWRITEBYTECODE=1 would compile every module from source in every process (0.04-0.06 s of
a loop command's CPU), so the script compiles the `designer` and `designer_cli` packages first
(`compileall`, a no-op where the bytecode is up to date).

For the sweep row the ratio is the FMU path's rate over the bare rollout's (higher is faster), run
in one process per round as bench_sweep.py does. Writes the figures as JSON (`--json`), and with
`--readme` rewrites README's table of them (tests/test_readme_figures.py checks the two agree).

    python benchmarks/bench_waits.py [--rounds 5] [--duration 2200] [--rows next,suggest] \
        [--json benchmarks/results/waits.json] [--readme]
"""

from __future__ import annotations

import argparse
import compileall
import importlib.util
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

HERE = Path(__file__).resolve().parent
README = HERE.parent / "README.md"
RESULTS = HERE / "results" / "waits.json"
BEGIN, END = "<!-- bench_waits: begin -->", "<!-- bench_waits: end -->"
CLI = [
    sys.executable,
    "-c",
    "import sys; from designer_cli.main import main; sys.argv[0] = 'designer'; main()",
]
CASADI = [sys.executable, "-c", "import casadi"]
SWEEP = (
    "import json, sys; sys.path.insert(0, {here!r}); from bench_sweep import *\n"
    "n = int(sys.argv[1]); out = {{}}\n"
    "sweep_rate(spec_for('fmu', 4))\n"
    "out['fmu'] = sweep_rate(spec_for('fmu', n)); out['engine'] = sweep_rate(spec_for('engine', n))\n"
    "out['bare'] = bare_rollout_rate(spec_for('engine', n)); print(json.dumps(out))"
)


@dataclass
class Row:
    key: str
    work: str
    anchor_name: str
    subject: list[str]
    anchor: list[str]
    goal_wall: float | None = None
    goal_rss: float | None = None
    rounds: list[dict] = field(default_factory=list)


def run(cmd: list[str]) -> dict:
    """Wall and CPU seconds and peak RSS (MiB) of one fresh process (reaped by wait4, which gives
    that child's own usage), and its stdout."""
    with tempfile.TemporaryFile("w+") as out, tempfile.TemporaryFile("w+") as err:
        start = time.perf_counter()
        proc = subprocess.Popen(cmd, stdout=out, stderr=err, text=True)
        _, status, usage = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - start
        proc.returncode = os.waitstatus_to_exitcode(status)
        out.seek(0), err.seek(0)
        if proc.returncode != 0:
            raise SystemExit(f"{' '.join(cmd)}: exit {proc.returncode}\n{err.read()[-2000:]}")
        return {
            "wall": wall,
            "cpu": usage.ru_utime + usage.ru_stime,
            "rss": usage.ru_maxrss / 1024,
            "out": out.read(),
        }


def rows(tmp: Path, duration: float, sweep_cases: int) -> list[Row]:
    log = tmp / "log"
    runs = tmp / "runs.csv"
    mine = tmp / "mine.json"
    pandas_read = "import sys, pandas as pd; pd.read_{}(sys.argv[1])"
    return [
        Row(
            "identify_csv",
            f"`designer identify` {duration:g} s x 6 axes at 1 kHz, CSV",
            "`pandas.read_csv` of the file",
            [*CLI, "identify", f"{log}.csv"],
            [sys.executable, "-c", pandas_read.format("csv"), f"{log}.csv"],
            2.0,
            1.2,
        ),
        Row(
            "identify_parquet",
            "same, Parquet",
            "`pandas.read_parquet`",
            [*CLI, "identify", f"{log}.parquet"],
            [sys.executable, "-c", pandas_read.format("parquet"), f"{log}.parquet"],
            2.0,
        ),
        Row(
            "next",
            "`designer next --k 0.8` (shipped surrogate)",
            "`import casadi`",
            [*CLI, "next", "--k", "0.8"],
            CASADI,
            4.0,
        ),
        Row(
            "calibrate",
            "`designer calibrate` (3 runs)",
            "`import casadi`",
            [*CLI, "calibrate", str(runs), "-o", str(tmp / "c.json")],
            CASADI,
            4.0,
        ),
        Row(
            "next_surrogate",
            "`designer next --k 0.8 --surrogate mine.json` after `calibrate`",
            "`import casadi`",
            [*CLI, "next", "--k", "0.8", "--surrogate", str(mine)],
            CASADI,
            4.0,
        ),
        Row(
            "suggest",
            "`designer suggest --k 0.8 --c 2e-3`",
            "`import casadi`",
            [*CLI, "suggest", "--k", "0.8", "--c", "2e-3"],
            CASADI,
            2.0,
        ),
        Row(
            "sweep",
            f"`bench_sweep.py` FMU path ({sweep_cases} arm cases), cases/s",
            "bare `mujoco.rollout`",
            [sys.executable, "-c", SWEEP.format(here=str(HERE)), str(sweep_cases)],
            [],
        ),
    ]


def prepare(tmp: Path, duration: float) -> None:
    """The rig log in both formats (the virtual rig, as bench_identify.py), the runs table and
    the calibrated surrogate the rows read. Run in a child process (`--prepare`): a child forked
    from a large parent starts with the parent's resident pages in its peak RSS."""
    sys.path.insert(0, str(HERE))
    from bench_identify import COEF

    import designer
    from designer.rig.logs import write_log
    from designer.rig.simulate import simulate

    df = simulate(COEF, duration=duration, noise=0.01, dropouts=0.001, seed=1)
    for suffix in (".csv", ".parquet"):
        write_log(df, tmp / f"log{suffix}")
    del df
    table = designer.load_table()
    factors = ["density", "length", "width", "height", "layer", "raster"]
    picked = table.iloc[[0, 7, 20]][factors + ["k_x", "c_x"]]
    picked.assign(k_x=picked["k_x"] * 1.2).to_csv(tmp / "runs.csv", index=False)
    run([*CLI, "calibrate", str(tmp / "runs.csv"), "-o", str(tmp / "mine.json")])


def compile_bytecode() -> list[str]:
    """Compile the bytecode of the installed (or editable) `designer`, its surrogates and `designer_cli`
    where it is missing or stale, as `pip install` does; returns their folders."""
    folders = []
    for name in ("designer", "designer.surrogates", "designer_cli"):
        spec = importlib.util.find_spec(name)
        for folder in spec.submodule_search_locations if spec else []:
            if not compileall.compile_dir(folder, quiet=1):
                raise SystemExit(f"compileall failed in {folder}")
            folders.append(folder)
    return folders


def one_round(row: Row) -> dict:
    if row.key == "sweep":
        rates = json.loads(run(row.subject)["out"].strip().splitlines()[-1])
        return {
            "fmu": rates["fmu"],
            "engine": rates["engine"],
            "bare": rates["bare"],
            "ratio": rates["fmu"] / rates["bare"],
        }
    anchor, subject = run(row.anchor), run(row.subject)
    return {
        "anchor_wall": anchor["wall"],
        "subject_wall": subject["wall"],
        "anchor_cpu": anchor["cpu"],
        "subject_cpu": subject["cpu"],
        "anchor_rss": anchor["rss"],
        "subject_rss": subject["rss"],
        "ratio": subject["wall"] / anchor["wall"],
        "cpu_ratio": subject["cpu"] / anchor["cpu"],
        "rss_ratio": subject["rss"] / anchor["rss"],
    }


def summary(row: Row) -> dict:
    med = {k: statistics.median(r[k] for r in row.rounds) for k in row.rounds[0]}
    out = {"work": row.work, "anchor": row.anchor_name, "rounds": row.rounds, "median": med}
    if row.goal_wall is not None:
        out["goal_wall"], out["holds_wall"] = row.goal_wall, med["ratio"] <= row.goal_wall
    if row.goal_rss is not None:
        out["goal_rss"], out["holds_rss"] = row.goal_rss, med["rss_ratio"] <= row.goal_rss
    return out


def table_lines(result: dict) -> list[str]:
    """README's table of the figures: one line per row, the medians as the script prints them."""
    load = result["load"]
    lines = [
        f"`python benchmarks/bench_waits.py --rounds {result['rounds']}` on {result['date']}, load average "
        f"{load['start']:.2f} at the start and {load['end']:.2f} at the end (2 cores), medians of "
        f"{result['rounds']} interleaved rounds of whole processes:",
        "",
        "| work | anchor | wall ratio | CPU ratio | peak RSS ratio | subject wall, CPU | goal | holds |",
        "| --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for s in result["rows"].values():
        m = s["median"]
        if "fmu" in m:
            lines.append(
                f"| {s['work']} | {s['anchor']} | {m['ratio']:.2f} (FMU / bare rate) | - | - | "
                f"{m['fmu']:.0f} cases/s (in-engine {m['engine']:.0f}, bare {m['bare']:.0f}) | - | - |"
            )
            continue
        goals = [f"wall <= {s['goal_wall']:g}x"] + ([f"RSS <= {s['goal_rss']:g}x"] if "goal_rss" in s else [])
        holds = [s["holds_wall"]] + ([s["holds_rss"]] if "goal_rss" in s else [])
        lines.append(
            f"| {s['work']} | {s['anchor']} | {m['ratio']:.2f}x | {m['cpu_ratio']:.2f}x | "
            f"{m['rss_ratio']:.2f}x | {m['subject_wall']:.2f} s, {m['subject_cpu']:.2f} s | "
            f"{', '.join(goals)} | "
            f"{'yes' if all(holds) else 'no'} |"
        )
    return lines


def write_readme(result: dict, readme: Path = README) -> None:
    text = readme.read_text()
    start, end = text.index(BEGIN) + len(BEGIN), text.index(END)
    readme.write_text(text[:start] + "\n" + "\n".join(table_lines(result)) + "\n" + text[end:])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--duration", type=float, default=2200.0, help="the identify rows' log, s at 1 kHz")
    ap.add_argument("--sweep-cases", type=int, default=200)
    ap.add_argument("--rows", default="", help="comma-separated row keys (default: all)")
    ap.add_argument("--json", type=Path, default=RESULTS)
    ap.add_argument("--readme", action="store_true", help="rewrite README's table from this run")
    ap.add_argument("--prepare", type=Path, help=argparse.SUPPRESS)  # the child that writes the inputs
    args = ap.parse_args()
    if args.prepare:
        prepare(args.prepare, args.duration)
        return
    compile_bytecode()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        run([sys.executable, __file__, "--prepare", str(tmp), "--duration", str(args.duration)])
        chosen = [
            r
            for r in rows(tmp, args.duration, args.sweep_cases)
            if not args.rows or r.key in args.rows.split(",")
        ]
        start_load = os.getloadavg()[0]
        for i in range(args.rounds):
            for row in chosen:
                row.rounds.append(one_round(row) | {"load": os.getloadavg()[0]})
            print(f"round {i + 1}/{args.rounds} done, load average {os.getloadavg()[0]:.2f}", flush=True)
        end_load = os.getloadavg()[0]
    result = {
        "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
        "rounds": args.rounds,
        "duration_s": args.duration,
        "cpus": os.cpu_count(),
        "load": {"start": start_load, "end": end_load},
        "rows": {r.key: summary(r) for r in chosen},
    }
    print("\n".join(table_lines(result)))
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(json.dumps(result, indent=1) + "\n")
    print(f"wrote {args.json}")
    if args.readme:
        write_readme(result)
        print(f"rewrote the table in {README}")


if __name__ == "__main__":
    main()
