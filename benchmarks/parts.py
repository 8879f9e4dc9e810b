"""Age with parts: one material aged by one recipe against the same material with two
recipes by a mask image, side by side in one run.

    ./run py -m benchmarks.parts

A 2 m plane under a sun with a box, its Base Color a 256² image of many colours,
exposure baked at 128². Each case is aged twice (the colour tables are loaded from the
disk cache, not built: one Age before the timings fills it) and the faster run is
printed. With parts, Age finds each recipe's shared table and builds one aging group per
recipe in use and the mixing group; nothing is done per texel (the parts' weights are
baked with Cycles only when Apply to Images or an export first needs them: the second
line times the first Apply after Age, that bake included). Last, two parts whose masks
overlap (bare wood on the left half, printed paper everywhere) at 30 years: the node group
(a Cycles bake of the copy's Base Color) against Apply's numpy twin, and the largest
channel of each (never above 1: each texel is shared out, not aged twice).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import bpy  # noqa: E402  (first: it puts Blender's modules on the path)
import addon_utils  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "blender"))
from conftest import build_floor_scene, reset_file  # noqa: E402

SIZE = 256


def _image(name, pixels):
    image = bpy.data.images.new(name, SIZE, SIZE, float_buffer=True)
    image.pixels.foreach_set(pixels.ravel())
    image.pack()
    return image


def main():
    reset_file()
    addon_utils.enable("lightfade_addon", default_set=True)
    from lightfade_addon import api

    parts = build_floor_scene()
    material = parts["material"]
    rng = np.random.default_rng(1)
    px = np.ones((SIZE, SIZE, 4), np.float32)
    px[..., :3] = rng.uniform(0.1, 0.9, (SIZE, SIZE, 3)).round(1)
    material.node_tree.nodes["Image Texture"].image = _image("Texture", px)
    m = np.ones((SIZE, SIZE, 4), np.float32)
    m[:, SIZE // 2:, :3] = 0.0
    mask = _image("Mask", m)
    material.lightfade.recipe = "DYED_FABRIC"
    scene = bpy.context.scene
    scene.lightfade.bake_resolution = 128
    api.bake(scene)
    cases = {"one recipe": [],
             "two recipes by mask": [dict(name="Frame", recipe="BARE_WOOD", image=mask)]}
    for chosen in cases.values():                  # fill the grid cache
        api.set_parts(material, chosen)
        api.age_scene(scene, years=5)
        api.reset(scene)
    times = {label: [] for label in cases}
    applies = {label: [] for label in cases}
    for _ in range(2):
        for label, chosen in cases.items():
            api.set_parts(material, chosen)
            t = time.perf_counter()
            api.age_scene(scene, years=5)
            times[label].append(time.perf_counter() - t)
            t = time.perf_counter()
            api.apply_aging(scene)                 # with parts: the weights' Cycles bake
            applies[label].append(time.perf_counter() - t)
            api.reset(scene)
    one, two = (min(times[label]) for label in cases)
    print(f"Age, {SIZE}² texture, 128² exposure: one recipe {one:.2f} s, two recipes by "
          f"mask {two:.2f} s, ratio {two / one:.2f}")
    one, two = (min(applies[label]) for label in cases)
    print(f"First Apply to Images after Age: one recipe {one:.2f} s, two recipes by mask "
          f"{two:.2f} s, ratio {two / one:.2f}")
    overlap(scene, material, mask)


def overlap(scene, material, mask):
    """Two overlapping parts at 30 years: node group against Apply, largest channels."""
    from lightfade_addon import api
    from lightfade_addon.blender.aging.apply import aged_pixels
    from lightfade_addon.blender.aging.copies import copies_of
    from lightfade_addon.blender.aging.parts import colour_socket
    from lightfade_addon.blender.albedo import bake_albedos
    from lightfade_addon.core.colour.colorimetry import XYZ_to_Lab, delta_E_2000, \
        linear_srgb_to_XYZ

    # the bake samples each texel near its centre: Closest reads the texel itself, as the
    # numpy twin does (Linear blends the random neighbours in)
    material.node_tree.nodes["Image Texture"].interpolation = "Closest"
    full = _image("Everywhere", np.ones((SIZE, SIZE, 4), np.float32))
    api.set_parts(material, [dict(name="Frame", recipe="BARE_WOOD", image=mask),
                             dict(name="Paint", recipe="PRINTED_PAPER", image=full)])
    api.age_scene(scene, years=30)
    (copy,) = copies_of(material)
    twin = aged_pixels(scene, copy, 30.0)[..., :3]
    image = bpy.data.images.new("NodeEvaluation", SIZE, SIZE, alpha=True, float_buffer=True)
    image.colorspace_settings.name = "Linear Rec.709"
    nodes = bake_albedos(scene, bpy.context.view_layer, copy.lightfade.aged_object,
                         [(copy, colour_socket(copy), image)], copy.lightfade.uv_map,
                         margin=0)[copy.name]
    inner = np.s_[1:-1, 1:-1]                   # the bake samples the outer ring off-centre

    def lab(rgb):
        return XYZ_to_Lab(linear_srgb_to_XYZ(np.asarray(rgb, float).reshape(-1, 3)))

    dE = delta_E_2000(lab(nodes[inner]), lab(twin[inner])).reshape(SIZE - 2, SIZE - 2)
    edge = dE[:, SIZE // 2 - 3: SIZE // 2 + 1]          # the mask's edge (u = 0.5)
    print(f"  (at the mask's edge, columns {SIZE // 2 - 2}-{SIZE // 2 + 1}: max "
          f"{edge.max():.3f}; elsewhere max "
          f"{np.delete(dE, np.s_[SIZE // 2 - 3: SIZE // 2 + 1], axis=1).max():.3f})")
    print(f"Overlapping parts, 30 years: node group against Apply p99 "
          f"{np.percentile(dE, 99):.3f}, max {dE.max():.3f} ΔE00; largest channel: node "
          f"group {nodes[inner].max():.4f}, Apply {twin.max():.4f}")
    api.reset(scene)


if __name__ == "__main__":
    main()
