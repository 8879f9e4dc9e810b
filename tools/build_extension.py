"""Build LightFade's Blender extension zips, one per platform.

Usage::

    python tools/build_extension.py [--platform linux-x64 ...] [--out dist/] [--no-validate]

The repository's ``blender_manifest.toml`` lists every wheel for every platform (the single
source of truth for versions).  For each requested platform this script

1. downloads the wheels that platform needs with ``pip download --only-binary=:all:
   --no-deps --python-version 3.11 --implementation cp --platform <wheel tag>`` into
   ``build/wheels/`` (a cache, gitignored; a wheel already there is not downloaded again)
   and checks that pip returned exactly the file named in the manifest;
2. writes ``<out>/lightfade-<version>-<platform>.zip`` whose root is the add-on package
   (``__init__.py``, ``core/``, ``blender/``, ...) with a copy of the manifest beside it
   that lists only that platform's wheels and ``platforms = ["<platform>"]``, plus
   ``wheels/``;  ``__pycache__``, ``*.pyc``, tests and caches are left out;
3. validates the zip with Blender's own extension checker when the ``bpy`` module is
   importable, and prints the sizes.
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tomllib
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "lightfade_addon"
MANIFEST = ROOT / "blender_manifest.toml"
CACHE = ROOT / "build" / "wheels"
PLATFORMS = ("windows-x64", "macos-arm64", "macos-x64", "linux-x64")
EXCLUDE_DIRS = {"__pycache__", "tests", ".pytest_cache", ".mypy_cache", ".ruff_cache", ".cache"}
EXCLUDE_SUFFIXES = (".pyc", ".pyo", ".blend1", ".orig", ".rej", "~")


def wheel_platform_tag(filename):
    """``scipy-1.15.3-cp311-cp311-win_amd64.whl`` -> ``"win_amd64"``."""
    return Path(filename).stem.split("-")[-1]


def blender_platforms(wheel_tag):
    """Blender platforms a wheel platform tag serves (``"any"`` serves all)."""
    if wheel_tag == "any":
        return set(PLATFORMS)
    out = set()
    for tag in wheel_tag.split("."):
        if tag.startswith("win") and tag.endswith("amd64"):
            out.add("windows-x64")
        elif tag.startswith("macosx_"):
            if tag.endswith("universal2"):
                out |= {"macos-x64", "macos-arm64"}
            elif tag.endswith("arm64"):
                out.add("macos-arm64")
            elif tag.endswith("x86_64"):
                out.add("macos-x64")
        elif "linux" in tag and tag.endswith("x86_64"):
            out.add("linux-x64")
        elif "linux" in tag and tag.endswith("aarch64"):
            out.add("linux-arm64")
    return out


def wheels_for(manifest, platform):
    """The manifest's wheel paths that ``platform`` needs."""
    return [w for w in manifest.get("wheels", []) if platform in blender_platforms(wheel_platform_tag(w))]


def fetch_wheel(relpath, platform):
    """Download one manifest wheel into the cache (if missing); return its path."""
    name = Path(relpath).name
    target = CACHE / name
    if target.exists():
        return target
    CACHE.mkdir(parents=True, exist_ok=True)
    dist, version, *_ = name[:-4].split("-")
    tag = wheel_platform_tag(name)
    cmd = [sys.executable, "-m", "pip", "download", "--quiet", "--only-binary=:all:", "--no-deps",
           "--python-version", "3.11", "--implementation", "cp", "--dest", str(CACHE)]
    if tag != "any":
        cmd += ["--platform", tag.split(".")[0]]
    cmd.append(f"{dist.replace('_', '-')}=={version}")
    print("  pip download", dist, version, tag, flush=True)
    subprocess.run(cmd, check=True)
    if not target.exists():
        got = sorted(p.name for p in CACHE.glob(f"{dist}-{version}-*.whl"))
        raise SystemExit(f"pip did not return {name} for {platform} (got {got}); update blender_manifest.toml")
    return target


def platform_manifest(text, platform, wheels):
    """The manifest text with only ``wheels`` and ``platforms = [platform]``."""
    listing = "wheels = [\n" + "".join(f'  "{w}",\n' for w in wheels) + "]"
    text, n = re.subn(r"^wheels\s*=\s*\[.*?\]", listing, text, count=1, flags=re.M | re.S)
    if n != 1:
        raise SystemExit("blender_manifest.toml: no wheels = [...] list found")
    text, n = re.subn(r"^platforms\s*=\s*\[.*?\]", f'platforms = ["{platform}"]', text,
                      count=1, flags=re.M | re.S)
    if n != 1:
        raise SystemExit("blender_manifest.toml: no platforms = [...] list found")
    tomllib.loads(text)  # still valid TOML
    return text


def package_files():
    """(path, name in zip) of the add-on package's files."""
    for dirpath, dirnames, filenames in os.walk(PACKAGE):
        dirnames[:] = sorted(d for d in dirnames if d not in EXCLUDE_DIRS and not d.startswith("."))
        for fname in sorted(filenames):
            if fname.endswith(EXCLUDE_SUFFIXES) or fname.startswith("."):
                continue
            path = Path(dirpath) / fname
            yield path, path.relative_to(PACKAGE).as_posix()


def build(platform, out_dir):
    text = MANIFEST.read_text()
    manifest = tomllib.loads(text)
    wheels = wheels_for(manifest, platform)
    print(f"{platform}: {len(wheels)} wheels", flush=True)
    paths = [fetch_wheel(w, platform) for w in wheels]
    out_dir.mkdir(parents=True, exist_ok=True)
    zpath = out_dir / f"{manifest['id']}-{manifest['version']}-{platform}.zip"
    with zipfile.ZipFile(zpath, "w", compression=zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("blender_manifest.toml", platform_manifest(text, platform, wheels))
        for path, arc in package_files():
            zf.write(path, arc)
        for rel, path in zip(wheels, paths):
            # Wheels are already compressed: store them.
            zf.write(path, rel.removeprefix("./"), compress_type=zipfile.ZIP_STORED)
    return zpath


def validate(zpath):
    """Run Blender's extension checker on ``zpath`` if the bpy module is available."""
    try:
        import bpy  # noqa: F401
    except ImportError:
        print("  (bpy not importable: skipping Blender's validation)")
        return
    import addon_utils

    cli = Path(addon_utils.paths()[0]).parent / "addons_core" / "bl_pkg" / "cli" / "blender_ext.py"
    cli = next((p for p in [cli] + [Path(d) / "bl_pkg" / "cli" / "blender_ext.py" for d in addon_utils.paths()]
                if p.exists()), None)
    if cli is None:
        print("  (Blender's blender_ext.py not found: skipping validation)")
        return
    proc = subprocess.run([sys.executable, str(cli), "validate", str(zpath)], capture_output=True, text=True)
    if proc.returncode != 0:
        raise SystemExit(f"Blender rejects {zpath.name}:\n{proc.stdout}{proc.stderr}")
    print("  valid:", (proc.stdout.strip().splitlines() or ["ok"])[-1])


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--platform", action="append", choices=PLATFORMS,
                        help="platform to build (repeatable); default: all")
    parser.add_argument("--out", type=Path, default=ROOT / "dist", help="output directory (default dist/)")
    parser.add_argument("--no-validate", action="store_true", help="skip Blender's manifest/zip check")
    args = parser.parse_args(argv)
    zips = []
    for platform in args.platform or PLATFORMS:
        zpath = build(platform, args.out)
        if not args.no_validate:
            validate(zpath)
        zips.append(zpath)
    for z in zips:
        print(f"{z}  {z.stat().st_size / 1e6:.1f} MB")
    return zips


if __name__ == "__main__":
    main()
