"""Memory and file size per aged material: the aging data against an aged image.

    ./run py -m benchmarks.footprint [--size 2048]

A plane with a ``size``² photograph-like albedo, a box, a sun and an incandescent lamp
(two light spectra), exposure baked at 64 texels per metre, aged. Printed per image:
Blender's memory (pixels × channels × 4 bytes for float, × 1 for 8-bit) and its packed
size in the saved .blend — the copy's data images (keys, dose rates, table), against the
aged image every copy carried before (commit b660256: a float RGBA image of the
albedo's size, which ``api.apply_aging`` now writes on request: the same image).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import bpy  # noqa: E402

from benchmarks.scrub import build  # noqa: E402


def memory(image):
    w, h = image.size
    return w * h * image.channels * (4 if image.is_float else 1)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=2048)
    args = parser.parse_args(argv)
    from lightfade_addon import api
    from lightfade_addon.blender.aging.copies import copies_of

    scene, floor = build(args.size)
    (copy,) = copies_of(obj=floor)
    api.apply_aging(scene, 10.0)
    props = copy.lightfade
    with tempfile.TemporaryDirectory() as folder:
        bpy.ops.wm.save_as_mainfile(filepath=str(Path(folder) / "f.blend"))
    rows = [("keys", props.key_image), ("dose rates", props.rate_image),
            ("aging table", props.table_image)]
    print(f"{args.size}² albedo; aging data of one aged material:")
    total_mem = total_file = 0
    for name, image in rows:
        packed = image.packed_file.size if image.packed_file else 0
        total_mem += memory(image)
        total_file += packed
        print(f"  {name:12s} {image.size[0]:>5} x {image.size[1]:<5} "
              f"{'float' if image.is_float else '8-bit'}  memory {memory(image) / 2**20:7.1f} MB"
              f"  packed {packed / 2**20:7.1f} MB")
    old = props.aged_image
    print(f"  {'total':12s} {'':19s}  memory {total_mem / 2**20:7.1f} MB  packed "
          f"{total_file / 2**20:7.1f} MB")
    print(f"before: one aged image {old.size[0]} x {old.size[1]} float: memory "
          f"{memory(old) / 2**20:.1f} MB, packed {old.packed_file.size / 2**20:.1f} MB")
    info = props.table_image["lightfade_table"]
    print(f"(table: {info['keys']} keys x {(info['q'] + 1) ** (info['S'] - 1)} mix slots x "
          f"{info['T']} dose nodes)")


if __name__ == "__main__":
    main()
