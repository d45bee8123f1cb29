"""README is navigable: its contents list names every section in order, and every in-page link
(`[text](#anchor)`) lands on a heading, with anchors made as GitHub makes them."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"


def github_anchor(heading: str, seen: dict[str, int]) -> str:
    """The anchor GitHub gives a heading (github-slugger): lower case, every character but letters,
    digits, `_`, `-` and spaces dropped, spaces made `-`; a repeated anchor gets `-1`, `-2`, ..."""
    slug = re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")
    count = seen.get(slug, 0)
    seen[slug] = count + 1
    return slug if count == 0 else f"{slug}-{count}"


def headings(text: str) -> list[tuple[int, str, str]]:
    """(level, title, anchor) of every heading outside code blocks."""
    outside = re.sub(r"```.*?```", "", text, flags=re.S)
    seen: dict[str, int] = {}
    found = re.findall(r"^(#{1,6}) (.+?)\s*$", outside, flags=re.M)
    return [(len(marks), title, github_anchor(title, seen)) for marks, title in found]


def contents(text: str) -> list[tuple[int, str]]:
    """(indent, anchor) of each entry of the list under `## Contents`."""
    block = text.split("\n## Contents\n", 1)[1].split("\n## ", 1)[0]
    return [(len(m.group(1)), m.group(2)) for m in re.finditer(r"^( *)- \[[^\]]+\]\(#([^)]+)\)", block, re.M)]


def test_anchor_rule():
    seen: dict[str, int] = {}
    assert github_anchor("Designing a joint: `fit`, `predict`, `suggest`", seen) == (
        "designing-a-joint-fit-predict-suggest"
    )
    assert (
        github_anchor("Exporting a joint (FMU, Modelica, MJCF)", seen)
        == "exporting-a-joint-fmu-modelica-mjcf"
    )
    assert github_anchor("From the designs: `identify --runs`", seen) == "from-the-designs-identify---runs"
    assert (
        github_anchor("Exporting a joint (FMU, Modelica, MJCF)", seen)
        == "exporting-a-joint-fmu-modelica-mjcf-1"
    )


def test_contents_lists_every_section_in_order():
    text = README.read_text()
    sections = [
        (level, anchor) for level, _, anchor in headings(text) if level in (2, 3) and anchor != "contents"
    ]
    listed = contents(text)
    assert [anchor for _, anchor in listed] == [anchor for _, anchor in sections]
    # a subsection is indented under its section
    assert [indent > 0 for indent, _ in listed] == [level == 3 for level, _ in sections]


def test_every_in_page_link_resolves():
    text = README.read_text()
    anchors = {anchor for _, _, anchor in headings(text)}
    links = re.findall(r"\]\(#([^)]+)\)", text)
    assert len(links) >= 15
    assert sorted(set(links) - anchors) == []
