"""The design loop's and suggest's outputs equal the stored ones (tests/data/loop_reference.json):
`designer next`, `calibrate` (3 runs), `next --surrogate` on the calibrated file and `suggest`,
their --json outputs with every number to 1e-12 relative and every string word for word. It guards
changes made for speed (issue 38), which must not change a print, a prediction or a P.

Regenerate only when a result is meant to change, and say why in the commit:
    python tests/test_loop_reference.py
"""

import json
import subprocess
import sys
import tempfile
from pathlib import Path

from stored_outputs import assert_same

import designer

REFERENCE = Path(__file__).parent / "data" / "loop_reference.json"
CLI = [sys.executable, "-c", "from designer_cli.main import main; main()"]
FACTORS = ["density", "length", "width", "height", "layer", "raster"]
COMMANDS = {
    "next": ["next", "--k", "0.8", "--json"],
    "calibrate": ["calibrate", "runs.csv", "-o", "mine.json", "--json"],
    "next --surrogate": ["next", "--k", "0.8", "--surrogate", "mine.json", "--json"],
    "suggest": ["suggest", "--k", "0.8", "--c", "2e-3", "--json"],
}


def outputs(folder: Path) -> dict:
    """Each command's --json output, run in `folder` in order (calibrate writes what next reads)."""
    picked = designer.load_table().iloc[[0, 7, 20]][FACTORS + ["k_x", "c_x"]]
    picked.assign(k_x=picked["k_x"] * 1.2).to_csv(folder / "runs.csv", index=False)
    out = {}
    for name, args in COMMANDS.items():
        done = subprocess.run(CLI + args, cwd=folder, capture_output=True, text=True, check=True)
        out[name] = json.loads(done.stdout)
    return out


def test_the_loop_and_suggest_give_the_stored_outputs(tmp_path):
    want = json.loads(REFERENCE.read_text())
    got = outputs(tmp_path)
    assert sorted(got) == sorted(want) == sorted(COMMANDS)
    for name in COMMANDS:
        assert_same(got[name], want[name], name)


if __name__ == "__main__":
    with tempfile.TemporaryDirectory() as tmp:
        REFERENCE.write_text(json.dumps(outputs(Path(tmp)), indent=1) + "\n")
    print(f"wrote {REFERENCE}")
