"""Issue 37, cause 5, as real `python -I` processes: stops that did not stop, and stops that lied.

- Ctrl-C or SIGTERM landing inside IPOPT during `designer next`: CasADi catches the interrupt and the
  solve returns early; `next` carried on and answered (exit 0) from the interrupted search. Now it ends
  with 130 or 143 and prints no answer.
- A stop landing just after a command wrote its output: `calibrate`, `rig simulate`, `clean` and
  `profile` said "stopped ... partial files removed" (143) while their complete output stayed. Now,
  like the commands that mark their last step (`finishing`), they end with their own exit code and
  say the output is complete.

The signal is sent by the process to itself at the exact moment: a watcher thread sends it when the
main thread is inside the IPOPT call of `Problem.solve` (CasADi releases the GIL while it solves), and
a wrapped writer sends it right after the real one returns.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

IN_IPOPT = r"""
import os, sys, threading, time
SIG = int(sys.argv.pop(1))

def watch():
    main = threading.main_thread().ident
    while True:
        frame, chain = sys._current_frames().get(main), []
        while frame is not None:
            chain.append(frame.f_code)
            frame = frame.f_back
        in_casadi = bool(chain) and os.sep + "casadi" + os.sep in chain[0].co_filename
        if in_casadi and any(c.co_name == "solve" and c.co_filename.endswith("search.py") for c in chain):
            os.kill(os.getpid(), SIG)
            return
        time.sleep(0.0002)

threading.Thread(target=watch, daemon=True).start()
from designer_cli.main import main
main()
"""

AFTER_WRITE = r"""
import importlib, os, signal, sys
module, attr = sys.argv.pop(1).split(":")
owner = importlib.import_module(module)
holder, name = (getattr(owner, attr.split(".")[0]), attr.split(".")[1]) if "." in attr else (owner, attr)
original = getattr(holder, name)

def write_then_stop(*args, **kwargs):
    out = original(*args, **kwargs)
    os.kill(os.getpid(), signal.SIGTERM)
    return out

setattr(holder, name, write_then_stop)
from designer_cli.main import main
main()
"""


def child(script: str, args: list, cwd: Path) -> subprocess.CompletedProcess:
    env = dict(os.environ, TMPDIR=str(cwd), XDG_CACHE_HOME=str(cwd / ".cache"))
    cmd = [sys.executable, "-I", "-c", script, *map(str, args)]
    return subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, timeout=300)


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_a_stop_inside_ipopt_stops_next(sig, tmp_path):
    r = child(IN_IPOPT, [int(sig), "next", "--k", "0.8", "--json"], tmp_path)
    name = signal.Signals(sig).name
    assert r.returncode == 128 + sig, (r.returncode, r.stderr)
    assert f"stopped by {name}" in r.stderr and "Traceback" not in r.stderr, r.stderr
    assert r.stdout == ""  # no answer from an interrupted search


RUNS = "density,length,width,height,layer,raster,k_x,c_x\n60,24,4.5,9,0.16,0,0.8,0.002\n"
WRITERS = {
    "calibrate": (["calibrate", "runs.csv", "-o", "out.json"], "designer.model.surrogate:Surrogate.save"),
    "rig simulate": (
        ["rig", "simulate", "--k", "0.8", "--c", "2e-3", "--duration", "2", "-o", "out.csv"],
        "designer.rig.logs:write_log",
    ),
    "clean": (["clean", "table.csv", "--max-drop", "1", "-o", "out.csv"], "designer.study.data:write_frame"),
    "profile": (["profile", "-o", "out.html"], "designer.plots.profile:write_profiler"),
}


@pytest.mark.parametrize("name", list(WRITERS))
def test_a_stop_after_the_output_is_written_keeps_the_commands_own_exit(name, tmp_path):
    from designer.study.data import load_table

    (tmp_path / "runs.csv").write_text(RUNS)
    load_table().to_csv(tmp_path / "table.csv", index=False)
    args, writer = WRITERS[name]
    r = child(AFTER_WRITE, [writer, *args], tmp_path)
    assert r.returncode == 0, (r.returncode, r.stderr)
    assert "SIGTERM came while the outputs were written: they are complete" in r.stderr, r.stderr
    out = next(tmp_path.glob("out.*"))
    assert out.stat().st_size > 0
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".") and p.name != ".cache") == []
