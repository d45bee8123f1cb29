"""Issue 37, cause 9: messages that offer what does not exist. `next` and `profile` offered
--allow-extrapolation, which they lack; `plot space` said `fixed=` (the library's argument) for --fix;
a cosim reference CSV separated by ';' or tabs got "has no column 't' (it has: t;angle)", a binary
one exit 3.

Every message template that names a flag is walked against every command's options: the library's
argument names the CLI translates (`common.FLAGS`, each with an example message) and the string
constants of each command's own code (and the module functions it calls)."""

from __future__ import annotations

import ast
import inspect
import re
import sys
import textwrap

import pytest
import typer
from clitools import assert_clean_failure, run_inprocess
from designer_cli.common import FLAGS, flag_message
from designer_cli.main import app, command_options

FLAG = re.compile(r"(?<![\w-])--[a-z][\w-]*")
#: a whole command line quoted in a message, e.g. `designer export fmu ... --axis theta`
QUOTED = re.compile(r"`designer [^`]*`")


def commands(cmd, path=()):
    """(path, click command) of every command under `cmd`."""
    if getattr(cmd, "commands", None):
        for name, sub in cmd.commands.items():
            yield from commands(sub, (*path, name))
    else:
        yield path, cmd


COMMANDS = list(commands(typer.main.get_command(app)))


def test_the_walk_sees_every_command():
    names = {" ".join(p) for p, _ in COMMANDS}
    assert {"next", "profile", "plot space", "export fmu", "cosim", "suggest"} <= names
    assert len(names) >= 20


@pytest.mark.parametrize("flag", FLAGS, ids=lambda f: f.flag.strip())
def test_each_translated_template_names_only_the_commands_own_flags(flag):
    assert re.search(flag.pattern, flag.example), f"the example no longer matches {flag.pattern}"
    offered = set()
    for path, _ in COMMANDS:
        options = command_options(list(path))
        text = flag_message(flag.example, options)
        for quoted in QUOTED.findall(text):  # a quoted command line: the flags of the command it quotes
            words = quoted.split()
            named = command_options(words[1 : words.index("...") if "..." in words else len(words)])
            assert set(FLAG.findall(quoted)) <= named, f"{quoted!r} names flags its command lacks"
        wrong = set(FLAG.findall(QUOTED.sub("", text))) - options
        assert not wrong, f"designer {' '.join(path)} would say {text!r}, naming {wrong} it lacks"
        offered |= set(FLAG.findall(text))
    assert offered, f"no command has the flag of {flag.pattern}: the entry is dead"


def strings_of(func, seen: set) -> list[str]:
    """String constants (f-string parts included) of `func` and of the functions of its own module
    that it calls, transitively."""
    if func in seen:
        return []
    seen.add(func)
    module = sys.modules[func.__module__]
    out = []
    for node in ast.walk(ast.parse(textwrap.dedent(inspect.getsource(func)))):
        if isinstance(node, ast.Constant) and isinstance(node.value, str):
            out.append(node.value)
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
            called = getattr(module, node.func.id, None)
            if inspect.isfunction(called) and called.__module__ == func.__module__:
                out += strings_of(called, seen)
    return out


@pytest.mark.parametrize("path", [p for p, _ in COMMANDS], ids=" ".join)
def test_each_commands_own_messages_name_only_its_flags(path):
    cmd = dict(COMMANDS)[path]
    callback = getattr(cmd.callback, "__wrapped__", cmd.callback)
    options = command_options(list(path))
    for text in strings_of(callback, set()):
        # a flag of another command is named with that command: "designer suggest --json"
        text = re.sub(r"designer (\w+ )*?\w+( -[-\w]+( [^\s-]\S*)?)*", "", text)
        wrong = set(FLAG.findall(text)) - options
        assert not wrong, f"designer {' '.join(path)} says {text!r}, naming {wrong} it lacks"


@pytest.mark.parametrize(
    "args, words",
    [
        (["next", "--k", "0.8", "--fix", "width=9"], "outside the tested range"),
        (["profile", "--design", "width=9", "--json"], "width"),
        (["plot", "space", "--x", "width", "--y", "height", "--fix", "width=4", "-o", "s.png"], "--fix"),
    ],
    ids=["next", "profile", "plot space"],
)
def test_a_command_is_never_offered_a_flag_it_lacks(args, words, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    code, _, err = run_inprocess(args, capsys)
    assert_clean_failure(code, err, allowed=(2,))
    assert words in err, err
    named = set(FLAG.findall(err))
    assert named <= command_options(args), f"{err!r} names {named - command_options(args)}"


SCENARIO = (
    '[simulation]\nduration = 0.2\nstep = 1e-3\n[robot]\nmodel = "arm"\n[joints.j1]\naxis = "theta"\n'
    'coefficients = { k = 330, c = 0.83 }\nreference = { type = "csv", file = "ref.csv" }\n'
)


@pytest.mark.parametrize(
    "content, words",
    [
        (b"t;q\n0;0\n1;0.3\n", "separated by semicolons"),
        (b"t\tq\n0\t0\n1\t0.3\n", "separated by tabs"),
        (bytes(range(256)) * 8, "binary"),
        (b't,q\n0,0\n1,"0.3\n', "not a comma-separated table"),
    ],
    ids=["semicolon", "tab", "binary", "unclosed quote"],
)
def test_a_cosim_reference_csv_names_its_problem(content, words, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "s.toml").write_text(SCENARIO)
    (tmp_path / "ref.csv").write_bytes(content)
    code, _, err = run_inprocess(["cosim", "s.toml", "-o", "res"], capsys)
    assert_clean_failure(code, err, allowed=(2,))
    assert words in err and "ref.csv" in err, err
    assert not (tmp_path / "res").exists()


@pytest.mark.parametrize(
    ("message", "said"),
    [
        ("into= needs joint_name=", "--into needs --joint"),
        ("give k= a target value", "give --k a target value"),
        ("use fmi_version=2 or 3", "use --fmi 2 or 3"),
        ("(give into=, or none)", "(give --into, or none)"),
    ],
)
def test_a_translated_flag_leaves_no_stray_space(message, said):
    assert flag_message(message) == said
