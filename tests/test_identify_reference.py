"""identify's results on fixed logs equal the stored ones (tests/data/identify_reference.json): k, c,
their standard errors, every other number to 1e-12 relative, and the warnings, failures and notes
word for word. It guards changes made for speed (the reader, the regression's algebra), which must
not change a result.

The logs come from tests/physics_logs.py (written from the physics, importing nothing from designer)
and from designer's virtual rig, each read from a CSV file and a Parquet file as a user gives them:
CSV written by pandas (shortest round-trip floats) and by a logger printing 7 significant digits.

Regenerate only when a result is meant to change, and say why in the commit:
    python tests/test_identify_reference.py
"""

import json
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))
from physics_logs import make_log  # noqa: E402
from stored_outputs import assert_same  # noqa: E402

from designer.rig.identify import identify  # noqa: E402
from designer.rig.simulate import simulate  # noqa: E402

REFERENCE = Path(__file__).parent / "data" / "identify_reference.json"
X = {"k": 0.8, "c": 2e-3, "m": 1e-3, "amplitude": 2.0}
SIX = {
    a: {"m": 1e-3 if a in "xyz" else 1e-7, "c": 2e-3 * (i + 1), "k": 0.3 * (i + 1)}
    for i, a in enumerate("xyz")
}
SIX |= {
    a: {"m": 1e-7, "c": 2e-3 * (i + 4), "k": 0.3 * (i + 4)} for i, a in enumerate(("theta", "phi", "psi"))
}
#: name: (the log, how it is written: "csv" pandas' repr, "csv7" 7 significant digits, "parquet")
CASES = {
    "clean": lambda: make_log({"x": X}, duration=60, rate=1000, seed=3),
    "1 % NaN glitches": lambda: make_log({"x": X}, duration=60, rate=1000, glitches=0.01, seed=4),
    "skew 2 ms, dropouts, offsets": lambda: make_log(
        {"x": X}, duration=60, rate=1000, skew_s=0.002, dropouts=0.002, offsets=True, seed=5
    ),
    "butter2 100 Hz, unknown": lambda: make_log(
        {"x": X}, duration=60, rate=1000, load_filter=(2, 100.0), seed=6
    ),
    "softening spring": lambda: make_log({"x": dict(X, k3=-0.2 * 0.8 / 4)}, duration=60, rate=1000, seed=7),
    "viscoelastic": lambda: make_log({"x": dict(X, maxwell=(0.04, 0.16))}, duration=60, rate=1000, seed=8),
    "2 kHz on a 1 ms clock": lambda: make_log({"x": X}, duration=30, rate=2000, time_resolution=1e-3, seed=9),
    "six axes, virtual rig": lambda: simulate(SIX, duration=120, noise=0.01, dropouts=0.001, seed=1),
}
FORMATS = ("csv", "csv7", "parquet")


def _write(df, path: Path, fmt: str) -> None:
    if fmt == "parquet":
        df.to_parquet(path, index=False)
    else:
        df.to_csv(path, index=False, float_format="%.7g" if fmt == "csv7" else None)


def outcomes(tmp: Path) -> dict:
    """identify's to_dict() (without the path) for every case and format."""
    out = {}
    for name, make in CASES.items():
        df = make()
        for fmt in FORMATS:
            path = tmp / f"{len(out)}.{'parquet' if fmt == 'parquet' else 'csv'}"
            _write(df, path, fmt)
            result = identify([path])[0].to_dict()
            result.pop("path")
            out[f"{name} [{fmt}]"] = json.loads(json.dumps(result, default=float))
    return out


@pytest.fixture(scope="module")
def current(tmp_path_factory):
    return outcomes(tmp_path_factory.mktemp("logs"))


def test_the_cases_cover_fits_warnings_and_notes():
    want = json.loads(REFERENCE.read_text())
    assert len(want) == len(CASES) * len(FORMATS)
    assert any(r["warnings"] for r in want.values())
    assert any(r["notes"] for r in want.values())
    assert all(r["ok"] for r in want.values())
    assert {len(r["axes"]) for r in want.values()} == {1, 6}


@pytest.mark.parametrize("case", [f"{n} [{f}]" for n in CASES for f in FORMATS])
def test_identify_gives_the_stored_results(current, case):
    want = json.loads(REFERENCE.read_text())[case]
    assert_same(current[case], want, case)
    for a, fit in want["axes"].items():  # the headline numbers, bit for bit where no reordering happened
        for key in ("k", "c", "k_se", "c_se"):
            if key in fit:
                assert np.isclose(current[case]["axes"][a][key], fit[key], rtol=1e-12, atol=0), (case, a, key)


if __name__ == "__main__":
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        REFERENCE.write_text(json.dumps(outcomes(Path(tmp)), indent=1, sort_keys=True) + "\n")
    print(f"wrote {REFERENCE}")
