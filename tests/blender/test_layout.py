"""The Blender shell's layout: one job per module, data flowing one way (no import circles)."""

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[2] / "lightfade_addon"


def _module(path):
    rel = path.relative_to(PACKAGE.parent).with_suffix("")
    parts = list(rel.parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path):
    """Modules of the package that ``path`` imports (relative imports resolved)."""
    name = _module(path)
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.level:
            base = package.rsplit(".", node.level - 1)[0] if node.level > 1 else package
            target = f"{base}.{node.module}" if node.module else base
            if node.module:                     # ``from . import x`` names modules only
                found.add(target)
            found.update(f"{target}.{a.name}" for a in node.names)
    return found


def graph():
    paths = {_module(p): p for p in PACKAGE.rglob("*.py")}
    return {m: {t for t in _imports(p) if t in paths and t != m} for m, p in paths.items()}


def test_no_import_circles_in_the_shell():
    g = {m: t for m, t in graph().items() if m.startswith("lightfade_addon.blender")}
    g = {m: {x for x in t if x in g} for m, t in g.items()}
    state = {}

    def visit(m, stack):
        state[m] = "open"
        for t in g[m]:
            if state.get(t) == "open":
                raise AssertionError(" -> ".join(stack[stack.index(t):] + [t]))
            if t not in state:
                visit(t, stack + [t])
        state[m] = "done"

    for m in g:
        if m not in state:
            visit(m, [m])


def test_the_graph_sees_imports():
    g = graph()
    assert "lightfade_addon.blender.runtime" in g["lightfade_addon.blender.apply"]
    assert "lightfade_addon.core.aging" in g["lightfade_addon.blender.runtime"]


def test_shell_modules_are_small():
    big = [p.name for p in (PACKAGE / "blender").rglob("*.py")
           if len(p.read_text().splitlines()) > 400 and p.name != "bake.py"]
    assert not big
