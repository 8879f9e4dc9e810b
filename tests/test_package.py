"""The package's layering: core never touches Blender, imports run one way (no import
circles, in the whole package and so in the Blender shell), the shell's modules are
small, the CLI works."""

import ast
import functools
import json
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "lightfade_addon"
BLENDER_MODULES = {"bpy", "mathutils", "bmesh", "gpu", "bl_math", "idprop"}


def _module_name(path, root):
    parts = list(path.relative_to(root).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


@functools.lru_cache(maxsize=None)
def import_graph(package=PACKAGE):
    """``{module: {modules it imports}}`` over the package's relative imports.

    Imports inside functions count: a circle through a deferred import is still a
    circle of dependencies, only hidden from the interpreter.
    """
    paths = {_module_name(p, package.parent): p for p in package.rglob("*.py")}
    graph = {}
    for name, path in paths.items():
        here = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
        deps = set()
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.ImportFrom) and node.level:
                base = ".".join(here[:len(here) - node.level + 1]
                                + ([node.module] if node.module else []))
                for alias in node.names:
                    # ``from .pkg import mod`` needs the module; ``from .pkg import name``
                    # needs the package's __init__ (where the name is defined)
                    sub = f"{base}.{alias.name}"
                    target = sub if sub in paths else base
                    if target in paths and target != name:
                        deps.add(target)
        graph[name] = deps
    return graph


def circles(graph):
    """The strongly connected components of more than one module (Tarjan)."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph[v]:
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
                found.append(sorted(component))

    for v in graph:
        if v not in index:
            visit(v)
    return found


def test_core_never_imports_blender_modules():
    offenders = []
    for path in (PACKAGE / "core").rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            names = []
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                names = [node.module]
            offenders += [f"{path.name}: {n}" for n in names if n.split(".")[0] in BLENDER_MODULES]
    assert offenders == []


class TestImportCircles:
    def test_the_checker_finds_a_circle(self, tmp_path):
        pkg = tmp_path / "lightfade_addon"
        (pkg / "sub").mkdir(parents=True)
        (pkg / "__init__.py").write_text("")
        (pkg / "a.py").write_text("def f():\n    from .sub import b\n")
        (pkg / "sub" / "__init__.py").write_text("")
        (pkg / "sub" / "b.py").write_text("from ..a import f\n")
        (pkg / "c.py").write_text("from . import a\n")
        assert circles(import_graph(pkg)) == [["lightfade_addon.a", "lightfade_addon.sub.b"]]

    def test_none_in_the_package(self):
        graph = import_graph()
        assert "lightfade_addon.blender.properties" in graph        # the whole package
        assert circles(graph) == []

    def test_the_graph_sees_imports(self):
        graph = import_graph()
        assert "lightfade_addon.blender.aging.runtime" in graph["lightfade_addon.blender.aging.apply"]
        assert "lightfade_addon.core.aging.ager" in graph["lightfade_addon.blender.aging.runtime"]
        assert "lightfade_addon.blender.bake" in graph["lightfade_addon.pipeline.steps"]

    def test_commands_never_import_the_cli(self):
        graph = import_graph()
        assert "lightfade_addon.commands" in graph["lightfade_addon.cli"]
        assert not any("lightfade_addon.cli" in deps for m, deps in graph.items()
                       if m.startswith("lightfade_addon.commands"))


def test_shell_modules_are_small():
    """One job per module in the Blender shell."""
    big = [p.name for p in (PACKAGE / "blender").rglob("*.py")
           if len(p.read_text().splitlines()) > 400 and p.name != "bake.py"]
    assert not big


def test_scene_scripts_are_small():
    """One job per module in the scripted demo scenes too."""
    big = [p.name for p in (ROOT / "scenes").glob("*.py") if len(p.read_text().splitlines()) > 400]
    assert not big


#: A process without Blender: imports the package, its core and the command line, and
#: runs ``lightfade info``; prints the Blender modules loaded before and after, then the
#: command's status and output.
WITHOUT_BLENDER = """
import contextlib, io, json, sys
import lightfade_addon, lightfade_addon.cli, lightfade_addon.core
import lightfade_addon.core.colour.colorimetry, lightfade_addon.core.fading.colourants
import lightfade_addon.core.fading.spectra

def blender():
    return sorted(m for m in sys.modules if m.split('.')[0] in {'bpy', 'mathutils', 'bmesh'})

imported = blender()
out = io.StringIO()
with contextlib.redirect_stdout(out):
    status = lightfade_addon.cli.main(["info"])
print(json.dumps([imported, blender(), status, out.getvalue()]))
"""


def real_processes(jobs, folder):
    """The module's two real processes: :data:`WITHOUT_BLENDER` and ``python -m
    lightfade_addon no-such-command``.  An early job (tests/conftest.py): they run beside
    the tests before these."""
    return {name: jobs.run([sys.executable, *args], cwd=ROOT, timeout=120) for name, args in (
        ("without blender", ["-c", WITHOUT_BLENDER]),
        ("unknown command", ["-m", "lightfade_addon", "no-such-command"]))}


EARLY = {"processes": real_processes}


def test_package_and_core_import_without_loading_bpy(early):
    """...and ``lightfade info`` runs without Blender (and loads none of it)."""
    proc = early("processes")["without blender"]
    assert proc.returncode == 0, proc.stderr
    imported, after_info, status, out = json.loads(proc.stdout)
    assert imported == [] and after_info == []
    assert status == 0
    assert "simulate defaults: layers=" in out
    assert "OpenImageIO 3." in out


class TestCommandLine:
    def test_unknown_command_is_one_line_naming_it_and_the_valid_ones(self, early):
        # a real process: the program name comes from ``python -m lightfade_addon``
        out = early("processes")["unknown command"]
        assert (out.returncode, out.stdout) == (2, "")
        [line] = out.stderr.splitlines()
        assert line.startswith("lightfade: error: ") and "'no-such-command'" in line
        assert "age-image" in line and "info" in line
        prog = f"{pathlib.Path(sys.executable).name} -m lightfade_addon"
        assert f"(see: {prog} --help)" in line

    def test_every_command_module_is_listed(self):
        from lightfade_addon import cli
        from lightfade_addon.commands import discover

        modules = discover()
        names = [m.NAME for m in modules]
        assert {"age-image", "info"} <= set(names) and names == sorted(names)
        choices = cli.make_parser()._subparsers._group_actions[0].choices
        assert list(choices) == names

    def test_help_without_a_command(self, capsys):
        from lightfade_addon import cli

        assert cli.main([]) == 0
        assert "age-image" in capsys.readouterr().out
