"""The built extension zip installs into a fresh repository and enables as bl_ext.<repo>.lightfade.

Runs in a subprocess with BLENDER_USER_EXTENSIONS / BLENDER_USER_CONFIG /
BLENDER_USER_SCRIPTS pointing into a temporary directory: installing an extension also
installs its wheels into the *user* extensions' site-packages, which must not leak into
the developer's Blender or into this test process.
"""

import json
import os
import subprocess
import sys
import tomllib
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

INSTALL = r"""
import json, sys
import bpy
import addon_utils
zip_path, repo_dir, out = sys.argv[1:4]
prefs = bpy.context.preferences.extensions
repo = prefs.repos.new(name="LightFade Test", module="lftest", custom_directory=repo_dir, source="USER")
ret = bpy.ops.extensions.package_install_files(filepath=zip_path, repo=repo.module, enable_on_install=True)
module = "bl_ext." + repo.module + ".lightfade"
enabled = addon_utils.check(module)
ops = sorted(name for name in dir(bpy.ops.lightfade))
scene_props = hasattr(bpy.context.scene, "lightfade") and bpy.context.scene.lightfade.bake_resolution
pkg = sys.modules[module]
bpy.ops.extensions.package_uninstall(repo_index=list(prefs.repos).index(repo), pkg_id="lightfade")
after_uninstall = addon_utils.check(module)
prefs.repos.remove(repo)
json.dump({"ret": sorted(ret), "enabled": enabled, "ops": ops, "scene_props": scene_props,
           "file": pkg.__file__, "after_uninstall": after_uninstall}, open(out, "w"))
"""


def _build(tmp_path):
    proc = subprocess.run(
        [sys.executable, str(ROOT / "tools" / "build_extension.py"), "--platform", "linux-x64",
         "--out", str(tmp_path / "dist")],
        cwd=ROOT, capture_output=True, text=True,
    )
    if proc.returncode != 0 and "pip download" in proc.stdout + proc.stderr and "valid" not in proc.stdout:
        pytest.skip(f"could not download the wheels (network?): {proc.stderr[-300:]}")
    assert proc.returncode == 0, proc.stdout + proc.stderr
    return tmp_path / "dist" / "lightfade-0.1.0-linux-x64.zip"


def test_zip_layout(tmp_path):
    zpath = _build(tmp_path)
    names = zipfile.ZipFile(zpath).namelist()
    assert "blender_manifest.toml" in names and "__init__.py" in names
    assert any(n.startswith("blender/operators/") for n in names)
    assert not any("__pycache__" in n or n.endswith(".pyc") or n.startswith("tests/") for n in names)
    manifest = tomllib.loads(zipfile.ZipFile(zpath).read("blender_manifest.toml").decode())
    assert manifest["platforms"] == ["linux-x64"]
    assert all(w.startswith("./wheels/") and w[2:] in names for w in manifest["wheels"])
    assert not any("win_amd64" in w or "macosx" in w or "numpy" in w for w in manifest["wheels"])
    assert {w.split("/")[-1].split("-")[0] for w in manifest["wheels"]} == {
        "colour_science", "scipy", "typing_extensions"}


def test_install_enables_as_extension(tmp_path):
    zpath = _build(tmp_path)
    env = dict(os.environ,
               BLENDER_USER_EXTENSIONS=str(tmp_path / "user_ext"),
               BLENDER_USER_CONFIG=str(tmp_path / "user_config"),
               BLENDER_USER_SCRIPTS=str(tmp_path / "user_scripts"))
    out = tmp_path / "result.json"
    repo_dir = tmp_path / "repo"
    proc = subprocess.run([sys.executable, "-c", INSTALL, str(zpath), str(repo_dir), str(out)],
                          cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    result = json.loads(out.read_text())
    assert result["ret"] == ["FINISHED"]
    assert result["enabled"] == [True, True], result
    assert "bake_exposure" in result["ops"]
    assert result["scene_props"] == 1024
    assert Path(result["file"]).is_relative_to(repo_dir)
    assert result["after_uninstall"] == [False, False]
    assert not (repo_dir / "lightfade").exists()
