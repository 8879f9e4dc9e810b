"""The zip built by the documented command installs, enables, bakes and ages in this Blender.

The zip is built once per session with ``tools/build_extension.py --platform linux-x64``
(Blender's own builder), then installed and aged in a subprocess: both run as an early job
(tests/conftest.py), beside the tests before these.  The subprocess runs with
BLENDER_USER_EXTENSIONS / BLENDER_USER_CONFIG / BLENDER_USER_SCRIPTS (and the grid cache)
in a temporary directory: installing an extension
also installs its wheels into the user extensions' site-packages, which must not leak into
the developer's Blender or into this test process.  The subprocess installs the zip into a
fresh repository with ``bpy.ops.extensions.package_install_files``, puts the site-packages
Blender installed the zip's wheels into ahead of this venv's (in Blender they are the only
colour and scipy there are), enables the add-on, then bakes and ages a small scene through
the INSTALLED package (``bl_ext.lftest.lightfade``), never through the checkout.

The bpy 4.2 module segfaults at process exit (-11) once a PropertyGroup with an ``update=``
callback was registered; the subprocess therefore writes its result file as its last act and
the test reads that file.  A -11 is accepted only on bpy < 5.0 and only with a complete
result; any other non-zero exit, or no result, fails.
"""

import json
import os
import sys
import tomllib
import zipfile
from pathlib import Path
from types import SimpleNamespace

import bpy
import pytest

ROOT = Path(__file__).resolve().parents[2]
PLATFORM = "linux-x64"
EXIT_SEGFAULT_OK = bpy.app.version < (5, 0, 0)

INSTALL_AND_AGE = r"""
import json, sys, traceback
zip_path, repo_dir, user_ext, out = sys.argv[1:5]
result = {}
try:
    import bpy, addon_utils
    import numpy as np
    result["bpy"] = list(bpy.app.version)
    bpy.ops.wm.read_factory_settings(use_empty=True)  # no default cube over the plane
    prefs = bpy.context.preferences.extensions
    repo = prefs.repos.new(name="LightFade Test", module="lftest", custom_directory=repo_dir, source="USER")
    result["install"] = sorted(bpy.ops.extensions.package_install_files(
        filepath=zip_path, repo=repo.module, enable_on_install=False))
    # Enabling installs the wheels that fit this Python into the user extensions'
    # site-packages: look there first, as a real Blender (no colour, no scipy) does.
    import os
    site = os.path.join(user_ext, ".local", "lib", "python%d.%d" % sys.version_info[:2], "site-packages")
    os.makedirs(site, exist_ok=True)
    sys.path.insert(0, site)
    result["imported_before"] = sorted({"colour", "scipy"} & set(sys.modules))
    module = "bl_ext.lftest.lightfade"
    def fail(ex):
        raise ex
    addon_utils.enable(module, default_set=True, handle_error=fail)
    result["enabled"] = list(addon_utils.check(module))
    import importlib
    api = importlib.import_module(module + ".api")
    import colour, scipy
    result["files"] = {"package": sys.modules[module].__file__, "api": api.__file__,
                       "colour": colour.__file__, "scipy": scipy.__file__}
    result["versions"] = {"colour": colour.__version__, "scipy": scipy.__version__}
    # What the README tells users to look at: the version Blender shows in Preferences
    # (from the installed manifest) and the package's own __version__.
    result["shown_version"] = [".".join(map(str, addon_utils.module_bl_info(m)["version"]))
                               for m in addon_utils.modules() if m.__name__.endswith(".lightfade")]
    result["package_version"] = sys.modules[module].__version__
    result["checkout_imported"] = "lightfade_addon" in sys.modules

    # A 2 m plane with a 64 px magenta image, a 0.6 m box standing on it, a sun overhead.
    bpy.ops.mesh.primitive_plane_add(size=2.0)
    plane = bpy.context.active_object
    mat = bpy.data.materials.new("Poster")
    if bpy.app.version < (5, 0, 0):  # node trees are always on from Blender 5.0
        mat.use_nodes = True
    image = bpy.data.images.new("PosterAlbedo", 64, 64)
    px = np.empty((64, 64, 4), np.float32)
    px[...] = (0.9, 0.15, 0.6, 1.0)
    image.pixels.foreach_set(px.ravel())
    image.pack()
    original = np.empty(64 * 64 * 4, np.float32)
    image.pixels.foreach_get(original)
    tex = mat.node_tree.nodes.new("ShaderNodeTexImage")
    tex.image = image
    mat.node_tree.links.new(tex.outputs["Color"], mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"])
    plane.data.materials.append(mat)
    mat.lightfade.enabled = True
    bpy.ops.mesh.primitive_cube_add(size=0.6, location=(0.4, 0.4, 0.3))
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy, sun.data.angle = 20.0, 0.0
    bpy.context.scene.collection.objects.link(sun)
    scene = bpy.context.scene
    api.bake(scene, objects=[plane], resolution=64, samples=4, margin=2)
    api.age_scene(scene, years=2)
    aged_images = list(api.apply_aging(scene).values())      # real aged pixels
    result["aged_images"] = [im.name for im in aged_images]
    aged = aged_images[0]

    def linear_rgb(img):
        a = np.empty(len(img.pixels), np.float32)
        img.pixels.foreach_get(a)
        a = a.reshape(img.size[1], img.size[0], img.channels)[..., :3].astype(np.float64)
        if img.colorspace_settings.name == "sRGB" and not img.is_float:
            a = np.where(a <= 0.04045, a / 12.92, ((a + 0.055) / 1.055) ** 2.4)
        return a

    now = np.empty_like(original)
    image.pixels.foreach_get(now)
    result["original_untouched"] = bool(np.array_equal(now, original)) and image.size[:] == (64, 64)
    diff = np.abs(linear_rgb(aged) - linear_rgb(image))
    # The box covers u, v in [0.55, 0.85] (texels 35-54): texels 7 deep inside are in
    # shadow (the 4-sample bake leaves < 0.1 lux there, 1.4 lux 5 texels in; the sun gives
    # 14,000), texels with u, v < 0.45 in the sun.
    result["shadow_change"] = float(diff[42:50, 42:50].max())
    result["lit_change"] = float(diff[4:26, 4:26].mean())
    result["lit_min_change"] = float(diff[4:26, 4:26].max(axis=-1).min())

    ret = bpy.ops.extensions.package_uninstall(repo_index=list(prefs.repos).index(repo), pkg_id="lightfade")
    result["uninstall"] = sorted(ret)
    result["after_uninstall"] = list(addon_utils.check(module))
except Exception:
    result["error"] = traceback.format_exc()
with open(out, "w") as fh:
    json.dump(result, fh)
sys.stdout.flush()
"""


def build_zip(jobs, out):
    """The zip written by the documented command (README, docs/blender.md) into ``out``."""
    proc = jobs.run([sys.executable, str(ROOT / "tools" / "build_extension.py"),
                     "--platform", PLATFORM, "--out", str(out)], cwd=ROOT)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    version = tomllib.loads((ROOT / "blender_manifest.toml").read_text())["version"]
    return out / f"lightfade-{version}-{PLATFORM.replace('-', '_')}.zip"


def install_and_age(jobs, folder):
    """Build the zip, then install, enable, bake, age and uninstall it in a fresh process
    (:data:`INSTALL_AND_AGE`) with every Blender user folder and the grid cache in
    ``folder``.  An early job (tests/conftest.py): it runs beside the tests before these."""
    built_zip = build_zip(jobs, folder / "dist")
    user_ext = folder / "user_ext"
    env = dict(os.environ,
               BLENDER_USER_EXTENSIONS=str(user_ext),
               BLENDER_USER_CONFIG=str(folder / "user_config"),
               BLENDER_USER_SCRIPTS=str(folder / "user_scripts"),
               LIGHTFADE_CACHE=str(folder / "grid_cache"))
    env.pop("PYTHONPATH", None)
    out = folder / "result.json"
    repo_dir = folder / "repo"
    proc = jobs.run([sys.executable, "-c", INSTALL_AND_AGE, str(built_zip), str(repo_dir),
                     str(user_ext), str(out)], cwd=folder, env=env, timeout=600)
    return SimpleNamespace(zip=built_zip, proc=proc, out=out, repo_dir=repo_dir, user_ext=user_ext)


EARLY = {"install and age": install_and_age}


@pytest.fixture
def installed(early):
    return early("install and age")


def manifest_wheels():
    return tomllib.loads((ROOT / "blender_manifest.toml").read_text())["wheels"]


def test_zip_layout(installed):
    archive = zipfile.ZipFile(installed.zip)
    names = archive.namelist()
    assert "blender_manifest.toml" in names and "__init__.py" in names
    assert any(n.startswith("blender/operators/") for n in names)
    assert not any("__pycache__" in n or n.endswith(".pyc") or n.startswith(("tests/", ".")) for n in names)
    manifest = tomllib.loads(archive.read("blender_manifest.toml").decode())
    generated = manifest["build"]["generated"]
    assert generated["platforms"] == [PLATFORM]
    wheels = generated["wheels"]
    assert all(w.startswith("./wheels/") and w[2:] in names for w in wheels)
    assert sorted(n for n in names if n.endswith(".whl")) == sorted(w[2:] for w in wheels)
    assert not any("win_amd64" in w or "macosx" in w or "numpy" in w for w in wheels)
    scipy = sorted(w for w in wheels if "/scipy-" in w)
    # One scipy per Python that Blender 4.2-5.2 ship: 3.11 and 3.13 (no 3.12).
    assert [w.split("-")[2] for w in scipy] == ["cp311", "cp313"]
    assert {w.split("/")[-1].split("-")[0] for w in wheels} == {"colour_science", "scipy", "typing_extensions"}


def test_manifest_lists_both_pythons_for_every_platform():
    wheels = [w for w in manifest_wheels() if "/scipy-" in w]
    for tag in ("win_amd64", "macosx_12_0_arm64", "macosx_10_14_x86_64", "manylinux_2_17_x86_64"):
        assert sorted(w.split("-")[2] for w in wheels if tag in w) == ["cp311", "cp313"], tag
    assert not any("numpy" in w for w in manifest_wheels())


def test_installed_zip_bakes_and_ages(installed):
    proc, out = installed.proc, installed.out
    repo_dir, user_ext = installed.repo_dir, installed.user_ext
    log = f"exit {proc.returncode}\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}"
    assert out.exists(), log
    result = json.loads(out.read_text())
    assert "error" not in result, result.get("error", "") + log
    assert proc.returncode == 0 or (EXIT_SEGFAULT_OK and proc.returncode == -11), log
    assert result["install"] == ["FINISHED"]
    assert result["enabled"] == [True, True], result
    # Everything LightFade ran came from the installed package and the zip's wheels.
    assert not result["checkout_imported"] and not result["imported_before"]
    for key in ("package", "api"):
        assert Path(result["files"][key]).is_relative_to(repo_dir), result["files"]
    for key in ("colour", "scipy"):
        assert Path(result["files"][key]).is_relative_to(user_ext), result["files"]
    shipped = {w.split("/")[-1].split("-")[0]: w.split("-")[1] for w in manifest_wheels()}
    assert result["versions"] == {"colour": shipped["colour_science"], "scipy": shipped["scipy"]}
    version = tomllib.loads((ROOT / "blender_manifest.toml").read_text())["version"]
    assert result["shown_version"] == [version] and result["package_version"] == version
    # Aging: the sunlit texels changed, the texels under the box did not, the original stayed.
    assert len(result["aged_images"]) == 1 and result["aged_images"] != ["PosterAlbedo"]
    assert result["original_untouched"]
    assert result["lit_change"] > 0.02 and result["lit_min_change"] > 0.005, result
    assert result["shadow_change"] < 0.004, result
    assert result["uninstall"] == ["FINISHED"]
    assert result["after_uninstall"] == [False, False]
    assert not (repo_dir / "lightfade").exists()
