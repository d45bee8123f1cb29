"""The figures README's Install and first-hour sections state, measured: what the install and each
extra weigh on disk, that exports need no C compiler (only the co-simulation kernel does), and how
long the whole test suite takes.

    python scripts/measure_install.py                  # sizes and the compiler check: seconds, JSON
    python scripts/measure_install.py --suite          # also times .ci/run (fresh venv, install, suite)
    python scripts/measure_install.py --suite-log LOG  # or reads the time from a saved .ci/run output

Sizes are of the installed distributions in this environment (the files each one's RECORD lists):
the project's requirements and their requirements, followed through the installed metadata, for the
base install and each extra; an extra's figure is what it adds to the base. tests/test_readme_install.py
reruns the cheap part and compares it with README's text.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from importlib import metadata
from pathlib import Path

from packaging.requirements import Requirement
from packaging.utils import canonicalize_name

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[1]
EXTRAS = ("test", "cluster")
MB = 1e6


def _installed() -> dict[str, metadata.Distribution]:
    """Installed distributions by canonical name (the first found on sys.path wins, as import does)."""
    found: dict[str, metadata.Distribution] = {}
    for dist in metadata.distributions():
        found.setdefault(canonicalize_name(dist.metadata["Name"]), dist)
    return found


def _size(dist: metadata.Distribution) -> int:
    """Bytes of the files the distribution installed (its RECORD), those that exist."""
    total = 0
    for f in dist.files or []:
        path = Path(f.locate())
        if path.is_file():
            total += path.stat().st_size
    return total


def _closure(requirements: list[str], installed: dict) -> tuple[set[str], set[str]]:
    """(installed names, missing names) reached from `requirements` through installed metadata."""
    marker_env = {"extra": ""}
    todo = [r for r in map(Requirement, requirements) if r.marker is None or r.marker.evaluate(marker_env)]
    seen: set[str] = set()
    missing: set[str] = set()
    while todo:
        req = todo.pop()
        name = canonicalize_name(req.name)
        dist = installed.get(name)
        if dist is None:
            missing.add(name)
            continue
        new = [x for x in [name, *(f"{name}[{e}]" for e in sorted(req.extras))] if x not in seen]
        if not new:
            continue
        seen.update(new)
        for text in dist.requires or []:
            sub = Requirement(text)
            wanted = [""] + sorted(req.extras)
            if sub.marker is None or any(sub.marker.evaluate(marker_env | {"extra": e}) for e in wanted):
                todo.append(sub)
    return {s for s in seen if "[" not in s}, missing


def sizes() -> dict:
    """MB of the base install's closure, of what each extra adds, of all together, and the largest."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    installed = _installed()
    bytes_of = {name: _size(dist) for name, dist in installed.items()}
    base, missing = _closure(project["dependencies"], installed)
    out: dict = {"base_mb": sum(bytes_of[n] for n in base) / MB, "largest": {}, "missing": sorted(missing)}
    every = set(base)
    out["largest"]["base"] = _largest(base, bytes_of)
    for extra in EXTRAS:
        names, gone = _closure(project["optional-dependencies"][extra], installed)
        added = names - base
        every |= names
        out[f"{extra}_adds_mb"] = sum(bytes_of[n] for n in added) / MB
        out["largest"][extra] = _largest(added, bytes_of)
        out["missing"] = sorted(set(out["missing"]) | gone)
    out["all_mb"] = sum(bytes_of[n] for n in every) / MB
    return out


def _largest(names: set[str], bytes_of: dict[str, int], n: int = 4) -> dict[str, float]:
    return {k: round(bytes_of[k] / MB) for k in sorted(names, key=bytes_of.get, reverse=True)[:n]}


def compiler() -> dict:
    """Run an export and a co-simulation with no C compiler on PATH (and no $CC, an empty cache): the
    export must succeed by copying the shipped binaries, the co-simulation must fall back to the
    Python master."""
    cli = [sys.executable, "-I", "-c", "from designer_cli.main import main; main()"]
    with tempfile.TemporaryDirectory() as tmp:
        bare = Path(tmp) / "bin"
        bare.mkdir()
        env = {k: v for k, v in os.environ.items() if k not in ("CC", "PYTHONPATH")}
        env |= {"PATH": str(bare), "XDG_CACHE_HOME": str(Path(tmp) / "cache")}
        fmu = Path(tmp) / "joint.fmu"
        export = subprocess.run(
            [*cli, "export", "fmu", "--k", "300", "--c", "0.8", "--axis", "theta", "-o", fmu],
            cwd=tmp,
            env=env,
            capture_output=True,
            text=True,
        )
        scenario = Path(tmp) / "arm.toml"
        scenario.write_text(
            '[simulation]\nduration = 0.05\nstep = 1e-3\n[robot]\nmodel = "arm"\n'
            '[joints.j1]\nfmu = "joint.fmu"\nreference = { type = "step", amplitude = 0.1, at = 0.0 }\n'
            '[joints.j2]\nfmu = "joint.fmu"\nreference = { type = "step", amplitude = 0.1, at = 0.0 }\n'
        )
        cosim = subprocess.run(
            [*cli, "cosim", scenario, "-o", Path(tmp) / "out", "--json"],
            cwd=tmp,
            env=env,
            capture_output=True,
            text=True,
        )
        engine = json.loads(cosim.stdout).get("engine") if cosim.returncode == 0 else None
        return {
            "export_without_compiler": export.returncode == 0,
            "export_error": export.stderr.strip()[-300:],
            "cosim_without_compiler_engine": engine,
            "cosim_error": cosim.stderr.strip()[-300:],
        }


def suite_from_log(text: str) -> dict:
    """pytest's own summary line of a .ci/run output (or of `pytest -q`, which prints it without the
    rule of equals signs): the counts and the minutes the tests took."""
    m = re.findall(r"^(?:=+ )?(\d+ \w+.*?) in ([\d.]+)s(?: \([\d:]+\))?(?: =+)?$", text, re.MULTILINE)
    if not m:
        raise SystemExit("no pytest summary line ('... passed ... in N s') in the log")
    counts, seconds = m[-1]
    return {"tests_min": float(seconds) / 60, "summary": counts}


def suite() -> dict:
    """Time .ci/run end to end (a fresh venv, the install with the test extras, the whole suite)."""
    start = time.perf_counter()
    run = subprocess.run(["bash", str(ROOT / ".ci" / "run")], cwd=ROOT, capture_output=True, text=True)
    total = (time.perf_counter() - start) / 60
    out = suite_from_log(run.stdout + run.stderr)
    return out | {"with_install_min": total, "returncode": run.returncode, "cores": os.cpu_count()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--suite", action="store_true", help="also time .ci/run (about ten minutes)")
    parser.add_argument("--suite-log", type=Path, help="read the suite's time from a saved .ci/run output")
    args = parser.parse_args()
    result = {"sizes": sizes(), "compiler": compiler()}
    if args.suite:
        result["suite"] = suite()
    elif args.suite_log:
        result["suite"] = suite_from_log(args.suite_log.read_text())
    json.dump(result, sys.stdout, indent=1)
    print()


if __name__ == "__main__":
    main()
