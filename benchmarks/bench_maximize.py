"""The profiler page's "maximize" against `designer suggest`: agreement on random goals and locks, and
the page's search time as a ratio to one `designer suggest` process (interleaved, same run).

Each case opens the page in headless Chromium, moves and locks 0-3 random factors, sets a random
goal on k_x (a target between 0.3 and 1.6 N/mm, or min, or max) through the page's controls and
presses maximize; then `designer suggest` runs with the same goal and `--fix`. A case agrees when the
designs are equal and P and D agree to 1e-9.

Usage: python benchmarks/bench_maximize.py [--cases 40] [--seed 11]
"""

from __future__ import annotations

import argparse
import json
import random
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
import cdp  # noqa: E402
from test_profile_browser import _design  # noqa: E402
from test_profile_console import _set_goal  # noqa: E402

from designer.study import space


def _case(page, rnd: random.Random) -> tuple[list[str], dict]:
    """Move and lock random factors, set a random goal, press maximize: suggest's arguments, status."""
    kind = rnd.choice(["target", "target", "target", "min", "max"])
    value = round(rnd.uniform(0.3, 1.6), 3) if kind == "target" else None
    names = rnd.sample([f.name for f in space.FACTORS], rnd.randint(0, 3))
    for n in names:
        f = space.BY_NAME[n]
        if f.categorical:
            page.click(f'button[data-factor="{n}"][data-level="{rnd.choice(f.levels):g}"]')
        else:
            page.click(f"#s-{n}", rnd.uniform(0.02, 0.98))
        page.click(f"#lock-{n}")
    _set_goal(page, "k_x", kind, value)
    held = {n: v for n, v in _design(page).items() if n in names}
    page.click("#maximize")
    status = page.js("Object.assign({}, document.getElementById('max-status').dataset)")
    args = ["--k", str(value) if kind == "target" else kind] + [f"--fix={n}={v!r}" for n, v in held.items()]
    return args, status


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=40)
    parser.add_argument("--seed", type=int, default=11)
    args = parser.parse_args()
    rnd = random.Random(args.seed)
    with tempfile.TemporaryDirectory() as tmp:
        html = Path(tmp) / "p.html"
        subprocess.run(["designer", "profile", "-o", str(html)], check=True, capture_output=True)
        agree, page_ms, suggest_ms = 0, [], []
        with cdp.Browser(cdp.find_browser(), width=1280, height=800) as browser:
            for _ in range(args.cases):
                page = browser.new_page()
                page.goto(html.as_uri())
                cli, status = _case(page, rnd)
                page.call("Page.close")
                t0 = time.perf_counter()
                run = subprocess.run(["designer", "suggest", *cli, "--json"], capture_output=True, text=True)
                suggest_ms.append(1e3 * (time.perf_counter() - t0))
                page_ms.append(float(status["ms"]))
                want = json.loads(run.stdout)["candidates"][0]
                got = json.loads(status["design"])
                same = all(abs(got[k] - want["params"][k]) < 1e-9 for k in got)
                dp = abs(float(status["p"]) - want["p_within"]) if status["p"] else 0.0
                dd = abs(float(status["d"]) - want["desirability"])
                agree += same and dp < 1e-9 and dd < 1e-9
                if not (same and dp < 1e-9):
                    print(f"differs: suggest {' '.join(cli)}: page {got}, P {status['p']}; "
                          f"suggest {want['params']}, P {want['p_within']}")  # fmt: skip
    print(f"{agree} of {args.cases} cases agree (design equal, P and D to 1e-9)")
    page, cli = statistics.median(page_ms), statistics.median(suggest_ms)
    print(
        f"median page maximize {page:.0f} ms, designer suggest process {cli:.0f} ms: ratio {page / cli:.3f}"
    )


if __name__ == "__main__":
    main()
