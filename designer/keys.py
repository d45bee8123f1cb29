"""Checking the keys of a user's table (TOML, JSON): unknown keys are named with the closest valid one."""

from __future__ import annotations

import difflib
from collections.abc import Iterable, Mapping
from typing import Any

from .errors import DesignerError


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
