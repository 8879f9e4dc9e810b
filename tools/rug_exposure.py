"""Does the demo rug's exposure map carry the rug's own pattern?

    python tools/rug_exposure.py [--texture 512] [--map 128] [--samples 16] [--old]

Builds the demo room (``scenes/room.py``; the rug is a Principled BSDF with sheen 0.4 over
its woven texture), bakes the rug's exposure to the sun as the demo does (denoised), and
compares, inside the sun patch (texels above half the map's 99th percentile), the
exposure with the luminance of the rug's texture at the same texel: their correlation,
and the mean lux on the lightest and on the mid-tone quarter of the texels.  Light
arriving at a rug does not know the rug's pattern: the correlation should be near 0 and
the two means equal.  ``--old`` bakes as before the baked texels were shown as white
diffuse (``bake/surface.py`` switched off), for comparison.
"""

from __future__ import annotations

import argparse
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import bpy  # noqa: E402, I001
import addon_utils  # noqa: E402
import numpy as np  # noqa: E402


def srgb_to_linear(c):
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def texture_at_texels(image, n):
    """Luminance (linear Rec. 709) of ``image`` sampled at the centres of an n × n map."""
    w, h = image.size
    px = np.empty(w * h * 4, dtype=np.float32)
    image.pixels.foreach_get(px)
    rgb = srgb_to_linear(px.reshape(h, w, 4)[..., :3])
    Y = rgb @ np.array([0.2126, 0.7152, 0.0722])
    centres = (np.arange(n) + 0.5) / n
    rows = np.minimum((centres * h).astype(int), h - 1)
    cols = np.minimum((centres * w).astype(int), w - 1)
    return Y[np.ix_(rows, cols)]


def measure(texture=512, map_size=128, samples=16, old=False):
    """Build the room, bake the rug and compare its exposure with its texture.

    Returns
    -------
    dict
        ``r`` (correlation inside the sun patch), ``light`` and ``mid`` (mean lux on the
        lightest and on the mid-tone quarter of the texels), ``mean`` (lux), ``texels``.
    """
    from scenes import room
    from scenes.tags import apply_tags

    if addon_utils.check("lightfade_addon")[1]:
        addon_utils.disable("lightfade_addon", default_set=True)
    info = room.build(resolution=texture)
    addon_utils.enable("lightfade_addon", default_set=True)
    from lightfade_addon.blender.bake import BakeSettings, bake_exposure, targets

    scene = bpy.context.scene
    apply_tags(scene)
    rug = bpy.data.objects[info["rug"]]
    settings = BakeSettings(resolution=map_size, samples=samples, margin=4)
    real = targets.expose_surface
    if old:
        targets.expose_surface = lambda state, material: None
    try:
        maps = bake_exposure(scene, [rug], settings, report=lambda m: None,
                             progress=lambda f, m: None)["maps"][rug.name]
    finally:
        targets.expose_surface = real
    sun = next(image for name, image in maps.items()
               if name.startswith(("Sun", "Daylight")))      # annual daylight at a place
    n = sun.size[0]
    lux = np.empty(n * n * 4, dtype=np.float32)
    sun.pixels.foreach_get(lux)
    lux = lux.reshape(n, n, 4)[..., 0]
    Y = texture_at_texels(bpy.data.images["Rug_Wool"], n)
    inner = np.zeros_like(lux, dtype=bool)
    inner[4:-4, 4:-4] = True  # away from the map's border (bake margin, rug edge)
    patch = inner & (lux > 0.5 * np.percentile(lux[inner], 99))
    q25, q50, q75 = np.percentile(Y[patch], [25, 50, 75])
    return dict(r=float(np.corrcoef(lux[patch], Y[patch])[0, 1]),
                light=float(lux[patch & (Y >= q75)].mean()),
                mid=float(lux[patch & (Y >= q25) & (Y <= q50)].mean()),
                mean=float(lux[patch].mean()), texels=int(patch.sum()))


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--texture", type=int, default=512, help="room texture size (rug width, texels)")
    p.add_argument("--map", type=int, default=128, help="exposure map size")
    p.add_argument("--samples", type=int, default=16, help="bake samples")
    p.add_argument("--old", action="store_true", help="bake without the white-diffuse texels")
    args = p.parse_args(argv)
    m = measure(args.texture, args.map, args.samples, args.old)
    label = "old (real material at the texel)" if args.old else "white diffuse at the texel"
    print(f"rug exposure to the sun, {label}: {m['texels']} texels in the sun patch, "
          f"{m['mean']:,.0f} lux on average")
    print(f"  correlation with the rug texture's luminance: {m['r']:+.2f}")
    print(f"  lightest quarter of the texture {m['light']:,.0f} lux, mid-tones {m['mid']:,.0f} lux "
          f"({(m['light'] / m['mid'] - 1) * 100:+.1f} %)")
    return m


if __name__ == "__main__":
    main()
