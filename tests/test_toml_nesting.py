"""Issue 37, cause 8 (the nesting part): a deeply nested scenario or sweep file ended as exit 3
(RecursionError); it is refused in one line naming the file and the limit. The example files stay
well within it."""

from __future__ import annotations

from pathlib import Path

import pytest
from clitools import assert_clean_failure, run_inprocess

from designer.keys import MAX_NESTING, nesting, read_toml

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
HEAD = '[simulation]\nduration = 0.1\nstep = 1e-3\n[robot]\nmodel = "arm"\n'


@pytest.mark.parametrize(
    "command, text",
    [
        (["cosim", "deep.toml", "-o", "r"], HEAD + "x = " + "[" * 5000 + "]" * 5000 + "\n"),
        (["cosim", "deep.toml", "-o", "r"], HEAD + "x = " + "{a = " * 40 + "1" + "}" * 40 + "\n"),
        (["sweep", "deep.toml", "-o", "r"], "x = " + "{a = " * 3000 + "1" + "}" * 3000 + "\n"),
        (["tune", "deep.toml"], "x = " + "[" * 100 + "]" * 100 + "\n"),
    ],
    ids=["scenario arrays 5000", "scenario tables 40", "sweep tables 3000", "tune arrays 100"],
)
def test_a_deeply_nested_file_is_refused_in_one_line(command, text, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "deep.toml").write_text(text)
    code, _, err = run_inprocess(command, capsys)
    assert_clean_failure(code, err, allowed=(2,))
    assert "deep.toml" in err and f"more than {MAX_NESTING} deep" in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["deep.toml"]


@pytest.mark.parametrize("path", sorted(EXAMPLES.glob("*.toml")), ids=lambda p: p.name)
def test_the_examples_nest_well_within_the_limit(path):
    assert nesting(read_toml(path, what="example")[1]) <= MAX_NESTING // 2
