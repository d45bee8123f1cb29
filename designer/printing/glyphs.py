"""The print id as strokes: a seven-segment alphabet that an FDM nozzle can engrave legibly.

A print id is engraved into a clamping block so that prints cannot be mixed up. Fonts need a font
file and a rasteriser; seven segments need neither, print cleanly at 1 mm strokes from a 0.4 mm
nozzle, and spell every digit and the letters below, which is all a print id needs.
"""

from __future__ import annotations

from ..errors import DesignerError

#: segments of a seven-segment cell: a top, b upper right, c lower right, d bottom, e lower left,
#: f upper left, g middle
SEGMENTS = {
    "0": "abcdef",
    "1": "bc",
    "2": "abdeg",
    "3": "abcdg",
    "4": "bcfg",
    "5": "acdfg",
    "6": "acdefg",
    "7": "abc",
    "8": "abcdefg",
    "9": "abcdfg",
    "A": "abcefg",
    "B": "cdefg",
    "C": "adef",
    "D": "bcdeg",
    "E": "adefg",
    "F": "aefg",
    "H": "bcefg",
    "L": "def",
    "P": "abefg",
    "U": "bcdef",
    "-": "g",
}
#: the characters a print id may hold
ALPHABET = "".join(SEGMENTS)


def check_print_id(text: str, name: str = "print_id") -> str:
    """`text` as a print id (upper case, 1-6 characters of `ALPHABET`); DesignerError naming `name`."""
    value = str(text).strip().upper()
    bad = sorted({ch for ch in value if ch not in SEGMENTS})
    if not 1 <= len(value) <= 6 or bad:
        raise DesignerError(
            f"{name}={text!r} cannot be engraved"
            + (f" (no stroke for {', '.join(repr(b) for b in bad)})" if bad else " (1 to 6 characters)"),
            f"use 1 to 6 of {ALPHABET}, e.g. P1",
        )
    return value


def strokes(text: str, width: float, height: float, stroke: float) -> list[tuple[float, float, float, float]]:
    """Rectangles (x0, y0, x1, y1) spelling `text` in cells of `width` x `height`, a gap of one
    stroke between cells, the text's lower left corner at the origin (x along the text)."""
    boxes = []
    h = height / 2
    for i, ch in enumerate(check_print_id(text, "text")):
        x = i * (width + stroke)
        spans = {
            "a": (x, height - stroke, x + width, height),
            "g": (x, h - stroke / 2, x + width, h + stroke / 2),
            "d": (x, 0.0, x + width, stroke),
            "f": (x, h, x + stroke, height),
            "e": (x, 0.0, x + stroke, h),
            "b": (x + width - stroke, h, x + width, height),
            "c": (x + width - stroke, 0.0, x + width, h),
        }
        boxes += [spans[s] for s in SEGMENTS[ch]]
    return boxes


def text_width(text: str, width: float, stroke: float) -> float:
    """The length of `text` spelled by `strokes`."""
    n = len(text)
    return n * width + (n - 1) * stroke
