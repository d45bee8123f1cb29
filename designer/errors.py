"""The one exception type the CLI turns into a one-line message and exit code 2, and the checks of
argument types that raise it naming the Python argument (`designer.suggest(None)` must not end as
"'NoneType' object has no attribute 'axes'" from deep inside)."""

from __future__ import annotations

import numbers
import os
from pathlib import Path
from typing import Any


class DesignerError(ValueError):
    """Bad input or an impossible request: the message names the problem and the fix."""

    def __init__(self, problem: str, fix: str | None = None) -> None:
        self.problem = problem
        self.fix = fix
        super().__init__(f"{problem} ({fix})" if fix else problem)


def describe(value: Any) -> str:
    """What `value` is, for a message: "None", "a numpy array of shape (3, 6)", "a list", "a str"."""
    if value is None:
        return "None"
    shape = getattr(value, "shape", None)
    name = type(value).__name__
    if type(value).__module__.startswith("numpy") and shape is not None:
        return f"a numpy array of shape {tuple(shape)}" if name == "ndarray" else f"a numpy {name}"
    return f"{'an' if name[:1].lower() in 'aeiou' else 'a'} {name}"


def check_type(value: Any, types: type | tuple[type, ...], name: str, *, expected: str, fix: str) -> None:
    """Raise DesignerError naming the argument `name` unless `value` is one of `types`.

    Raises:
        DesignerError: "`name` is <what it is>, not `expected`" with `fix`.
    """
    if not isinstance(value, types):
        raise DesignerError(f"{name} is {describe(value)}, not {expected}", fix)


def path_argument(value: Any, name: str, *, what: str = "a file") -> Path:
    """`value` (a str or os.PathLike) as a Path.

    Raises:
        DesignerError: naming the argument `name` when `value` is anything else (None, a number...).
    """
    fix = f"give {name} as a str or pathlib.Path of {what}"
    check_type(value, (str, os.PathLike), name, expected="a path", fix=fix)
    return Path(value)


def names_argument(value: Any, name: str, *, example: str) -> list[str]:
    """`value` (a str, or a list or tuple of str) as a list of names, e.g. responses or axes.

    Raises:
        DesignerError: naming the argument `name` when `value` is a number, an array, a dict...
    """
    if isinstance(value, str):
        return [value]
    fix = f"give {name} as a list of names, e.g. {name}={example}"
    check_type(value, (list, tuple), name, expected="a list of names", fix=fix)
    for item in value:
        check_type(item, str, f"{name}[{value.index(item)}]", expected="a name (str)", fix=fix)
    return list(value)


def number_argument(value: Any, name: str, *, example: str = "0.8") -> float:
    """`value` (a real number, not a bool; numpy scalars too) as a float.

    Raises:
        DesignerError: naming the argument `name` when `value` is a list, an array, a str, None...
    """
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        fix = f"give {name} as one number, e.g. {example}"
        raise DesignerError(f"{name} is {describe(value)}, not a number", fix)
    return float(value)
