"""A CSV rig log's header lines: a logger's '#' comments above the column names, and the sampling
rate they may state, checked against the time column (c scales with the time base, k does not: a
1 kHz log stamped at 500 Hz gave c twice the truth, and only a stated rate can tell).
"""

from __future__ import annotations

import re
from pathlib import Path

from ..errors import DesignerError

#: the most comment lines read above a CSV log's header row
MAX_COMMENT_LINES = 200
#: a sampling rate stated in a comment: "sample_rate: 1000 Hz", "Sampling rate (Hz) = 1000", "fs=1 kHz",
#: "rate_hz: 500" (a bare "rate" only with Hz, as a strain rate is a rate too)
_RATE_RE = re.compile(
    r"(?i)\b(?P<key>sampl(?:e|ing)[ _-]?(?:rate|frequency)|fs|rate)(?:[ _-]?\(?(?P<u1>k?hz)\)?)?"
    r"\s*[:=]?\s*(?P<value>[0-9]+(?:\.[0-9]*)?(?:e[+-]?[0-9]+)?)\s*(?P<u2>k?hz\b)?"
)
#: the stated and the logged rate may differ by this fraction (a clock's error is ppm; rounding of t)
RATE_TOLERANCE = 0.01


def comment_lines(p: Path) -> list[str]:
    """The lines starting with '#' above a CSV log's header row (a logger's metadata), as text."""
    out = []
    with open(p, encoding="utf-8-sig", errors="replace") as fh:
        for line in fh:
            if not line.lstrip().startswith("#") or len(out) >= MAX_COMMENT_LINES:
                break
            out.append(line.rstrip("\r\n"))
    return out


def stated_rate(comments: list[str]) -> tuple[float, str] | None:
    """The sampling rate (Hz) a log's comment lines state, with the line that states it; None if none."""
    for line in comments:
        for m in _RATE_RE.finditer(line):
            unit = (m["u1"] or m["u2"] or "").lower()
            if m["key"].lower() == "rate" and not unit:
                continue
            value = float(m["value"]) * (1e3 if unit == "khz" else 1.0)
            if value > 0:
                return value, line.strip()
    return None


def check_stated_rate(logged: float, comments: list[str], source: str) -> None:
    """Refuse a log whose header states a sampling rate its time column (sampled at `logged` Hz) does
    not have: one of them is wrong, and c scales with the time base (k does not)."""
    stated = stated_rate(comments)
    if stated is None or abs(stated[0] / logged - 1.0) <= RATE_TOLERANCE:
        return
    rate, line = stated
    raise DesignerError(
        f"{source}: the header states {rate:.6g} Hz ('{line[:80]}') but the time column 't' is sampled at "
        f"{logged:.6g} Hz; one of them is wrong, and c scales with the time base (k does not)",
        "correct the header or the t column (t = row index / the true rate), then identify again",
    )
