"""What every command shares: JSON output, rich console, progress bars shown only on a terminal."""

from __future__ import annotations

import contextlib
import json
import math
import re
import sys
from collections.abc import Callable, Iterator
from typing import Any

from rich.console import Console

# piped output is not cut at rich's 80-column default: numbers must never be truncated
console = Console(highlight=False, width=None if sys.stdout.isatty() else 120)
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


@contextlib.contextmanager
def progress(description: str, enabled: bool = True) -> Iterator[Callable[[float], None]]:
    """Yield a callback taking the fraction done (0..1); draws a bar only when stderr is a terminal."""
    if not (enabled and err_console.is_terminal):
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


#: Python arguments named in library messages, and the flags the CLI spells them with: the library
#: speaks to Python callers, the command line to its users, so the one error path translates
FLAGS: tuple[tuple[str, str], ...] = (
    (r"\bsource_only=True\b", "--source-only"),
    (r"\bfmi_version=", "--fmi "),
    (r"\binterface=", "--interface "),
    (r"\ballow_extrapolation=True\b", "--allow-extrapolation"),
    (r"\btop=", "--top "),
    (r"\bk= and/or c=", "--k and/or --c"),
    (r"\btargets=\{'k': 0\.8\}", "--target k=0.8"),
    # export mjcf/urdf/sdf/modelica/ssp
    (r"\binto=", "--into "),
    (r"\bjoint_name=", "--joint "),
    (r"\baxis=(?='\w+'(, or| is | does ))", "--use-axis "),
    (r"\bform=(?='\w*' is not a form)", "--form "),
    (r"\bmsl=", "--msl "),
    (r"\brest=(?=\S+ is for exports into)", "--rest "),
    (r"\bmotor_inertia=", "--motor-inertia "),
    (r"\bmotor_bandwidth=", "--motor-bandwidth "),
)


def flag_message(text: str) -> str:
    """A library message with its Python argument names replaced by the CLI's flags."""
    for pattern, flag in FLAGS:
        text = re.sub(pattern, flag, text)
    return text
