"""Entry point of the `designer` command: registers the sub-commands and turns errors into one line."""

from __future__ import annotations

import os
import sys

#: fit, predict and suggest do small dense algebra: OpenBLAS's thread pool costs more to start
#: (~50 ms) than it saves; set before numpy loads, and only when the user has not chosen
DESIGN_COMMANDS = ("fit", "predict", "suggest")
_DESIGN = sys.argv[1:2] != [] and sys.argv[1] in DESIGN_COMMANDS
if _DESIGN:
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import typer  # noqa: E402

from designer.errors import DesignerError  # noqa: E402

from . import cosim, design, export, plots, rig, sweep  # noqa: E402
from .common import flag_message  # noqa: E402

SETTINGS = dict(
    help="Design 3D-printed TPU flexible joints: predict and choose stiffness and damping, export FMUs.",
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    add_completion=False,
    rich_markup_mode="rich",
)
app = typer.Typer(**SETTINGS)
#: typer builds the click tree of every registered command on each call: a design command gets an
#: app with only fit, predict and suggest (the help of `designer` itself still lists everything)
design_app = typer.Typer(**SETTINGS)
design.register(design_app)
design.register(app)
rig.register(app)
export.register(app)
cosim.register(app)
plots.register(app)
sweep.register(app)


def main() -> None:
    """Run the command; bad input ends with one line on stderr and exit code 2, no traceback."""
    try:
        (design_app if _DESIGN else app)(prog_name="designer")
    except DesignerError as exc:
        print(f"error: {flag_message(str(exc))}", file=sys.stderr)
        sys.exit(2)
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        sys.exit(130)
