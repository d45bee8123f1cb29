"""Users' tables (TOML, JSON): reading a TOML file, and unknown keys named with the closest valid one."""

from __future__ import annotations

import difflib
import sys
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

if sys.version_info >= (3, 11):
    import tomllib
else:
    import tomli as tomllib

from .errors import DesignerError, path_argument


def check_keys(table: Mapping[str, Any], allowed: Iterable[str], *, where: str) -> None:
    """Raise DesignerError for the first key of `table` not in `allowed`, suggesting the nearest one.

    `where` names the table for the message, e.g. "[simulation] of arm.toml".

    Raises:
        DesignerError: "unknown key 'duraton' in [simulation] of arm.toml; did you mean 'duration'?"
    """
    allowed = list(allowed)
    for key in table:
        if key in allowed:
            continue
        close = difflib.get_close_matches(str(key), allowed, n=1, cutoff=0.6)
        hint = f"did you mean '{close[0]}'?" if close else f"valid keys: {', '.join(allowed)}"
        raise DesignerError(f"unknown key '{key}' in {where}", hint)


def read_toml(path: str | Path, *, what: str) -> tuple[Path, dict[str, Any]]:
    """The absolute path and the contents of the TOML file `path`, a `what` ("scenario", "sweep").

    Raises:
        DesignerError: the file does not exist or is not valid TOML.
    """
    path = path_argument(path, "path", what=f"a .toml {what} file").resolve()
    if not path.is_file():
        raise DesignerError(f"{what} file {path} does not exist", f"give the path of a .toml {what} file")
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8-sig"))  # a BOM (Windows editors) is fine
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise DesignerError(f"{path.name} is not valid TOML: {exc}", "fix the syntax") from None
    except RecursionError:
        data = None
    if data is None or nesting(data) > MAX_NESTING:
        raise DesignerError(
            f"{path.name} nests tables or arrays more than {MAX_NESTING} deep",
            f"a {what} file nests a few levels (see the README's {what} format)",
        )
    return path, data


#: the deepest nesting of tables and arrays a scenario or sweep file may have (they use 4 or 5)
MAX_NESTING = 16


def nesting(value: Any) -> int:
    """How deep tables and arrays nest in `value` (parsed TOML), walked without recursion."""
    deepest, stack = 0, [(value, 0)]
    while stack:
        v, depth = stack.pop()
        deepest = max(deepest, depth)
        if depth > MAX_NESTING:
            break
        children = v.values() if isinstance(v, dict) else v if isinstance(v, list) else ()
        stack.extend((c, depth + 1) for c in children)
    return deepest
