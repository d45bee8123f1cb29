"""Shared by the CLI robustness tests: running the command in-process or as a real process, a folder
snapshot to prove nothing is left behind, and the malformed input files of the bad-input campaign."""

from __future__ import annotations

import contextlib
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd

CLI = [sys.executable, "-I", "-c", "from designer_cli.main import main; main()"]


def run_inprocess(args: list[str], capsys) -> tuple[int, str, str]:
    """The command line `args` run in this process: (exit code, stdout, stderr)."""
    from designer_cli.main import run

    capsys.readouterr()
    code = run([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def run_process(args: list[str], cwd: Path, **kwargs) -> subprocess.CompletedProcess:
    """The command line `args` as a real `python -I` process (the installed package)."""
    return subprocess.run([*CLI, *map(str, args)], cwd=cwd, capture_output=True, text=True, **kwargs)


@contextlib.contextmanager
def tmpfs(folder: Path, size: str):
    """A tmpfs of `size` (e.g. "2m") mounted on the new folder `folder` for the block; pytest.skip with
    the reason where mounting is not allowed (not root). Unmounted lazily: a process still writing
    there cannot make the unmount fail."""
    import pytest

    folder.mkdir()
    mount = ["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(folder)]
    r = subprocess.run(mount, capture_output=True)
    if r.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here (needs root): {r.stderr.decode().strip()}")
    try:
        yield folder
    finally:
        subprocess.run(["umount", "--lazy", str(folder)], check=True)


def enter_workdir(tmp_path: Path, inputs: Path, monkeypatch) -> Path:
    """`tmp_path` as the working folder, the campaign's inputs linked in as in/, a private build cache."""
    (tmp_path / "in").symlink_to(inputs, target_is_directory=True)
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path.parent / "cache"))
    return tmp_path


def snapshot(*folders: Path) -> dict[str, tuple[int, float]]:
    """Every file and folder (hidden ones too) under `folders`, with size and modification time."""
    seen = {}
    for folder in folders:
        for root, dirs, files in os.walk(folder, followlinks=False):
            for name in dirs + files:
                p = Path(root, name)
                st = p.lstat()
                # a folder's own time changes when a probe file comes and goes: only files' times count
                seen[str(p)] = (st.st_size, st.st_mtime_ns) if p.is_file() else (-1, 0)
    return seen


def assert_clean_failure(code: int, err: str, allowed=(1, 2)) -> None:
    """A failure: an expected non-zero code, no traceback, and for bad input one 'error:' line."""
    assert code in allowed, f"exit {code}: {err}"
    assert "Traceback" not in err and "internal error" not in err, err
    if code == 2:
        lines = [ln for ln in err.splitlines() if ln.strip()]
        assert len(lines) == 1 and lines[0].startswith("error: "), err


def bundled_table() -> pd.DataFrame:
    from designer.study.data import load_table

    return load_table()


def make_inputs(folder: Path) -> None:
    """Write the campaign's input files into `folder` (good ones and malformed ones)."""
    folder.mkdir(parents=True, exist_ok=True)
    good = bundled_table()
    good.to_csv(folder / "good.csv", index=False)
    tables = {
        "semicolon.csv": lambda: good.to_csv(folder / "semicolon.csv", sep=";", index=False),
        "tabs.csv": lambda: good.to_csv(folder / "tabs.csv", sep="\t", index=False),
        "binary.csv": lambda: (folder / "binary.csv").write_bytes(bytes(range(256)) * 4),
        "empty.csv": lambda: (folder / "empty.csv").write_bytes(b""),
        "header.csv": lambda: good.iloc[:0].to_csv(folder / "header.csv", index=False),
        "parquet.csv": lambda: good.to_parquet(folder / "parquet.csv"),
        "text.parquet": lambda: good.to_csv(folder / "text.parquet", index=False),
        "onerun.csv": lambda: good.iloc[:1].to_csv(folder / "onerun.csv", index=False),
    }
    for make in tables.values():
        make()
    k = next(c for c in good.columns if c.startswith("k_x"))
    variants = {
        "nan.csv": lambda t: t.assign(**{k: t[k].where(t.index != 3)}),
        "negk.csv": lambda t: t.assign(**{k: -t[k]}),
        "textcell.csv": lambda t: t.assign(width=t["width"].astype(object).where(t.index != 2, "wide")),
        "nocol.csv": lambda t: t.drop(columns=["height"]),
        "badunit.csv": lambda t: t.rename(columns={k: "k_x [N/m]"}),
        "levels.csv": lambda t: t.assign(layer=0.3),
        "density500.csv": lambda t: t.assign(density=t["density"].where(t.index != 5, 500)),
        "k1e308.csv": lambda t: t.assign(**{k: t[k].where(t.index != 4, 1e308)}),
        "subnormal.csv": lambda t: t.assign(**{k: t[k].where(t.index != 4, 5e-324)}),
    }
    for name, change in variants.items():
        change(good.copy()).to_csv(folder / name, index=False)
    text = (folder / "good.csv").read_text().splitlines()
    (folder / "dupcol.csv").write_text("\n".join([text[0] + f",{k}"] + [r + ",0.9" for r in text[1:]]) + "\n")
    _make_logs(folder)
    _make_suggestions(folder)
    _make_series(folder)
    (folder / "bad.toml").write_text("[simulation\nduration = ")
    # a step far too large for the arm: MuJoCo warns (printed, and MUJOCO_LOG.TXT by default) and resets
    (folder / "diverge.toml").write_text(
        '[simulation]\nduration = 1.0\nstep = 0.08\n[robot]\nmodel = "arm"\n[joints.j1]\naxis = "theta"\n'
        'coefficients = { k = 330, c = 0.83 }\nreference = { type = "step", amplitude = 0.3, at = 0.1 }\n'
    )
    (folder / "binary.toml").write_bytes(bytes(range(256)))
    arm = '[robot]\nmodel = "arm"\n[joints.j1]\naxis = "theta"\ncoefficients = { k = 330, c = 0.83 }\n'
    (folder / "typo.toml").write_text("[simulation]\nduraton = 5\nstep = 1e-3\n" + arm)
    (folder / "huge.toml").write_text("[simulation]\nduration = 1e9\nstep = 1e-3\n" + arm)
    (folder / "stifness.toml").write_text(arm.replace("coefficients", "stifness"))


#: a short co-simulation of the arm with one joint (0.1 s): for tests of outputs, not of results
ARM_SCENARIO = (
    '[simulation]\nduration = 0.1\nstep = 1e-3\n[robot]\nmodel = "arm"\n[joints.j1]\naxis = "theta"\n'
    'coefficients = { k = 330, c = 0.83 }\nreference = { type = "step", amplitude = 0.3, at = 0.05 }\n'
)
FACTORS = {"density": 60, "length": 24, "width": 4.5, "height": 9, "layer": 0.16, "raster": 0}
#: the study's centre design as command-line flags
SIX_FLAGS = [a for n, v in FACTORS.items() for a in (f"--{n}", str(v))]


def _make_logs(folder: Path) -> None:
    from designer.rig.logs import write_log
    from designer.rig.simulate import simulate

    df = simulate({"x": {"m": 1e-3, "c": 2e-3, "k": 0.8}}, duration=20, rate=200, seed=1)
    write_log(df, folder / "log.csv", FACTORS)
    logs = {
        "log_semicolon.csv": lambda: df.to_csv(folder / "log_semicolon.csv", sep=";", index=False),
        "log_noload.csv": lambda: df.drop(columns=["Fx"]).to_csv(folder / "log_noload.csv", index=False),
        "log_backwards.csv": lambda: df.iloc[::-1].to_csv(folder / "log_backwards.csv", index=False),
        "log_unit.csv": lambda: df.rename(columns={"x": "x [m]"}).to_csv(
            folder / "log_unit.csv", index=False
        ),
        "log_empty.csv": lambda: (folder / "log_empty.csv").write_bytes(b""),
        "log_binary.csv": lambda: (folder / "log_binary.csv").write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(300)),
    }
    for make in logs.values():
        make()
    sidecars = {
        "side_typo": {"factors": FACTORS, "load_dealy_s": 0.001},
        "side_range": {"factors": dict(FACTORS, density=500)},
        "side_text": {"factors": dict(FACTORS, width="wide")},
        "side_unknown": {"factors": dict(FACTORS, colour=3)},
        "side_list": [1, 2, 3],
    }
    for name, doc in sidecars.items():
        df.to_csv(folder / f"{name}.csv", index=False)
        (folder / f"{name}.json").write_text(json.dumps(doc))
    df.to_csv(folder / "side_notjson.csv", index=False)
    (folder / "side_notjson.json").write_text("{factors: 60")


def _make_suggestions(folder: Path) -> None:
    from designer.design.suggestions import suggest
    from designer.model.surrogate import Surrogate

    good = suggest(Surrogate.load(), k=0.8, top=2).to_dict()
    (folder / "suggestion.json").write_text(json.dumps(good))
    cand = good["candidates"][0]
    bad = {
        "sug_notjson.json": "{axis: x",
        "sug_list.json": [good],
        "sug_other.json": {"name": "not a suggestion", "value": 3},
        "sug_typo.json": {**good, "candidtes": good["candidates"]},
        "sug_extra.json": {**good, "colour": "red"},
        "sug_empty.json": {**good, "candidates": []},
        "sug_noparams.json": {**good, "candidates": [{"desirability": 1}]},
        "sug_range.json": {**good, "candidates": [{**cand, "params": dict(cand["params"], density=500)}]},
        "sug_axis.json": {**good, "axis": "w"},
        "sug_candkey.json": {**good, "candidates": [{**cand, "paramz": cand["params"]}]},
    }
    for name, doc in bad.items():
        (folder / name).write_text(doc if isinstance(doc, str) else json.dumps(doc))


def _make_series(folder: Path) -> None:
    t = np.linspace(0, 1, 50)
    frame = pd.DataFrame({"t": t, "a.x.s": np.sin(t), "a.x.f": np.cos(t)})
    frame.to_csv(folder / "ts.csv", index=False)
    frame.to_csv(folder / "ts_semicolon.csv", sep=";", index=False)
