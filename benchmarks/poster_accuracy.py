"""Issue 27's accuracy check inside Blender: photographs as posters on a sunlit plane.

    ./run py -m benchmarks.poster_accuracy [--photos DIR] [--size 256]

Each photograph (:func:`benchmarks.colour_table.photos`: those found on this machine and
in ``DIR``) is the Base Color of a 1 m plane (Printed Paper) lit by a sun alone (no
world, nothing occluding; 8.9 h a day), about 1 Mlx·h a year. The exposure is baked,
the material aged (Age), and ``api.apply_aging`` writes the aged image at 5 and 25
years; ``age-image --exact`` ages the same pixels at the dose the baked map holds under
each. Printed: ΔE00 p99 / max per photograph (issue 27: at most 0.6 / 1.5), and Age's
time.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import bpy  # noqa: E402
import addon_utils  # noqa: E402
import numpy as np  # noqa: E402

from benchmarks.colour_table import photos  # noqa: E402

YEARS = (5.0, 25.0)
#: Sun strength (W/m²) for ~3000 lux on a plane it meets at 40° from the zenith.
SUN = 0.58


def poster(path, size):
    """A fresh file: the plane, its material (the photograph, scaled to ``size``), a sun."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    addon_utils.enable("lightfade_addon", default_set=True)
    bpy.ops.mesh.primitive_plane_add(size=1.0)
    plane = bpy.context.active_object
    image = bpy.data.images.load(path)
    w, h = image.size
    scale = size / max(w, h)
    if scale < 1:
        image.scale(max(1, round(w * scale)), max(1, round(h * scale)))
    image.pack()
    mat = bpy.data.materials.new("Poster")
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    tex = mat.node_tree.nodes.new("ShaderNodeTexImage")
    tex.image = image
    tex.interpolation = "Closest"
    mat.node_tree.links.new(tex.outputs["Color"],
                            mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"])
    mat.lightfade.enabled = True
    mat.lightfade.recipe = "PRINTED_PAPER"
    plane.data.materials.append(mat)
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy, sun.data.angle = SUN, 0.0
    sun.data.lightfade.hours_per_day, sun.data.lightfade.days_per_year = 8.9, 365.0
    sun.rotation_euler = (math.radians(40.0), 0.0, 0.0)
    bpy.context.scene.collection.objects.link(sun)
    scene = bpy.context.scene
    scene.lightfade.bake_resolution = 64
    return scene, plane, mat, image


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--photos", help="a folder of more photographs (.png, .jpg)")
    p.add_argument("--size", type=int, default=256, help="longer side of each photo (px)")
    a = p.parse_args(argv)
    from lightfade_addon import api
    from lightfade_addon.blender.exposure import exposure_images
    from lightfade_addon.blender.pixels import read_linear, read_rgba, resample
    from lightfade_addon.core.colour.colorimetry import (XYZ_to_Lab, delta_E_2000,
                                                         linear_srgb_to_XYZ, srgb_decode)
    from lightfade_addon.core.fading.exact import age_image_exact
    from lightfade_addon.core.fading.lights import Light
    from lightfade_addon.core.fading.recipes import get_recipe

    def lab(linear):
        return XYZ_to_Lab(linear_srgb_to_XYZ(np.clip(linear, 0, 1).reshape(-1, 3)))

    print(f"{'photo':18s} {'size':>9s} {'Mlx·h/yr':>9s} {'Age s':>6s}  " +
          "  ".join(f"{y:g} y p99 / max" for y in YEARS))
    worst = [0.0, 0.0]
    for name, path in photos(a.photos).items():
        if path.endswith(".exr"):
            continue                                   # posters are 8-bit pictures
        scene, plane, mat, image = poster(path, a.size)
        assert bpy.ops.lightfade.bake_exposure() == {"FINISHED"}
        t0 = time.perf_counter()
        assert bpy.ops.lightfade.age(years=YEARS[0]) == {"FINISHED"}
        age_s = time.perf_counter() - t0
        (map_image, light), = exposure_images(scene, plane)
        lux = read_rgba(map_image)[..., 0]
        per_year = float(lux.mean()) * light.hours_per_day * light.days_per_year
        src = read_rgba(image)[..., :3]                # encoded sRGB, as the file holds it
        exposure = resample(lux, src.shape[:2]) / float(lux.mean())
        ref_light = Light(light.spectrum, light.uv_filter, float(lux.mean()),
                          light.hours_per_day, light.days_per_year)
        exact = age_image_exact(src, list(YEARS), get_recipe("printed-paper"), ref_light,
                                exposure=exposure)
        cells = []
        for years, ref in zip(YEARS, exact):
            (aged,) = api.apply_aging(scene, years).values()
            ours = read_linear(aged)[..., :3]
            api.live_aging(scene)
            d = delta_E_2000(lab(ours), lab(srgb_decode(ref)))
            p99, mx = float(np.percentile(d, 99)), float(d.max())
            worst = [max(worst[0], p99), max(worst[1], mx)]
            cells.append(f"{p99:6.2f} / {mx:5.2f}")
        H, W = src.shape[:2]
        print(f"{name:18s} {W:4d}x{H:<4d} {per_year / 1e6:9.2f} {age_s:6.1f}  " + "   ".join(cells),
              flush=True)
    print(f"worst p99 {worst[0]:.2f} (target 0.6), worst max {worst[1]:.2f} (target 1.5)")


if __name__ == "__main__":
    main(sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:])
