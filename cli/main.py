"""Entry point of the `designer` command: registers the sub-commands and turns errors into one line."""

from __future__ import annotations

import sys

import typer

from designer.errors import DesignerError

from . import cosim, design, export, plots, rig
from .common import flag_message

app = typer.Typer(
    help="Design 3D-printed TPU flexible joints: predict and choose stiffness and damping, export FMUs.",
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    add_completion=False,
    rich_markup_mode="rich",
)
design.register(app)
rig.register(app)
export.register(app)
cosim.register(app)
plots.register(app)


def main() -> None:
    """Run the command; bad input ends with one line on stderr and exit code 2, no traceback."""
    try:
        app()
    except DesignerError as exc:
        print(f"error: {flag_message(str(exc))}", file=sys.stderr)
        sys.exit(2)
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        sys.exit(130)
