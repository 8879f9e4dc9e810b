"""The furnished room of public CC0 assets aged 0, 10, 25 and 50 years, two views: a figure.

    ./run py tools/furnished_room_figure.py ASSETS_DIR docs/img/furnished_room_years.png
    ./run py tools/furnished_room_figure.py ASSETS_DIR out/years.png --blend out/room_aged.blend

Without ``--blend`` the room is built (:func:`tools.furnished_room.build`: 52° N, annual
daylight through its window), baked at the scene's default quality (Final, a few minutes
on 2 cores) and aged; with it, the file must hold the room already aged (Age pressed).
Each view is rendered in Cycles (CPU, denoised) at each years value, with the frame
images LightFade writes before a render where it is installed, and the renders are laid
out as a contact sheet: one row per view, one column per years value.
"""

from __future__ import annotations

import argparse
import pathlib
import sys
import tempfile

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))

from tools.furnished_room import ROOM_VIEW, place_camera  # noqa: E402

#: name -> (location in metres, rotation in degrees (X, Y, Z), lens in mm, what it shows).
VIEWS = {
    "towards the window": (*ROOM_VIEW, "sofa, curtains, floor in the sun"),
    "from the window": ((-0.3, -1.3, 1.5), (80.0, 0.0, 8.0), 18.0,
                        "cabinets, stool, door, the floor's shade"),
}


def aged_room(assets, blend=None):
    """The aged room's scene: ``blend`` opened, or the room built, baked and aged."""
    import bpy  # first: it puts Blender's modules (addon_utils) on the path
    import addon_utils

    if blend is not None:
        bpy.ops.wm.open_mainfile(filepath=str(pathlib.Path(blend).resolve()))
        addon_utils.enable("lightfade_addon", default_set=False)
        return bpy.context.scene
    from lightfade_addon import api
    from tools import furnished_room

    furnished_room.build(assets)
    scene = bpy.context.scene
    api.bake(scene)
    api.age_scene(scene, years=0.0)
    return scene


def render_years(scene, years, folder, size, samples, exposure):
    """{(view, years): PNG path} of every view at every years value, the film brightened
    by ``exposure`` stops (the room is lit by its window alone)."""
    import bpy

    from lightfade_addon import api
    from scenes.render import configure_render

    configure_render(scene, *size, samples, view_transform="AgX")
    scene.view_settings.exposure = exposure
    paths = {}
    for view, (location, rotation, lens, _) in VIEWS.items():
        place_camera(scene, "LightFadeFigure " + view, location, rotation, lens)
        for y in years:
            api.set_years(scene, y)
            path = pathlib.Path(folder) / f"{view.replace(' ', '_')}_{y:g}.png"
            scene.render.filepath = str(path)
            bpy.ops.render.render(write_still=True)
            print(f"rendered {view}, {y:g} years", flush=True)
            paths[view, y] = path
    return paths


def sheet(paths, years, title):
    """The contact sheet (PIL image): a row per view, a column per years value."""
    from PIL import Image

    from lightfade_addon.contact_sheet import contact_sheet

    tiles, labels, sublabels = [], [], []
    for view, (*_, shows) in VIEWS.items():
        for y in years:
            tiles.append(Image.open(paths[view, y]).convert("RGB"))
            labels.append(f"{y:g} years")
            sublabels.append(f"{view}: {shows}")
    return contact_sheet(tiles, labels, sublabels, title=title, columns=len(years))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("assets", type=pathlib.Path, help="folder of the CC0 .gltf files")
    ap.add_argument("output", type=pathlib.Path, help="the figure (PNG)")
    ap.add_argument("--blend", type=pathlib.Path, help="an aged furnished room (.blend)")
    ap.add_argument("--years", type=float, nargs="+", default=(0.0, 10.0, 25.0, 50.0))
    ap.add_argument("--size", type=int, nargs=2, default=(480, 300))
    ap.add_argument("--samples", type=int, default=64)
    ap.add_argument("--exposure", type=float, default=2.5, help="film exposure, stops")
    args = ap.parse_args(argv)

    scene = aged_room(args.assets, args.blend)
    with tempfile.TemporaryDirectory(prefix="lf_room_fig_") as folder:
        paths = render_years(scene, args.years, folder, args.size, args.samples,
                             args.exposure)
        title = ("A furnished room of public CC0 assets under annual daylight at 52° N "
                 "through its one window: years of exposure")
        image = sheet(paths, args.years, title)
        args.output.parent.mkdir(parents=True, exist_ok=True)
        image.save(args.output)
    print("wrote", args.output)


if __name__ == "__main__":
    main()
