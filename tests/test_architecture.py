"""The package's shape, as README's ARCHITECTURE section states it: imports run one way down the layers
of its table, no import cycle, no private name imported from another module, no module over 600 lines.

The graph is read from the installed package's source with `ast` (every import statement, at module
level or inside a function, except those under `if TYPE_CHECKING:`, which never run).
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import designer_cli
import pytest

import designer

README = Path(__file__).resolve().parents[1] / "README.md"
MAX_LINES = 600
#: packages of designer/ that are layers of their own; joint.py and mass.py form the `joint` layer,
#: the other top-level modules the `foundation`
SUBPACKAGES = ("study", "model", "design", "plots", "rig", "printing", "export", "cosim", "sweep", "validate")


def _modules() -> dict[str, Path]:
    """Dotted module name -> source file, for designer and designer_cli as installed."""
    out = {}
    for pkg in (designer, designer_cli):
        root = Path(pkg.__file__).parent
        for path in root.rglob("*.py"):
            parts = [pkg.__name__, *path.relative_to(root).with_suffix("").parts]
            if parts[-1] == "__init__":
                parts = parts[:-1]
            out[".".join(parts)] = path
    return out


MODULES = _modules()


def _type_checking_lines(tree: ast.Module) -> set[int]:
    lines: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            for child in node.body:
                lines.update(range(child.lineno, (child.end_lineno or child.lineno) + 1))
    return lines


def _imports(name: str, path: Path) -> list[tuple[str, str | None]]:
    """(imported module, imported name or None) of every import statement of a module that runs."""
    tree = ast.parse(path.read_text())
    skip = _type_checking_lines(tree)
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    out: list[tuple[str, str | None]] = []
    for node in ast.walk(tree):
        if getattr(node, "lineno", None) in skip:
            continue
        if isinstance(node, ast.Import):
            out += [(a.name, None) for a in node.names if a.name in MODULES]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - (node.level - 1)]
                source = ".".join(base + ([node.module] if node.module else []))
            else:
                source = node.module or ""
            for a in node.names:
                if f"{source}.{a.name}" in MODULES:  # from package import module
                    out.append((f"{source}.{a.name}", None))
                elif source in MODULES:
                    out.append((source, a.name))
    return out


GRAPH = {name: _imports(name, path) for name, path in MODULES.items()}


def layer_of(module: str) -> str:
    """The row of README's table a module belongs to."""
    parts = module.split(".")
    if parts[0] == "designer_cli":
        return "cli"
    if len(parts) > 1 and parts[1] in SUBPACKAGES:
        return parts[1]
    if len(parts) > 1 and parts[1] in ("joint", "mass"):
        return "joint"
    return "foundation"


def readme_rules() -> dict[str, set[str]]:
    """README's ARCHITECTURE table: layer -> the layers it may import (besides itself)."""
    text = README.read_text()
    section = text[text.index("## Architecture") :]
    end = section.find("\n## ", 5)
    section = section if end < 0 else section[:end]
    rules = {}
    for line in section.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) != 3 or not cells[0].startswith("`"):
            continue
        layer = re.match(r"`([a-z_]+)`", cells[0]).group(1)
        rules[layer] = set(re.findall(r"`([a-z_]+)`", cells[2]))
    return rules


def test_readme_table_names_every_layer_once():
    rules = readme_rules()
    layers = {layer_of(m) for m in MODULES}
    assert set(rules) == layers, (sorted(rules), sorted(layers))
    for layer, allowed in rules.items():
        assert allowed <= set(rules), (layer, allowed - set(rules))


def test_imports_follow_the_readme_table():
    rules = readme_rules()
    broken = [
        f"{src} imports {dst} ({layer_of(src)} may import {sorted(rules[layer_of(src)]) or 'nothing'})"
        for src, imports in GRAPH.items()
        for dst, _ in imports
        if layer_of(dst) != layer_of(src) and layer_of(dst) not in rules[layer_of(src)]
    ]
    assert not broken, "\n".join(broken)


def test_no_import_cycle():
    """Tarjan's strongly connected components of the module graph: each must be one module."""
    edges = {m: {d for d, _ in GRAPH[m] if d != m} for m in MODULES}
    # a package's __init__ importing its own modules is how a package exposes them, and Python
    # runs that __init__ before any of its modules: not an edge back from the module
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    cycles: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in edges[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                cycles.append(sorted(component))

    for v in MODULES:
        if v not in index:
            visit(v)
    assert not cycles, cycles


def test_no_private_name_is_imported_from_another_module():
    private = [
        f"{src} imports {name} from {dst}"
        for src, imports in GRAPH.items()
        for dst, name in imports
        if name and name.startswith("_") and not name.startswith("__")
    ]
    assert not private, "\n".join(private)


@pytest.mark.parametrize("module", sorted(MODULES))
def test_module_is_under_600_lines(module):
    n = len(MODULES[module].read_text().splitlines())
    assert n < MAX_LINES, f"{module} has {n} lines: split it by what its parts do"


def test_the_checker_sees_a_cycle_and_a_private_import(tmp_path):
    """The graph reader on a tiny package of two modules that import each other's private names."""
    a, b = tmp_path / "_probe_a.py", tmp_path / "_probe_b.py"
    a.write_text("from ._probe_b import _hidden\n")
    b.write_text(
        "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    import designer.joint\n"
        "def f():\n    from ._probe_a import g\n"
    )
    MODULES.update({"designer._probe_a": a, "designer._probe_b": b})
    try:
        assert _imports("designer._probe_a", a) == [("designer._probe_b", "_hidden")]
        assert _imports("designer._probe_b", b) == [("designer._probe_a", "g")]
    finally:
        del MODULES["designer._probe_a"], MODULES["designer._probe_b"]


def test_only_the_scenario_loader_branches_on_a_kind():
    """Robot and rig scenarios (and FMU modes, value types, case types) dispatch through their types:
    the TOML loader decides the scenario's type, and nothing else writes `kind ==`."""
    branching = sorted(
        f"{name} line {i}"
        for name, path in MODULES.items()
        for i, line in enumerate(path.read_text().splitlines(), 1)
        if re.search(r"\bkind\s*[!=]=", line)
    )
    assert all(b.startswith("designer.cosim.scenario_file ") for b in branching), branching
