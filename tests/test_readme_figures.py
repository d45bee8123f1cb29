"""README's table of where users wait is the last run of benchmarks/bench_waits.py, verbatim: the
lines between its markers are what the script makes of benchmarks/results/waits.json, so a figure
in README cannot drift from a measured one (rerun the script with --readme to refresh both)."""

import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
import bench_waits  # noqa: E402

ROWS = {"identify_csv", "identify_parquet", "next", "calibrate", "next_surrogate", "suggest", "sweep"}


def test_readme_quotes_the_last_benchmark_run():
    result = json.loads(bench_waits.RESULTS.read_text())
    text = (ROOT / "README.md").read_text()
    quoted = text[text.index(bench_waits.BEGIN) + len(bench_waits.BEGIN) : text.index(bench_waits.END)]
    assert quoted.strip().splitlines() == bench_waits.table_lines(result)


def test_the_run_covers_every_row_with_its_rounds_and_load():
    result = json.loads(bench_waits.RESULTS.read_text())
    assert set(result["rows"]) == ROWS
    assert result["rounds"] >= 5 and result["duration_s"] == 2200
    for key, row in result["rows"].items():
        assert len(row["rounds"]) == result["rounds"], key
        assert all("load" in r for r in row["rounds"]), key
        if "goal_wall" in row:  # the verdict is the median's, as printed
            assert row["holds_wall"] == (row["median"]["ratio"] <= row["goal_wall"]), key


def test_the_readme_rewrite_replaces_only_the_table(tmp_path):
    readme = tmp_path / "README.md"
    readme.write_text(f"before\n{bench_waits.BEGIN}\nSTALE TABLE\n{bench_waits.END}\nafter\n")
    result = json.loads(bench_waits.RESULTS.read_text())
    bench_waits.write_readme(result, readme)
    text = readme.read_text()
    assert text.startswith(f"before\n{bench_waits.BEGIN}\n") and text.endswith(f"{bench_waits.END}\nafter\n")
    assert "STALE TABLE" not in text and "\n".join(bench_waits.table_lines(result)) in text
