"""The figure of ``docs/bake.md`` on window glass: the mullioned room's floor and rug under
the year's daylight through a pane of refracting glass, at the default quality, with
*Portals over Windows* off and on.

Cycles' shadow rays stop at a Glass BSDF, so with the switch off the sky reaches the room
only by bounces that happen to refract out through the pane; with it on the window gets
a portal and the glass is a clear pane of its own transmittance while the sky is baked
(``lightfade_addon/blender/bake/panes.py``).  The third panel is the same window open,
with its portal: what the glass should give, times its 0.92.

Run ``python -m scenes.glass_figure [--out docs/img] [--density 64]`` (under a minute on
2 cores).  Writes ``glass_window.png``.
"""

from __future__ import annotations

from pathlib import Path

import bpy
import addon_utils  # Blender's module: importable once bpy is
import numpy as np

from . import daylight_room as R
from .daylight_figures import figure_parser, save, top_view
from .meshes import mesh_from_quads


def glass_pane():
    """A Glass BSDF pane (IOR 1.5, smooth, white) filling the window opening."""
    mat = bpy.data.materials.new("Window_Glass")
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    tree = mat.node_tree
    tree.nodes.remove(tree.nodes["Principled BSDF"])
    glass = tree.nodes.new("ShaderNodeBsdfGlass")
    glass.inputs["Roughness"].default_value = 0.0
    glass.inputs["IOR"].default_value = 1.5
    tree.links.new(glass.outputs[0], tree.nodes["Material Output"].inputs["Surface"])
    (x0, x1), (z0, z1), y = R.WINDOW["x"], R.WINDOW["z"], R.ROOM["y"][0]
    return mesh_from_quads("Pane", [((x0, y, z0), (x1, y, z0), (x1, y, z1), (x0, y, z1))],
                           material=mat)


def _doses(api, scene, objects, portals):
    scene.lightfade_bake.window_portals = portals
    result = api.bake(scene, objects=[scene.objects[o] for o in objects], quality="FINAL")
    doses = {o: sum(api.annual_dose(scene, scene.objects[o]).values()) for o in objects}
    return doses, result["notes"]


def make(out, density=64.0):
    from lightfade_addon import api
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib import pyplot as plt

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    panels = []
    for glass, portals, title in ((True, False, "glass, Portals over Windows off"),
                                  (True, True, "glass, Portals over Windows on"),
                                  (False, True, "no glass (open window), on")):
        names = R.build()
        addon_utils.enable("lightfade_addon", default_set=True)
        if glass:
            glass_pane()
        scene = bpy.context.scene
        scene.lightfade_bake.texels_per_metre = density
        api.set_daylight(scene, **R.PLACE)
        objects = [names["floor"], names["rug"]]
        doses, _ = _doses(api, scene, objects, portals)
        panels.append((title, top_view(doses, objects)))
    top = max(float(np.percentile(p, 99.5)) for _t, p in panels)
    fig, axes = plt.subplots(1, 3, figsize=(11.4, 4.2), dpi=110)
    for ax, (title, values) in zip(axes, panels):
        ax.imshow(values / top, origin="lower", extent=(-2, 2, -2, 2), cmap="inferno",
                  vmin=0, vmax=1)
        ax.set_title(f"{title}\nmean {values.mean() / 1e6:.3g} Mlx·h a year", fontsize=8)
        ax.set_xlabel("x (m)   window: south wall, y = -2", fontsize=7)
        ax.tick_params(labelsize=6)
    fig.suptitle("Floor and rug dose under the year's daylight at 52° N, default quality "
                 "(8 samples, denoised), one scale", fontsize=9)
    save(fig, out / "glass_window.png")
    return out


def main(argv=None):
    args = figure_parser(__doc__).parse_args(argv)
    print(make(args.out, args.density))


if __name__ == "__main__":
    main()
