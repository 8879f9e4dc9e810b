"""Age with parts: one material aged by one recipe against the same material with two
recipes by a mask image, side by side in one run.

    ./run py -m benchmarks.parts

A 2 m plane under a sun with a box, its Base Color a 256² image of many colours,
exposure baked at 128². Each case is aged twice (the colour tables are loaded from the
disk cache, not built: one Age before the timings fills it) and the faster run is
printed. With parts, Age finds each recipe's shared table and builds one aging group per
recipe in use and the mixing group; nothing is done per texel (the parts' weights are
baked with Cycles only when Apply to Images or an export first needs them: the second
line times the first Apply after Age, that bake included).
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


if __name__ == "__main__":
    main()
