"""The figures of ``docs/daylight.md``: one static sun against the annual daylight bake on
the floor of the mullioned room, and the dose view (annual dose and years until a
just-noticeable fade) with its legends.

Run ``python -m scenes.daylight_figures [--out docs/img] [--density 64] [--samples 16]``
(about a minute on 2 cores).  Writes:

``daylight_static_vs_annual.png``  floor and rug dose, one sun lamp × 8 h a day against
                                   the year's sun and sky at 52° N (clear sky)
``daylight_dose_view.png``         the dose view's two images (what the view material
                                   shows), seen from above, with their legends
``daylight_legend_dose.png``, ``daylight_legend_years.png``  the legends the operator writes
"""

from __future__ import annotations

import argparse
from pathlib import Path

import bpy
import addon_utils
import numpy as np

from . import daylight_room as R

DOCS_IMG = Path(__file__).resolve().parents[1] / "docs" / "img"


def _uv_box(obj):
    """(u0, v0, u1, v1) of a one-quad mesh's UVs (its rectangle in the map)."""
    uv = np.empty(len(obj.data.loops) * 2, np.float64)
    obj.data.uv_layers[0].data.foreach_get("uv", uv)
    uv = uv.reshape(-1, 2)
    return (*uv.min(axis=0), *uv.max(axis=0))


def top_view(values, objects, n=256):
    """Top view of the floor (4 m square) with the rug laid on it: each object's map
    sampled at world (x, y) through its quad's UV rectangle.  ``values``: name ->
    (H, W) or (H, W, C) arrays in the objects' maps (rows bottom-up)."""
    xs = (np.arange(n) + 0.5) / n * 4.0 - 2.0
    X, Y = np.meshgrid(xs, xs)
    out = None
    for name in objects:                    # later objects lie on top
        obj = bpy.data.objects[name]
        a = values[name]
        (x0, y0, _), (x1, y1, _) = np.min(_corners(obj), axis=0), np.max(_corners(obj), axis=0)
        u0, v0, u1, v1 = _uv_box(obj)
        inside = (X >= x0) & (X <= x1) & (Y >= y0) & (Y <= y1)
        h, w = a.shape[:2]
        u = u0 + (X - x0) / (x1 - x0) * (u1 - u0)
        v = v0 + (Y - y0) / (y1 - y0) * (v1 - v0)
        col = np.clip((u * w).astype(int), 0, w - 1)
        row = np.clip((v * h).astype(int), 0, h - 1)
        if out is None:
            out = np.zeros((n, n) + a.shape[2:], dtype=np.float64)
        out[inside] = a[row[inside], col[inside]]
    return out


def save(fig, path):
    """Lay ``fig`` out, write it to ``path`` and close it."""
    from matplotlib import pyplot as plt

    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def figure_parser(doc):
    """The command line of a figure script: ``--out`` and ``--density``."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument("--out", default=str(DOCS_IMG))
    parser.add_argument("--density", type=float, default=64.0, help="texels per metre")
    return parser


def _corners(obj):
    return np.array([obj.matrix_world @ v.co for v in obj.data.vertices])


def bake(api, scene, objects, samples):
    api.bake(scene, objects=[scene.objects[o] for o in objects], quality="CUSTOM",
             samples=samples)
    return {o: sum(api.annual_dose(scene, scene.objects[o]).values()) for o in objects}


def make(out, density=64.0, samples=16):
    from lightfade_addon import api
    from lightfade_addon.blender.daylight import colours
    from lightfade_addon.blender.daylight.doses import HORIZON_YEARS
    from lightfade_addon.blender.daylight.view import view_values
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib import pyplot as plt

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    names = R.build()
    addon_utils.enable("lightfade_addon", default_set=True)
    scene = bpy.context.scene
    scene.lightfade_bake.texels_per_metre = density
    scene.lightfade_daylight.sky_width = 512
    for name, recipe in ((names["floor"], "BARE_WOOD"), (names["rug"], "DYED_FABRIC")):
        props = scene.objects[name].data.materials[0].lightfade
        props.enabled, props.recipe = True, recipe
    objects = [names["floor"], names["rug"]]
    sun = R.static_sun()
    sun.data.lightfade.hours_per_day = 8.0
    bpy.context.view_layer.update()
    static = bake(api, scene, objects, samples)
    api.set_daylight(scene, **R.PLACE)
    annual = bake(api, scene, objects, samples)

    fig, axes = plt.subplots(1, 2, figsize=(8.4, 4.2), dpi=110)
    for ax, doses, title in ((axes[0], static, "one sun lamp (38°, due south) × 8 h a day"),
                             (axes[1], annual, "annual: the year's sun and sky, 52° N clear")):
        top = top_view(doses, objects)
        ax.imshow(top / top.max(), origin="lower", extent=(-2, 2, -2, 2), cmap="inferno",
                  vmin=0, vmax=1)
        ax.set_title(f"{title}\npeak {top.max() / 1e6:.3g} Mlx·h a year", fontsize=8)
        ax.set_xlabel("x (m)   window: south wall, y = -2", fontsize=7)
        ax.tick_params(labelsize=6)
    fig.suptitle("Floor and rug dose, each scaled to its peak", fontsize=9)
    save(fig, out / "daylight_static_vs_annual.png")

    fig, axes = plt.subplots(1, 2, figsize=(8.4, 4.6), dpi=110)
    for ax, mode in zip(axes, ("DOSE", "YEARS")):
        rug_values, _, _ = view_values(scene, scene.objects[names["rug"]], mode)
        floor_values, _, _ = view_values(scene, scene.objects[names["floor"]], mode)
        both = np.concatenate([rug_values.ravel(), floor_values.ravel()])
        scale = (colours.years_scale(both, HORIZON_YEARS)
                 if mode == "YEARS" else colours.dose_scale(both))
        images = {names["rug"]: colours.false_colour(rug_values, scale)[..., :3],
                  names["floor"]: colours.false_colour(floor_values, scale)[..., :3]}
        ax.imshow(top_view(images, objects), origin="lower", extent=(-2, 2, -2, 2))
        ax.set_title(f"{scale.title}\n({scale.unit}; floor: bare wood, rug: dyed wool)",
                     fontsize=8)
        ax.tick_params(labelsize=6)
        legend = out / f"daylight_legend_{mode.lower()}.png"
        colours.write_legend(str(legend), scale, "grey: no visible fade within "
                             f"{HORIZON_YEARS:g} years" if mode == "YEARS" else "grey: no light")
    save(fig, out / "daylight_dose_view.png")
    return out


def main(argv=None):
    parser = figure_parser(__doc__)
    parser.add_argument("--samples", type=int, default=16)
    args = parser.parse_args(argv)
    print(make(args.out, args.density, args.samples))


if __name__ == "__main__":
    main()
