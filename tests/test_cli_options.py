"""One spelling per flag across commands: `-o/--output` for what a command writes, `--data` for an
input table, `--json` on every command that produces numbers; `--help` of each shows an example."""

from __future__ import annotations

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
