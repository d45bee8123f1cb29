"""What every command shares: its common options (one spelling each), --fix parsing, JSON output, the
rich console, and progress bars shown only on a terminal."""

from __future__ import annotations

import contextlib
import json
import math
import re
import sys
from collections.abc import Callable, Collection, Iterator
from pathlib import Path
from typing import Annotated, Any, NamedTuple

import typer
from rich.console import Console
from typer.core import TyperCommand

from designer.errors import DesignerError
from designer.study.space import FACTOR_NAMES, FACTORS


class Command(TyperCommand):
    """A command whose usage line names its arguments as click and POSIX usage do (`designer calibrate
    [OPTIONS] RUNS`), where typer 0.28 writes `{runs}`."""

    def collect_usage_pieces(self, ctx: Any) -> list[str]:
        return [
            re.sub(r"^([\[{]?)([a-z][\w-]*)([\]}]?)", _argument_usage, piece)
            for piece in super().collect_usage_pieces(ctx)
        ]


def _argument_usage(m: re.Match) -> str:
    optional = m.group(1) == "["
    return f"[{m.group(2).upper()}]" if optional else m.group(2).upper()


class Typer(typer.Typer):
    """typer.Typer whose commands are `Command`s."""

    def command(self, *args: Any, cls: Any = None, **kwargs: Any) -> Any:
        return super().command(*args, cls=cls or Command, **kwargs)


#: set by `finishing()`, cleared by each `run()`: the command is writing its outputs and a stop signal
#: no longer interrupts it; LATE_STOP is the signal that came meanwhile (None: none did)
FINISHING = False
LATE_STOP: int | None = None


def finishing() -> None:
    """Mark the command's last step, writing its outputs and printing what it wrote: a stop signal
    from here on is recorded, not raised, so the outputs are whole and the exit code is the command's
    own (stopped at this point, it would say "partial files removed" of files that are complete)."""
    global FINISHING
    FINISHING = True


# the options many commands share, spelled once: -o/--output, --data, --json, --surrogate, --fix
JsonOpt = Annotated[bool, typer.Option("--json", help="print machine-readable JSON only")]
DataOpt = Annotated[
    Path | None,
    typer.Option("--data", help="coefficient table (CSV or Parquet); default: the bundled 44 study runs"),
]
SurrogateOpt = Annotated[
    Path | None,
    typer.Option("--surrogate", help="surrogate JSON from `designer fit` (default: the shipped one)"),
]
AcceptImplausibleOpt = Annotated[
    bool,
    typer.Option(
        "--accept-implausible",
        help="keep a measured k or c no printer can give (refused by default: a unit slip)",
    ),
]
FixOpt = Annotated[
    list[str] | None,
    typer.Option("--fix", help="hold a factor, NAME=VALUE in rig units, e.g. --fix width=4.5 (repeatable)"),
]


def output_option(help: str) -> Any:
    """The `-o/--output` option with a command's own help text."""
    return typer.Option("-o", "--output", help=help)


def quiet_mujoco() -> None:
    """Drop MuJoCo's warnings for this process: by default MuJoCo prints them and appends them to
    MUJOCO_LOG.TXT in the current folder; the co-simulation reports an unstable run itself, in one line."""
    import mujoco

    mujoco.set_mju_user_warning(lambda message: None)


def parse_fix(
    items: list[str] | None,
    *,
    flag: str = "--fix",
    example: str = "width=4.5",
    names: tuple[str, ...] | None = FACTOR_NAMES,
) -> dict[str, float]:
    """['width=4.5', 'raster=0'] -> {'width': 4.5, 'raster': 0.0}: NAME=VALUE pairs of `flag`.

    `names` are the accepted names (default: the six factors; None accepts any name).

    Raises:
        DesignerError: not NAME=VALUE, an unknown name (with the closest one), a name given twice, or a
            value that is not a number (with the factor's unit and range).
    """
    import difflib

    from designer.study import space

    pairs: dict[str, float] = {}
    for item in items or []:
        name, sep, value = item.partition("=")
        name = name.strip()
        if not sep or not name:
            raise DesignerError(
                f"{flag} '{item}' is not NAME=VALUE", f"write it as, for example, {flag} {example}"
            )
        if names is not None and name not in names:
            close = difflib.get_close_matches(name, names, n=1)
            hint = f"did you mean '{close[0]}'? " if close else ""
            raise DesignerError(
                f"unknown factor '{name}' in {flag} {item}", f"{hint}factors: {', '.join(names)}"
            )
        if name in pairs:
            raise DesignerError(f"{flag} {name} is given twice", f"give each name once ({flag} {name}=VALUE)")
        try:
            pairs[name] = float(value)
        except ValueError:
            f = space.BY_NAME.get(name)
            wanted = (
                f"give {name} as a number, {f.describe_range()}" if f else f"write it as {flag} {example}"
            )
            raise DesignerError(f"{flag} {item}: '{value.strip()}' is not a number", wanted) from None
    return pairs


# piped output is not cut at rich's 80-column default: numbers must never be truncated; no markup
# unless a call asks for it (markup=True), so a path or a name in brackets ("prints [v2]") is printed
# as it is, not taken for a style
class _Console(Console):
    """rich's console, except that a closed stdout raises BrokenPipeError (rich exits 1 there): the
    one error path (`main.run`) ends such a command quietly with exit 0, as SIGPIPE would."""

    def on_broken_pipe(self) -> None:
        raise BrokenPipeError


console = _Console(highlight=False, markup=False, width=None if sys.stdout.isatty() else 120)
err_console = Console(stderr=True, highlight=False)


def _clean(obj: Any) -> Any:
    """Make numpy scalars and non-finite floats JSON-safe (NaN and Inf become null)."""
    if isinstance(obj, dict):
        return {str(k): _clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_clean(v) for v in obj]
    if hasattr(obj, "item") and callable(obj.item):
        obj = obj.item()
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def print_json(data: Any) -> None:
    """Print machine-readable output on stdout, nothing else."""
    sys.stdout.write(json.dumps(_clean(data), indent=2) + "\n")


#: set by `--quiet` (main.run): no progress bars
QUIET = False


@contextlib.contextmanager
def progress(description: str, enabled: bool = True) -> Iterator[Callable[[float], None]]:
    """Yield a callback taking the fraction done (0..1); draws a bar only when stderr is a terminal
    and `--quiet` was not given."""
    if not (enabled and err_console.is_terminal) or QUIET:
        yield lambda fraction: None
        return
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    with Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        TextColumn("{task.percentage:>3.0f}%"),
        TimeRemainingColumn(),
        console=err_console,
        transient=True,
    ) as bar:
        task = bar.add_task(description, total=1.0)
        yield lambda fraction: bar.update(task, completed=min(max(fraction, 0.0), 1.0))


class Flag(NamedTuple):
    """A Python argument named in library messages and the flag the CLI spells it with."""

    pattern: str
    flag: str
    #: a library message the pattern matches (tests/test_cli_flag_messages.py walks these)
    example: str
    #: the replacement in a command without that flag (None: the words stay as they are)
    fallback: str | None = None


#: Python arguments named in library messages, and the flags the CLI spells them with: the library
#: speaks to Python callers, the command line to its users, so the one error path translates. A
#: command that lacks the flag gets the fallback, never a flag it does not have
FLAGS: tuple[Flag, ...] = (
    Flag(r"\bsource_only=True\b", "--source-only", "or export with source_only=True and build"),
    Flag(r"\bplatforms=\"(\w+)\"", r"--platforms \1", 'or use platforms="host"'),
    Flag(r"\brebuild=True\b", "--build", "export with rebuild=True"),
    Flag(r"\bfmi_version=", "--fmi ", "use fmi_version=2 or 3"),
    Flag(r"\binterface=", "--interface ", "use interface='force' or 'body'"),
    Flag(
        r"(, or pass )?\ballow_extrapolation=True\b( to accept an unsupported prediction)?",
        r"\1--allow-extrapolation\2",
        "choose a value inside it, or pass allow_extrapolation=True to accept an unsupported prediction",
        "",
    ),
    Flag(r"\btop=", "--top ", "top=0 must be at least 1"),
    Flag(r"\bk= and/or c=", "--k and/or --c", "give k= and/or c= (a value, 'min' or 'max')"),
    Flag(
        r"\bgive k= a target value", "give --k a target value", "give k= a target value (k_x is predictable)"
    ),
    Flag(r"\bn=(?=\S+ is not a whole number)", "--n ", "n=0 is not a whole number from 1 to 10"),
    Flag(r"\bstop=(?=\S+ is not in)", "--stop ", "stop=2 is not in (0, 1]"),
    Flag(
        r"\bload_filter=",
        "--load-filter ",
        "give the sensor's filter (load_filter='butter2:200Hz' if that is it)",
    ),
    Flag(
        r"\ballow_outside_range=True\b", "--allow-outside-range", "or allow_outside_range=True if the spring"
    ),
    Flag(r"\btargets=\{'k': 0\.8\}", "--target k=0.8", "give targets={'k': 0.8}, for k or c"),
    Flag(
        r"\baccept_implausible=True\b",
        "--accept-implausible",
        "k_x 800 is 1000 times the study's; if the value is right, pass accept_implausible=True",
    ),
    Flag(r"\bfrom fixed=", "from --fix", "drop width from fixed="),
    # export mjcf/urdf/sdf/modelica/ssp
    Flag(r"\binto=", "--into ", "then export with into='robot_flat.xml'"),
    Flag(
        r"\bjoint_name=", "--joint ", "joint_name='knee': the robot has no hinge or slide joint of that name"
    ),
    Flag(r"\baxis=(?='\w+'(, or| is | does ))", "--use-axis ", "axis='x' is not an axis of the joint"),
    Flag(r"\bform=(?='\w*' is not a form)", "--form ", "form='serial' is not a form"),
    Flag(r"\bform='(\w+)'", r"--form \1", "form='series' into a USD robot is not written"),
    Flag(r"\bmsl=", "--msl ", "msl='3.2' is not supported"),
    Flag(r"\brest=(?=\S+ is for exports into)", "--rest ", "rest=0.1 is for exports into a robot"),
    Flag(r"\bmotor_inertia=", "--motor-inertia ", "motor_inertia=0 and motor_bandwidth=0 must be positive"),
    Flag(
        r"\bmotor_bandwidth=", "--motor-bandwidth ", "motor_inertia=0 and motor_bandwidth=0 must be positive"
    ),
    Flag(
        r"\brest=(?=\S+ (rad|m) is outside the range)",
        "--rest ",
        "rest=2 rad is outside the range [-1, 1] rad of robot joint 'knee'",
    ),
    Flag(
        r"\bpackage_paths=\{'([^']+)': 'DIR'\}",
        r"--package-path \1=DIR",
        "as ROS's package path would: package_paths={'arm': 'DIR'}",
    ),
    # a quoted command line names the flags of the command it quotes, whichever command is running
    Flag(
        r"export_fmu of a Joint with axes=\['(\w+)'\]",
        r"`designer export fmu ... --axis \1`",
        "export the joint on axis theta: export_fmu of a Joint with axes=['theta']",
    ),
    Flag(r"\bprint_id='(\w+)'", r"--print \1", "give print_id='P1' (the id engraved on the specimen)"),
    Flag(r"\bprint_id=(?!')", "--print", "identify one log at a time with print_id=, or name each"),
    Flag(
        r"\bcandidate=(?=\d+ is not in)", "--candidate ", "candidate=4 is not in the suggestion (it holds 3)"
    ),
    Flag(r"\bgive candidate (?=\d+ to \d+)", "give --candidate ", "give candidate 1 to 3"),
    Flag(
        r"\bcandidate is for a suggest", "--candidate is for a suggest", "candidate is for a suggest output"
    ),
    Flag(
        r"\bprint_id=(?='[^']*' cannot be engraved)",
        "--id ",
        "print_id='P 1' cannot be engraved (no stroke for ' ')",
    ),
    Flag(
        r"\bruns_path=(?=')",
        "--runs ",
        "append this batch to it with runs_path='prints/runs.csv' (its ids continue)",
    ),
    Flag(
        r"pass a Suggestion, its to_dict\(\) or such a JSON file|give a JSON file of Suggestion\.to_dict\(\)",
        "give the output of `designer suggest ... --json`",
        "suggestion has no list of candidates (pass a Suggestion, its to_dict() or such a JSON file)",
    ),
    Flag(r"\bmax_cases=(\d+)", r"--max-cases \1", "or pass max_cases=2000000 if that many are meant"),
    Flag(r"\bpackage_paths\['([^']+)'\]=", r"--package-path \1=", "package_paths['arm']='x' is not a folder"),
)


def flag_message(text: str, options: Collection[str] | None = None) -> str:
    """A library message with its Python argument names replaced by the CLI's flags; with `options`
    (the running command's), a flag the command lacks is never named (the flag's fallback instead)."""
    for f in FLAGS:
        quoted = f.flag.startswith("`designer ")
        if options is None or quoted or set(re.findall(r"--[\w-]+", f.flag)) <= set(options):
            text = re.sub(f.pattern, f.flag, text)
        elif f.fallback is not None:
            text = re.sub(f.pattern, f.fallback, text)
    # a flag that takes a value ("--into ") where the Python words named the argument alone
    # ("into= needs joint_name=") keeps no space before a space, a comma or a bracket
    return re.sub(r"(--[\w-]+) (?=[\s,;:)]|$)", r"\1", text)


def design_text(params: dict) -> str:
    """One design's six settings as every command prints them, with the flags' names and units:
    "density 60 %, length 24 mm, width 4.5 mm, height 9 mm, layer 0.16 mm, raster 0 deg"."""
    return ", ".join(f"{f.name} {params[f.name]:g} {f.unit}" for f in FACTORS)


AxisOpt = Annotated[str, typer.Option("--axis", help="axis: x y z theta phi psi")]
ToleranceOpt = Annotated[
    float, typer.Option("--tolerance", help="band around a target that counts as met, % (+-)")
]


def load_surrogate(path: Path | None):
    """The surrogate of a --surrogate flag: that file, or the shipped one for None."""
    from designer.model.surrogate import Surrogate

    return Surrogate.load() if path is None else Surrogate.load(path)


def parse_goal(text: str | None, flag: str) -> float | str | None:
    """A goal flag's value: a number in rig units, or min or max."""
    if text is None:
        return None
    if text.strip().lower() in ("min", "max"):
        return text.strip().lower()
    try:
        return float(text)
    except ValueError:
        raise DesignerError(
            f"{flag} '{text}' is not a number, min or max", f"write e.g. {flag} 0.8 or {flag} max"
        ) from None


def pi_text(p: dict, unit: str = "") -> str:
    """A prediction's to_dict() as 'value [low, high] unit' (`designer.model.prediction.Prediction.text`)."""
    from designer.model.prediction import Prediction

    return Prediction.from_dict(p).text(unit)


def answer(data: dict, as_json: bool, show: Callable[[dict], None]) -> None:
    """Print a design answer (JSON, or `show`'s table and sentences); exit 1 when it is negative
    (`data["reachable"]` False: the output still says why and what comes nearest)."""
    if as_json:
        print_json(data)
    else:
        show(data)
    if not data["reachable"]:
        raise typer.Exit(1)


def tolerance_fraction(percent: float) -> float:
    """--tolerance in % as a fraction, refused outside (0, 100)."""
    if not 0 < percent < 100:
        raise DesignerError(f"--tolerance {percent:g} is not between 0 and 100 %", "give e.g. --tolerance 10")
    return percent / 100
