"""The in-engine sweep path's table equals the stored one (tests/data/sweep_engine_reference.json) to
1e-12: it guards changes made for speed (issue 38: no MuJoCo profiling clock, one model for all
cases), which must not change a result. The grid puts a diverging case between good ones, so a
case that follows a diverged one starts clean; the example arm's Monte Carlo draws cover two joints.

Regenerate only when a result is meant to change, and say why in the commit:
    python tests/test_sweep_reference.py
"""

import ctypes
import dataclasses
import json
import tempfile
from pathlib import Path

from stored_outputs import assert_same

from designer import cosim, sweep
from designer.cosim.kernel_build import mujoco_paths
from designer.sweep.executors import SerialExecutor
from designer.sweep.spec import Cases, Spec, with_duration

REFERENCE = Path(__file__).parent / "data" / "sweep_engine_reference.json"
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
GRID = '[sweep]\nduration = 0.5\n[cases]\ntype = "grid"\n[cases.joints.j1]\nk = [300, 1e8, 500]\n'
GRID += "c = [6.0, 21.2]\n"


def _specs(tmp: Path) -> dict[str, Spec]:
    (tmp / "grid.toml").write_text(f'scenario = "{EXAMPLES / "tune_one_link.toml"}"\n' + GRID)
    arm = with_duration(cosim.load(EXAMPLES / "two_link_arm.toml"), 1.0)
    draws = Cases(type="montecarlo", joints={"j1": None, "j2": None}, n=12, seed=11)
    return {
        "one link grid": dataclasses.replace(sweep.load(tmp / "grid.toml"), path="engine", check=0),
        "two-link arm, 12 draws": Spec(scenario=arm, cases=draws, path="engine", check=0),
    }


def tables(tmp: Path) -> dict[str, list[dict]]:
    out = {}
    for name, spec in _specs(tmp).items():
        table = sweep.run(spec, executor=SerialExecutor()).table.drop(columns=["wall_s"])
        # A case's key hashes the scenario's repr, which holds the checkout's absolute paths: it is a
        # cache key for this machine, not a result. Stored: that the keys are distinct.
        assert table["key"].is_unique, name
        table = table.drop(columns=["key"])
        records = table.to_dict(orient="records")
        out[name] = json.loads(
            json.dumps(records, default=lambda v: v.item() if hasattr(v, "item") else str(v))
        )
    return out


def test_engine_sweep_tables_equal_the_stored_ones_and_mujoco_keeps_its_clock(tmp_path):
    hook = ctypes.c_void_p.in_dll(ctypes.CDLL(str(mujoco_paths()[1])), "mjcb_time")
    before = hook.value
    want = json.loads(REFERENCE.read_text())
    got = tables(tmp_path)
    assert hook.value == before and before is not None
    assert sorted(got) == sorted(want)
    for name, rows in want.items():
        assert [r["status"] for r in rows] == [r["status"] for r in got[name]]
        assert {r["status"] for r in rows} == ({"ok", "failed"} if "grid" in name else {"ok"})
        assert_same(got[name], rows, name)


if __name__ == "__main__":
    with tempfile.TemporaryDirectory() as tmp:
        REFERENCE.write_text(json.dumps(tables(Path(tmp)), indent=1) + "\n")
    print(f"wrote {REFERENCE}")
