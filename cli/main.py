"""Entry point of the `designer` command: registers the sub-commands and owns the one error path.

Every failure ends as one line on stderr naming the problem and the fix, never a traceback:

| exit | meaning |
| --- | --- |
| 0 | success |
| 1 | a negative answer: a check failed, no design meets the target, a log failed identification |
| 2 | bad input or environment (a file, a flag, a full disk, too little memory) |
| 3 | internal error (a bug: the line says so; `--debug` shows the traceback) |
| 129, 130, 143 | stopped by SIGHUP, Ctrl-C (SIGINT) or SIGTERM; part files are removed |

A stop that comes while a command writes its outputs (`common.finishing`) lets it finish them.
"""

from __future__ import annotations

import atexit
import errno
import gc
import os
import signal
import sys
import threading
import traceback
import warnings
from typing import Annotated

#: fit, predict, suggest and the loop's calibrate and next do small dense algebra: OpenBLAS's thread
#: pool costs more to start (~50 ms) than it saves; set before numpy loads, and only when the user has
#: not chosen
DESIGN_COMMANDS = ("fit", "predict", "suggest", "calibrate", "next")
_DESIGN = sys.argv[1:2] != [] and sys.argv[1] in DESIGN_COMMANDS
if _DESIGN:
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import typer  # noqa: E402

from designer.errors import DesignerError  # noqa: E402

from . import common, design, loop  # noqa: E402
from .common import Typer, flag_message  # noqa: E402

try:  # typer 0.28 vendors click
    from typer._click import exceptions as _click_errors
except ImportError:  # pragma: no cover - older typer on click
    from click import exceptions as _click_errors

REPORT_HINT = "this is a bug in designer: rerun with --debug and report the traceback"

SETTINGS = dict(
    help="Design 3D-printed TPU flexible joints: predict and choose stiffness and damping, export FMUs.\n\n"
    "Exit codes: 0 success, 1 negative answer (a check failed, no design meets the target), 2 bad input "
    "or environment, 3 internal error; 130, 143, 129 when stopped by Ctrl-C, SIGTERM, SIGHUP.",
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    add_completion=False,
    rich_markup_mode="rich",
)
#: the design and loop commands: a design command runs on an app of its own (`command_app`; the help
#: of `designer` itself still lists everything), and the other commands' modules (and the library
#: modules they import) are not loaded for it
design_app = Typer(**SETTINGS)


def _version(value: bool) -> None:
    if value:
        from designer import __version__

        print(f"designer {__version__}")
        raise typer.Exit(0)


@design_app.callback()
def _options(
    version: Annotated[
        bool, typer.Option("--version", callback=_version, is_eager=True, help="print the version and exit")
    ] = False,
    debug: Annotated[
        bool, typer.Option("--debug", help="on an internal error, show the traceback (any position)")
    ] = False,
    quiet: Annotated[
        bool,
        typer.Option("--quiet", help="no progress bars on stderr (any position; off a terminal always)"),
    ] = False,
) -> None:
    """Options of the `designer` command itself (--debug is also accepted after a sub-command)."""


design.register(design_app)
loop.register(design_app)
_FULL: list[Typer] = []


def command_app(name: str) -> Typer:
    """An app holding the design command `name` alone, with `designer`'s own options: typer turns
    each registered command's signature into click's on every call (16 ms for the five design
    commands, most of it for the four that do not run); the command parses, helps and fails the same."""
    app = Typer(**SETTINGS)
    app.callback()(_options)
    app.registered_commands = [
        c for c in design_app.registered_commands if (c.name or c.callback.__name__) == name
    ]
    return app


def chosen_app(args: list[str]) -> Typer:
    """The app a command line `args` runs on: a design command's own, else the full one."""
    return command_app(args[0]) if args[:1] and args[0] in DESIGN_COMMANDS else full_app()


def full_app() -> Typer:
    """The app with every command (built once, on first use): a design command runs on `command_app`'s."""
    if not _FULL:
        from . import cosim, export, plots, printing, rig, sweep

        app = Typer(**SETTINGS)
        app.callback()(_options)
        for module in (design, loop, printing, rig, export, cosim, plots, sweep):
            module.register(app)
        _FULL.append(app)
    return _FULL[0]


def __getattr__(name: str) -> Typer:
    """`designer_cli.main.app`, the app with every command, built when first asked for."""
    if name == "app":
        return full_app()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


class Stopped(BaseException):
    """Raised in the main thread by SIGINT, SIGTERM or SIGHUP: unwinds through every `finally` and
    `except BaseException` (which remove part files) and is not caught as an `Exception`."""

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum


#: the stop signals received, in order (a Stopped that a C extension turned into another exception,
#: such as "ImportError: initialization failed" when it landed in a module's import, is still a stop)
RECEIVED: list[int] = []


def _stop(signum: int, frame) -> None:
    if common.FINISHING:  # the outputs are being written: the command ends on its own, in a moment
        common.LATE_STOP = signum
        return
    # later signals are ignored so that the cleanup they interrupt runs to its end
    for s in _signals():
        signal.signal(s, signal.SIG_IGN)
    RECEIVED.append(signum)
    raise Stopped(signum)


def _unraisable(hook):
    """sys.unraisablehook: a Stopped raised while Python ran a weakref callback, a __del__ or the
    garbage collector is swallowed there ("Exception ignored in ..."), and the command would go on
    to exit 0 with a traceback printed; instead the signal is delivered again, to the main flow."""

    def handle(unraisable) -> None:
        exc = unraisable.exc_value
        if isinstance(exc, Stopped):
            # sent again from another thread a moment later, when the main thread has left the
            # callback (raised here, it would land in this hook and be swallowed again)
            signal.signal(exc.signum, _stop)
            again = threading.Timer(0.02, os.kill, (os.getpid(), exc.signum))
            again.daemon = True  # never holds up the interpreter's exit
            again.start()
            return
        hook(unraisable)

    return handle


def _signals() -> list[int]:
    return [getattr(signal, n) for n in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, n)]


def _os_message(exc: OSError) -> tuple[str, str]:
    """An operating-system error as (problem, fix)."""
    where = f" ({exc.filename})" if exc.filename else ""
    if exc.errno in (errno.ENOSPC, errno.EDQUOT):
        import shutil
        import tempfile

        tmp = tempfile.gettempdir()
        inside = str(exc.filename or "").startswith(tmp + os.sep)
        # no file named (an archive unpacked, a library's own write): the temporary folder, if it is full
        if inside or (exc.filename is None and shutil.disk_usage(tmp).free < 1 << 20):
            return (
                f"the temporary folder is full ({tmp}, TMPDIR)",
                "free some space there, or point TMPDIR to a folder with room",
            )
        return f"the disk is full{where}", "free some space or write to another disk"
    if exc.errno in (errno.EACCES, errno.EPERM, errno.EROFS):
        return f"permission denied{where}", "choose a path you can read or write"
    if exc.errno == errno.ENOENT:
        return f"no such file or folder{where}", "check the path"
    if exc.errno == errno.EISDIR:
        return f"a folder where a file is expected{where}", "give a file"
    return f"{exc.strerror or exc}{where}", "check the path and the disk"


def _fail(problem: str, fix: str | None, code: int) -> int:
    line = f"error: {problem}" + (f" ({fix})" if fix else "")
    # one line: control characters and non-printable bytes of user input are not echoed raw
    line = "".join(ch if ch.isprintable() else "?" for ch in line.replace("\n", " "))
    print(line, file=sys.stderr)
    return code


def run(argv: list[str] | None = None) -> int:
    """Run the command line `argv` (default sys.argv[1:]) and return its exit code; never raises."""
    args = list(sys.argv[1:] if argv is None else argv)
    debug = "--debug" in args[: args.index("--")] if "--" in args else "--debug" in args
    if debug:
        args.remove("--debug")
    head = args[: args.index("--")] if "--" in args else args
    common.QUIET = "--quiet" in head  # like --debug, accepted in any position
    common.FINISHING, common.LATE_STOP = False, None
    RECEIVED.clear()  # a command run in this process before (the tests) is not this one
    if common.QUIET:
        args.remove("--quiet")
    with warnings.catch_warnings():
        if not debug:  # library warnings (numpy overflow, deprecations) are not the user's business
            warnings.simplefilter("ignore")
        return _run(args, debug)


def _check_tmpdir() -> None:
    """Refuse a TMPDIR that is not a writable folder before any work: Python falls back to /tmp
    silently, but the co-simulation libraries write there and crash (libcosimpy: SIGSEGV).

    Raises:
        DesignerError: naming TMPDIR and its value.
    """
    folder = os.environ.get("TMPDIR")
    if folder and not (os.path.isdir(folder) and os.access(folder, os.W_OK | os.X_OK)):
        why = "is not a writable folder" if os.path.isdir(folder) else "does not exist"
        raise DesignerError(f"TMPDIR={folder} {why}", "create it, or point TMPDIR to a writable folder")


#: the smallest address-space limit (ulimit -v) a command runs under: the numerical libraries map up
#: to 2 GiB (designer next measured 1.9 GiB of VmPeak), and under a smaller limit a failed mapping is
#: not reported: CasADi's OpenBLAS retries it forever (1 GiB), IPOPT's plugin fails to load (600 MiB)
MIN_ADDRESS_SPACE = 4 << 30


def _check_address_space(args: list[str]) -> None:
    """Refuse a command (not --help) under an address-space limit it may not fit in, before any work.

    Raises:
        DesignerError: naming the limit and the one needed.
    """
    import resource

    soft = resource.getrlimit(resource.RLIMIT_AS)[0]
    if soft == resource.RLIM_INFINITY or soft >= MIN_ADDRESS_SPACE or not args or "--help" in args:
        return
    from designer.files import format_bytes

    raise DesignerError(
        f"the address-space limit (ulimit -v) is {format_bytes(soft)}, less than the "
        f"{format_bytes(MIN_ADDRESS_SPACE)} the numerical libraries may map (under it they can hang)",
        f"raise it: ulimit -v {MIN_ADDRESS_SPACE >> 10} (KiB) or unlimited",
    )


def _run(args: list[str], debug: bool) -> int:
    try:
        _check_tmpdir()
        _check_address_space(args)
        code = chosen_app(args)(args=args, prog_name="designer", standalone_mode=False)
        if RECEIVED or code == 130:
            return _swallowed()
        _late_stop()
        return code if isinstance(code, int) else 0
    except Stopped as exc:
        return _stopped(exc.signum)
    except (KeyboardInterrupt, typer.Abort):
        return _stopped(RECEIVED[0] if RECEIVED else signal.SIGINT)
    except typer.Exit as exc:
        if RECEIVED:
            return _swallowed()
        _late_stop()
        return exc.exit_code
    except _click_errors.ClickException as exc:
        if type(exc).__name__ == "NoArgsIsHelpError":
            return 2  # the help is already printed
        ctx = getattr(exc, "ctx", None)
        where = f"{ctx.command_path} --help" if ctx is not None else "designer --help"
        return _fail(exc.format_message(), f"see {where}", 2)
    except DesignerError as exc:
        options = command_options(args)
        return _fail(flag_message(exc.problem, options), exc.fix and flag_message(exc.fix, options), 2)
    except BrokenPipeError:
        return _closed_stdout()
    except MemoryError:
        return _fail("out of memory", "ask for a smaller run (shorter, coarser, fewer cases)", 2)
    except OSError as exc:
        if exc.errno is None:
            return _internal(exc, debug)
        return _fail(*_os_message(exc), 2)
    except Exception as exc:  # noqa: BLE001 - the one place that turns any bug into exit 3
        if RECEIVED:  # the stop, converted on its way out: not a bug
            return _stopped(RECEIVED[0])
        return _internal(exc, debug)


def command_options(args: list[str]) -> set[str]:
    """The option names (e.g. --fix) of the command the command line `args` invokes, with those of
    `designer` itself: a message must not offer a flag the command lacks."""
    cmd = typer.main.get_command(chosen_app(args))
    names = {o for p in cmd.params for o in (*p.opts, *p.secondary_opts)}
    for token in args:
        commands = getattr(cmd, "commands", None)
        if not commands:
            break
        if token in commands:
            cmd = commands[token]
            names |= {o for p in cmd.params for o in (*p.opts, *p.secondary_opts)}
    return names


def _swallowed() -> int:
    """A command that returned although a stop signal came before its last step: a C extension
    caught the stop (CasADi inside IPOPT turns it into a failed solve; the library raises it again as a
    KeyboardInterrupt, which typer turns into a silent exit 130). It was stopped all the same."""
    return _stopped(RECEIVED[0] if RECEIVED else signal.SIGINT)


def _late_stop() -> None:
    """Say so when a stop signal came while the command wrote its outputs (it finished them)."""
    if common.LATE_STOP is not None:
        name = signal.Signals(common.LATE_STOP).name
        print(f"{name} came while the outputs were written: they are complete", file=sys.stderr)


def _stopped(signum: int) -> int:
    print(f"stopped by {signal.Signals(signum).name}; partial files removed", file=sys.stderr)
    return 128 + signum


def _closed_stdout() -> int:
    """The reader of our output has gone (`designer ... | head`): a normal end for a command line, as
    with SIGPIPE's default action. Later writes and the exit flush go to /dev/null; exit 0."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, sys.stdout.fileno())
    os.close(devnull)
    return 0


def _internal(exc: BaseException, debug: bool) -> int:
    if debug:
        traceback.print_exception(exc)
    first = (str(exc).splitlines() or [""])[0][:200]
    return _fail(f"internal error: {type(exc).__name__}: {first}", REPORT_HINT, 3)


def install_signal_handlers() -> None:
    """SIGINT, SIGTERM and SIGHUP raise Stopped in the main thread, also when they land in a finaliser."""
    for s in _signals():
        signal.signal(s, _stop)
    sys.unraisablehook = _unraisable(sys.unraisablehook)


def main() -> None:
    """The console script: SIGTERM and SIGHUP stop the command like Ctrl-C; exit with run()'s code."""
    install_signal_handlers()
    # the objects the imports made live as long as the command: frozen, the garbage collector no
    # longer walks them (half of next's collection time, 0.02 s); the interpreter's last collection
    # would walk all of them again (0.08 s of the loop's commands), so what is left is frozen at exit
    # too (the other exit handlers, registered before, still run after it)
    gc.freeze()
    atexit.register(gc.freeze)
    try:
        code = run()
    except Stopped as exc:  # landed just outside the command's own handling (before or after it)
        code = _stopped(exc.signum)
    # the command's work is over (its files complete, or removed): a signal arriving from here on,
    # while the interpreter shuts down, would kill it with -signum; ignored, the exit code stands
    for s in _signals():
        signal.signal(s, signal.SIG_IGN)
    try:
        sys.stdout.flush()
    except BrokenPipeError:
        code = _closed_stdout()
    sys.exit(code)


if __name__ == "__main__":  # pragma: no cover
    main()
