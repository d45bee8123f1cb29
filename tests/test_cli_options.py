"""One spelling per flag across commands: `-o/--output` for what a command writes, `--data` for an
input table, `--json` on every command that produces numbers; `--help` of each shows an example."""

from __future__ import annotations

import json
import re

import typer
from designer_cli.main import app


def _commands(group, path=("designer",)):
    for name, cmd in group.commands.items():
        if hasattr(cmd, "commands"):
            yield from _commands(cmd, (*path, name))
        else:
            yield " ".join((*path, name)), cmd


COMMANDS = dict(_commands(typer.main.get_command(app)))


def test_every_command_is_found():
    assert {
        "designer fit",
        "designer rig simulate",
        "designer plot timeseries",
        "designer export fmu",
    } <= set(COMMANDS)


def test_one_spelling_per_flag():
    for path, cmd in COMMANDS.items():
        flags = {opt for p in cmd.params for opt in getattr(p, "opts", [])}
        assert not flags & {"--out", "--table", "--input", "--output-dir"}, (path, flags)
        for p in cmd.params:
            if p.name == "output" or "--output" in getattr(p, "opts", []):
                assert sorted(p.opts) == ["--output", "-o"], (path, p.opts)
            if "--data" in getattr(p, "opts", []):
                assert p.opts == ["--data"], (path, p.opts)


def test_every_command_prints_json_and_shows_an_example():
    for path, cmd in COMMANDS.items():
        flags = {opt for p in cmd.params for opt in getattr(p, "opts", [])}
        assert "--json" in flags, f"{path} has no --json"
        assert "Example: designer" in (cmd.help or ""), f"{path} --help has no example"


def test_every_option_and_argument_has_help():
    """A newcomer reads `--help`: no option or argument of any command may be left without text."""
    import typer.main
    from designer_cli.main import app

    def commands(cmd, path):
        if hasattr(cmd, "commands"):
            for name, sub in cmd.commands.items():
                yield from commands(sub, [*path, name])
        else:
            yield " ".join(path), cmd

    bare = [
        (path, param.name)
        for path, cmd in commands(typer.main.get_command(app), ["designer"])
        for param in cmd.params
        if not (getattr(param, "help", None) or "").strip() and "--help" not in getattr(param, "opts", [])
    ]
    assert not bare, f"without help: {bare}"


def _usage(cmd, path: str) -> str:
    import click

    ctx = click.Context(cmd, info_name=path)
    return cmd.get_usage(ctx)


def test_usage_lines_name_arguments_in_capitals():
    """`designer calibrate [OPTIONS] RUNS`, as click and POSIX usage write it, not typer's `{runs}`."""
    usages = {path: _usage(cmd, path) for path, cmd in COMMANDS.items()}
    assert usages["designer calibrate"].split() == ["Usage:", "designer", "calibrate", "[OPTIONS]", "RUNS"]
    assert usages["designer identify"].split()[-1] == "LOGS..."
    assert not [u for u in usages.values() if re.search(r"[{}]|\b[a-z_]+\.\.\.", u)], usages


def test_help_texts_share_one_style():
    """Every option's and argument's help starts in lower case (unless with a name such as MuJoCo or
    JSON) and ends without a full stop, as most of them did; `suggest --help` states each exit code once."""
    odd = []
    for path, cmd in [*COMMANDS.items(), ("designer", typer.main.get_command(app))]:
        for p in cmd.params:
            text = (getattr(p, "help", None) or "").strip()
            first = text.split()[0] if text else ""
            named = (
                re.match(r"[A-Z]{2}", first) or re.search(r"[a-z][A-Z]", first) or first in {"Monte", "Dask"}
            )
            if text and ((text[0].isupper() and not named) or text.endswith(".")):
                odd.append((path, p.name, text))
    assert not odd, odd
    suggest = COMMANDS["designer suggest"].help
    assert len(re.findall(r"\bExits? 1\b", suggest)) == 1


def test_designs_are_printed_with_the_flags_names(capsys):
    """Flags, tables, sentences and JSON say density, length, width, height: never infill, l, b, h."""
    from clitools import run_inprocess

    code, out, _ = run_inprocess(["suggest", "--k", "0.8", "--top", "2"], capsys)
    assert code == 0
    header = " ".join(out.splitlines()[2:4])
    assert all(word in header for word in ("density", "length", "width", "height", "layer", "raster"))
    assert not re.search(r"\binfill\b|\bl\b|\bb\b|\bh\b", header) and "l, b, h" not in out
    assert "Printability: density rounded to 1 %" in " ".join(out.split())
    code, out, _ = run_inprocess(["next", "--k", "0.8", "--n", "1"], capsys)
    assert code == 0 and re.search(r"Design #1 now: density \d+ %, length [\d.]+ mm, width ", out)
    assert "after printing and measuring it, the best" in " ".join(out.split()), out  # not "these 1"
    assert re.search(r"k [\d.]+ \[[\d.]+, [\d.]+\] N/mm, c [\d.]+ \[[\d.]+, [\d.]+\] N\.s/mm;", out), out
    code, out, _ = run_inprocess(["suggest", "--k", "0.8", "--top", "1", "--json"], capsys)
    assert list(json.loads(out)["candidates"][0]["params"]) == [
        "density", "length", "width", "height", "layer", "raster"
    ]  # fmt: skip


def test_the_timeseries_example_names_columns_a_robot_run_writes():
    """`plot timeseries --help`'s example once named rig columns (joint.x.s) no robot run has."""
    from dataclasses import replace
    from pathlib import Path

    from designer import cosim

    example = COMMANDS["designer plot timeseries"].help.split("Example: ", 1)[1].split()
    columns = example[example.index("--columns") + 1].split(",")
    scenario = cosim.load(Path(__file__).resolve().parents[1] / "examples" / "two_link_arm.toml")
    frame = cosim.run(replace(scenario, duration=0.01)).to_frame()
    assert set(columns) <= set(frame.columns), (columns, list(frame.columns))
