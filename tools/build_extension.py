"""Build LightFade's Blender extension zips with Blender's own extension builder.

Usage::

    ./run py tools/build_extension.py                          # all four platforms -> dist/
    ./run py tools/build_extension.py --platform linux-x64     # one (repeatable)
    ./run py tools/build_extension.py --out /tmp/zips

writes ``<out>/lightfade-<version>-<platform>.zip`` (``windows_x64``, ``macos_arm64``,
``macos_x64``, ``linux_x64``), each installable in Blender 4.2 LTS to 5.2.  This script only
gathers the inputs; the zips are made and checked by Blender:

1. **Wheels.** ``blender_manifest.toml`` names every wheel file (the one source of truth for
   versions).  Each one missing from ``build/wheels/`` (a cache, gitignored) is fetched with
   ``pip download --only-binary=:all: --no-deps --implementation cp --python-version 3.11|3.13
   --platform <the wheel's platform tag> <name>==<version>``, and pip must return exactly
   the named file.
2. **Source directory.** ``build/extension/`` is rebuilt from scratch: the files of
   ``lightfade_addon/`` (no caches), the manifest beside them and the wheels the requested
   platforms need in ``wheels/``.  With ``--platform``, the staged manifest's ``platforms``
   (and ``wheels``) lists are cut down to those platforms -- the only difference from a full
   build's zip for the same platform.
3. **Blender's builder.** ``blender_ext.py build --split-platforms`` (Blender's extension
   command line, shipped inside the ``bpy`` module that runs this script:
   ``bpy/<version>/scripts/addons_core/bl_pkg/cli/blender_ext.py``) writes one zip per
   platform holding only that platform's wheels and a ``[build.generated]`` manifest
   section; then ``blender_ext.py validate`` checks each zip the way Blender does when it
   installs one.
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import re
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "lightfade_addon"
MANIFEST = ROOT / "blender_manifest.toml"
CACHE = ROOT / "build" / "wheels"
STAGE = ROOT / "build" / "extension"
PLATFORMS = ("windows-x64", "macos-arm64", "macos-x64", "linux-x64")
IGNORE = shutil.ignore_patterns("__pycache__", "*.pyc", ".*")


def blender_ext_cli():
    """Path of Blender's ``blender_ext.py`` inside the importable ``bpy`` module."""
    spec = importlib.util.find_spec("bpy")
    if spec is None or not spec.submodule_search_locations:
        raise SystemExit("tools/build_extension.py needs the bpy module (Blender's builder ships in it): "
                         "run it as './run py tools/build_extension.py'")
    for location in spec.submodule_search_locations:
        found = sorted(Path(location).glob("*/scripts/addons_core/bl_pkg/cli/blender_ext.py"))
        if found:
            return found[-1]
    raise SystemExit(f"Blender's blender_ext.py not found in {list(spec.submodule_search_locations)}")


def load_blender_ext(cli):
    """Blender's builder as a module, to reuse its wheel/platform matching."""
    spec = importlib.util.spec_from_file_location("blender_ext", cli)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def pip_download_args(filename):
    """``pip download`` options and requirement that fetch exactly the wheel ``filename``.

    ``scipy-1.16.3-cp313-cp313-win_amd64.whl`` -> CPython 3.13, platform ``win_amd64``,
    ``scipy==1.16.3``.  Pure wheels (``py3-none-any``) need no platform options.
    """
    dist, version, python_tag, abi_tag, platform_tag = filename[:-4].split("-")
    args = ["--only-binary=:all:", "--no-deps"]
    if platform_tag != "any":
        m = re.fullmatch(r"cp(\d)(\d+)", python_tag)
        if m is None:
            raise SystemExit(f"blender_manifest.toml: cannot tell the Python version of {filename}")
        args += ["--implementation", "cp", "--python-version", f"{m[1]}.{m[2]}", "--abi", abi_tag]
        args += [arg for tag in platform_tag.split(".") for arg in ("--platform", tag)]
    return args, f"{dist.replace('_', '-')}=={version}"


def fetch_wheel(relpath):
    """Download one manifest wheel into the cache (if missing); return its path."""
    name = Path(relpath).name
    target = CACHE / name
    if target.exists():
        return target
    CACHE.mkdir(parents=True, exist_ok=True)
    args, requirement = pip_download_args(name)
    print("  pip download", name, flush=True)
    subprocess.run([sys.executable, "-m", "pip", "download", "--quiet", "--dest", str(CACHE), *args, requirement],
                   check=True)
    if not target.exists():
        got = sorted(p.name for p in CACHE.glob(f"{name.split('-')[0]}-*.whl"))
        raise SystemExit(f"pip did not return {name} (got {got}); correct the name in blender_manifest.toml")
    return target


def stage(platforms, blender_ext):
    """Fill ``build/extension/`` with the package, manifest and wheels; return its path."""
    text = MANIFEST.read_text()
    manifest = tomllib.loads(text)
    wheels = [w for w in manifest["wheels"]
              if any(blender_ext.paths_filter_wheels_by_platform([w], p) for p in platforms)]
    if tuple(platforms) != tuple(manifest["platforms"]):
        text = _replace_list(text, "platforms", platforms)
        text = _replace_list(text, "wheels", wheels)
    shutil.rmtree(STAGE, ignore_errors=True)
    shutil.copytree(PACKAGE, STAGE, ignore=IGNORE)
    (STAGE / "blender_manifest.toml").write_text(text)
    for relpath in wheels:
        dest = STAGE / relpath
        dest.parent.mkdir(parents=True, exist_ok=True)
        wheel = fetch_wheel(relpath)
        try:
            os.link(wheel, dest)  # no second copy of ~300 MB of wheels
        except OSError:
            shutil.copyfile(wheel, dest)
    return STAGE


def _replace_list(text, key, values):
    """``text`` with the TOML array ``key = [...]`` replaced by ``values``."""
    listing = f"{key} = [\n" + "".join(f'  "{v}",\n' for v in values) + "]"
    text, n = re.subn(rf"^{key}\s*=\s*\[.*?\]", listing, text, count=1, flags=re.M | re.S)
    if n != 1:
        raise SystemExit(f"blender_manifest.toml: no {key} = [...] list found")
    tomllib.loads(text)
    return text


def run_cli(cli, *args):
    """Run Blender's ``blender_ext.py`` with ``args``; exit with its output if it fails."""
    proc = subprocess.run([sys.executable, str(cli), *map(str, args)], capture_output=True, text=True)
    if proc.returncode != 0:
        raise SystemExit(f"blender_ext.py {args[0]} failed:\n{proc.stdout}{proc.stderr}")
    return proc.stdout


def build(platforms, out_dir):
    """Build and validate one zip per platform in ``out_dir``; return the zip paths."""
    cli = blender_ext_cli()
    print(f"Blender's builder: {cli}", flush=True)
    source = stage(platforms, load_blender_ext(cli))
    out_dir.mkdir(parents=True, exist_ok=True)
    manifest = tomllib.loads(MANIFEST.read_text())
    zips = [out_dir / f"{manifest['id']}-{manifest['version']}-{p.replace('-', '_')}.zip" for p in platforms]
    for z in zips:
        z.unlink(missing_ok=True)
    run_cli(cli, "build", "--source-dir", source, "--output-dir", out_dir, "--split-platforms")
    for z in zips:
        if not z.exists():
            raise SystemExit(f"Blender's builder did not write {z}")
        run_cli(cli, "validate", z)
        print(f"{z}  {z.stat().st_size / 1e6:.1f} MB  (valid)", flush=True)
    return zips


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--platform", action="append", choices=PLATFORMS,
                        help="platform to build (repeatable); default: all four")
    parser.add_argument("--out", type=Path, default=ROOT / "dist", help="output directory (default dist/)")
    args = parser.parse_args(argv)
    platforms = [p for p in PLATFORMS if p in (args.platform or PLATFORMS)]
    return build(platforms, args.out.resolve())


if __name__ == "__main__":
    main()
