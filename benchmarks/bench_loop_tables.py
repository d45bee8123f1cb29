"""README's design-loop tables from `bench_loop.py --json` outputs, one file per printer kind.

Usage: python benchmarks/bench_loop_tables.py extrusion.json adhesion.json combined.json drawn.json ...
Prints two markdown tables: prints to a hit (the loop, the textbook baseline, paired) and how true the
stated P is (per bin of 0.2, mean stated / share landed (count); bins under 20 recommendations in
parentheses), with the stop signal's claims.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

BINS = ("0.0-0.2", "0.2-0.4", "0.4-0.6", "0.6-0.8", "0.8-1.0")
#: bins with fewer recommendations than this are shown but not judged
JUDGED = 20


def _prints(s: dict) -> str:
    never = f", {s['never']} of {s['runs']} not within 10" if s["never"] else f" ({s['runs']} runs)"
    return f"median {s['median']:g}, p90 {s['p90']:g}{never}"


def _cell(row: dict | None) -> str:
    if row is None:
        return "-"
    text = f"{row['mean_stated']:.2f} / {100 * row['realised']:.0f} % ({row['n']})"
    return text if row["n"] >= JUDGED else f"({text})"


def tables(results: list[dict]) -> str:
    names = [r["truth"] + (" (smooth)" if r.get("smooth") else "") for r in results]
    head = "| | " + " | ".join(names) + " |\n| --- |" + " --- |" * len(names)
    out = ["| prints to a hit within +-10 %" + head[1:]]
    out.append(
        "| the loop: `calibrate`, `next --n 1` | " + " | ".join(_prints(r["loop"]) for r in results) + " |"
    )
    out.append(
        "| baseline: GP + expected improvement | "
        + " | ".join(_prints(r["baseline"]) for r in results)
        + " |"
    )
    out.append(
        "| paired mean prints, loop / baseline (loop fewer, baseline fewer, ties) | "
        + " | ".join(
            f"{p['loop_mean']:.2f} / {p['baseline_mean']:.2f} "
            f"({p['loop_wins']}, {p['baseline_wins']}, {p['ties']})"
            for p in (r["paired"] for r in results)
        )
        + " |"
    )
    out.append(
        "| one-shot `suggest` on the study lands | "
        + " | ".join(f"{100 * r['one_shot_hit_share']:.0f} %" for r in results)
        + " |"
    )
    out.append("")
    out.append("| stated P: mean stated / landed (n)" + head[1:])
    for b in BINS:
        rows = [next((x for x in r["stated_p_loop"] if x["stated"] == b), None) for r in results]
        out.append(f"| {b} | " + " | ".join(_cell(x) for x in rows) + " |")
    stops = []
    for r in results:
        s = r["stop_signal"]
        stops.append(f"{s['mean_stated']:.2f} / {100 * s['realised']:.0f} % ({s['n']})" if s["n"] else "-")
    out.append('| stop signal ("print design #1") | ' + " | ".join(stops) + " |")
    return "\n".join(out)


def main() -> None:
    results = [json.loads(Path(p).read_text()) for p in sys.argv[1:]]
    print(tables(results))


if __name__ == "__main__":
    main()
