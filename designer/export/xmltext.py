"""Edit a user's XML file as text, so every byte the edit does not touch stays as they wrote it.

A parser would re-serialise the whole file (quotes, attribute layout, line breaks inside tags); these
helpers change one start tag's attributes or insert a line, and the caller parses the result to check it.
"""

from __future__ import annotations

import re

from ..errors import DesignerError


def _outside_comments(text: str, matches: list[re.Match]) -> list[re.Match]:
    spans = [m.span() for m in re.finditer(r"<!--.*?-->", text, re.S)]
    return [m for m in matches if not any(a <= m.start() < b for a, b in spans)]


def find_one(
    text: str, tag: str, attr: str, value: str, *, whole: bool = False, nth: int | None = None
) -> re.Match:
    """The one `<tag ... attr="value" ...>` start tag (or, `whole`, element up to `</tag>`) in `text`.

    `nth`: of several such tags outside comments, the one at this index in document order (the
    caller located the element with a parser, e.g. a URDF's robot-level <joint> among the <joint>s
    that <transmission> blocks also name).

    Raises:
        DesignerError: none or several outside comments (without `nth`), or fewer than nth + 1.
    """
    start = rf"<{tag}\b[^>]*?\s{attr}\s*=\s*(['\"]){re.escape(value)}\1[^>]*>"
    found = _outside_comments(text, list(re.finditer(start, text, re.S)))
    if nth is None and len(found) != 1 or nth is not None and len(found) <= nth:
        raise DesignerError(
            f"cannot find <{tag} {attr}={value!r}> once in the file's text ({len(found)} found)",
            f"write it as one <{tag}> element outside comments",
        )
    m = found[0 if nth is None else nth]
    if not whole or m.group(0).endswith("/>"):
        return m
    return re.compile(start + rf".*?</{tag}\s*>", re.S).match(text, m.start())


def set_attributes(start_tag: str, values: dict[str, str]) -> str:
    """`start_tag` with each attribute in `values` set: replaced in place, or added before its end."""
    for attr, value in values.items():
        attr_re = re.compile(r"(\s" + re.escape(attr) + r"\s*=\s*)(['\"]).*?\2", re.S)
        m = attr_re.search(start_tag)
        if m:
            start_tag = (
                f"{start_tag[: m.start()]}{m.group(1)}{m.group(2)}{value}{m.group(2)}{start_tag[m.end() :]}"
            )
        else:
            end = re.search(r"\s*/?>$", start_tag).start()
            start_tag = f'{start_tag[:end]} {attr}="{value}"{start_tag[end:]}'
    return start_tag


def indent_before(text: str, pos: int) -> str:
    """The indentation of the line holding `pos`."""
    line = text[text.rfind("\n", 0, pos) + 1 : pos]
    return line[: len(line) - len(line.lstrip())]


def remove_attributes(start_tag: str, names: tuple[str, ...]) -> str:
    """`start_tag` without the attributes `names` (those it does not have are ignored)."""
    for attr in names:
        start_tag = re.sub(
            r"\s" + re.escape(attr) + r"\s*=\s*(['\"]).*?\1", "", start_tag, count=1, flags=re.S
        )
    return start_tag
