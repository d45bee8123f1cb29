"""`--quiet` (any position, like --debug) turns the progress bars off even on a terminal."""

from __future__ import annotations

import io

from designer_cli import common, main
from rich.console import Console


def _bar_output(monkeypatch) -> str:
    buf = io.StringIO()
    monkeypatch.setattr(common, "err_console", Console(file=buf, force_terminal=True, width=80))
    with common.progress("working") as bar:
        bar(0.5)
        bar(1.0)
    return buf.getvalue()


def test_progress_draws_on_a_terminal_and_not_when_quiet(monkeypatch):
    monkeypatch.setattr(common, "QUIET", False)
    assert "working" in _bar_output(monkeypatch)
    monkeypatch.setattr(common, "QUIET", True)
    assert _bar_output(monkeypatch) == ""


def test_quiet_is_accepted_in_any_position(monkeypatch, capsys):
    monkeypatch.setattr(common, "QUIET", False)
    assert main.run(["suggest", "--k", "0.8", "--json", "--quiet"]) == 0
    assert common.QUIET
    assert capsys.readouterr().err == ""


def test_fit_reports_progress_per_response():
    from designer.model.surrogate import Surrogate

    seen: list[float] = []
    Surrogate().fit(None, responses=["k_x", "c_x"], nested=False, progress=seen.append)
    assert seen == [0.5, 1.0]
