"""The package's layering: core never touches Blender; imports work without bpy."""

import ast
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]
BLENDER_MODULES = {"bpy", "mathutils", "bmesh", "gpu", "bl_math", "idprop"}


def test_core_never_imports_blender_modules():
    offenders = []
    for path in (ROOT / "lightfade_addon" / "core").rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            names = []
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                names = [node.module]
            offenders += [f"{path.name}: {n}" for n in names if n.split(".")[0] in BLENDER_MODULES]
    assert offenders == []


def _python(code):
    return subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True,
                          text=True, timeout=120)


def test_package_and_core_import_without_loading_bpy():
    out = _python("import sys, lightfade_addon, lightfade_addon.core, lightfade_addon.cli;"
                  "print(sorted(m for m in sys.modules if m.split('.')[0] in "
                  "{'bpy', 'mathutils', 'bmesh'}))")
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "[]"


def test_command_line_runs_without_blender():
    out = subprocess.run([sys.executable, "-m", "lightfade_addon", "info"], cwd=ROOT,
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert "simulate defaults" in out.stdout


def test_unknown_command_is_an_error():
    out = subprocess.run([sys.executable, "-m", "lightfade_addon", "no-such-command"],
                         cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert out.returncode != 0
