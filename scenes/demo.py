"""The LightFade demo: the paper's Figure 9 redone, plus a gallery wall and a test chart.

For each scene (``room``, ``gallery``, ``swatches``) it builds the scripted scene, maps the
scene's ``lightfade_*`` custom tags to LightFade settings (:func:`apply_tags`), bakes the
exposure maps, prepares aging once, and renders a sequence of years with
``api.set_years`` between renders (only the dose-dependent part runs). The room and the
swatches also get the reveal state (rug and lamp, or the card, removed) at the last year.
Outputs, all in one folder (``--out``, default ``out/demo/``)::

    room_0y.png ... room_25y.png    the years sequence (main camera)
    room_reveal_25y.png             rug and lamp removed after 25 years
    room_dresser_*.png              the dresser close-up: 0 y, 25 y, lamp removed
    room_floor_*.png                looking down at the rug's place: 25 y, rug removed
    gallery_*.png, swatches_*.png   the other scenes' sequences
    contact_<scene>.png             labelled contact sheet per scene
    room.gif                        the room's years as an animation
    <scene>.blend                   the aged scene: open it and drag Scene > LightFade > Years

Run ``python -m scenes.demo`` (or ``./run demo``); ``--quick`` makes a tiny version in
seconds (used by the tests); ``--docs`` also writes small images to ``docs/img/``.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

import bpy  # noqa: E402, I001  (first: it makes Blender's own modules importable)
import addon_utils  # noqa: E402
import numpy as np  # noqa: E402

from scenes import common as C  # noqa: E402
from scenes import gallery, materials, room, swatches  # noqa: E402

ADDON = "lightfade_addon"
DOCS_IMG = ROOT / "docs" / "img"
DOCS_PNG_LIMIT = 400_000  # bytes
DOCS_GIF_LIMIT = 3_000_000
DOCS_GIF_WIDTH = 480

#: Render and bake sizes. "full" keeps the whole demo (three scenes) well under 10 minutes
#: on two CPU cores; "quick" is a smoke test that runs in seconds.
PRESETS = {
    "full": dict(texture=1024, bake_resolution=384, bake_samples=16, bake_margin=8,
                 size=(576, 360), samples=20),
    "quick": dict(texture=96, bake_resolution=64, bake_samples=2, bake_margin=2,
                  size=(160, 100), samples=2),
}

#: Years shown per scene and the extra cameras rendered for the reveal.
#: room: the sun patch gives ~45 Mlx·h a year on the floor; the rug (Blue Wool 4)
#: shows a clear fade within a year and is washed out after ~10; the floor's yellowing
#: saturates after ~5 years. gallery: 50-150 lux, 8 h a day (0.15-0.44 Mlx·h a year).
#: swatches: a 50 klx light-fastness test, 24 h a day (~440 Mlx·h a year).
SCENES = {
    "room": dict(module=room, years=(0, 1, 3, 10, 25), quick_years=(0, 25), reveal=True,
                 texture_scale=1.0),
    "gallery": dict(module=gallery, years=(0, 10, 25, 50, 100), quick_years=(0, 50),
                    reveal=False, texture_scale=0.5),
    "swatches": dict(module=swatches, years=(0, 7 / 365, 1 / 12, 0.25, 1), quick_years=(0, 1),
                     reveal=True, texture_scale=1.0),
    # eight kinds of artist materials (tiled, procedural, mixed, grouped, attribute, shared,
    # linked duplicates, an image control), half of each in shade; small maps suffice
    "materials": dict(module=materials, years=(0, 2, 10), quick_years=(0, 10), reveal=False,
                      texture_scale=0.0625, max_bake_resolution=128),
}


def log(msg):
    print(f"[demo] {msg}", flush=True)


def quiet(enabled=True):
    """Silence what Cycles prints to stdout (per-tile and bake chatter) when ``enabled``."""
    from lightfade_addon.blender.bake.state import quiet_stdout

    return quiet_stdout() if enabled else contextlib.nullcontext()


# ----------------------------------------------------------------------- tags -> settings


def _addon():
    if str(ROOT) not in sys.path:
        sys.path.insert(0, str(ROOT))
    addon_utils.enable(ADDON, default_set=True)
    if not hasattr(bpy.types.Scene, "lightfade"):
        raise RuntimeError(f"could not enable the {ADDON} add-on")
    from lightfade_addon import api

    return api


def _schedule_from_tags(schedule, idb, spectrum_enum):
    """Copy ``lightfade_*`` tags of ``idb`` to a LightFade schedule; untagged: excluded."""
    if "lightfade_spectrum" not in idb:
        schedule.enabled = False
        return None
    schedule.enabled = True
    schedule.spectrum = spectrum_enum[idb["lightfade_spectrum"]]
    schedule.hours_per_day = float(idb.get("lightfade_hours_per_day", schedule.hours_per_day))
    schedule.days_per_year = float(idb.get("lightfade_days_per_year", schedule.days_per_year))
    schedule.uv_filter = bool(idb.get("lightfade_uv_filter", False))
    return dict(spectrum=idb["lightfade_spectrum"], hours_per_day=schedule.hours_per_day,
                days_per_year=schedule.days_per_year, uv_filter=schedule.uv_filter)


def apply_tags(scene):
    """Map the scene's custom tags to LightFade settings.

    - A material with ``mat["lightfade_recipe"]`` gets ``Material.lightfade.enabled``, the
      recipe and, if tagged, ``mat["lightfade_blue_wool"]`` (set after the recipe, whose
      update callback resets the class to the recipe's own); untagged materials are left off.
    - Lights, the world and meshes with ``lightfade_spectrum`` get their schedule from
      ``lightfade_spectrum`` / ``_hours_per_day`` / ``_uv_filter`` (and ``_days_per_year``,
      default 365). Untagged emitters are excluded from aging: in these scenes every
      light that belongs to the room's history is tagged (the room's sky through the
      window is tagged daylight-glass, 10 h a day, so it counts).

    Returns
    -------
    dict
        ``materials`` {name: {recipe, blue_wool}} and ``emitters`` {name: schedule or None}.
    """
    from lightfade_addon.blender.properties import RECIPE_IDS, SPECTRUM_IDS

    recipe_enum = {v: k for k, v in RECIPE_IDS.items()}
    spectrum_enum = {v: k for k, v in SPECTRUM_IDS.items()}
    out = dict(materials={}, emitters={})
    materials = []
    for obj in scene.objects:
        for slot in getattr(obj, "material_slots", ()):
            if slot.material is not None and slot.material not in materials:
                materials.append(slot.material)
    for mat in materials:
        props = mat.lightfade
        if "lightfade_recipe" not in mat:
            props.enabled = False
            continue
        props.enabled = True
        props.recipe = recipe_enum[mat["lightfade_recipe"]]
        props.sensitivity_mode = "BLUE_WOOL"
        if "lightfade_blue_wool" in mat:
            props.blue_wool = int(mat["lightfade_blue_wool"])
        out["materials"][mat.name] = dict(recipe=mat["lightfade_recipe"], blue_wool=props.blue_wool)
    for obj in scene.objects:
        if obj.type == "LIGHT":
            out["emitters"][obj.name] = _schedule_from_tags(obj.data.lightfade, obj.data, spectrum_enum)
        elif obj.type == "MESH" and "lightfade_spectrum" in obj:
            out["emitters"][obj.name] = _schedule_from_tags(obj.lightfade_emitter, obj, spectrum_enum)
        elif obj.type == "MESH":
            obj.lightfade_emitter.enabled = False
    if scene.world is not None:
        out["emitters"]["World"] = _schedule_from_tags(scene.world.lightfade, scene.world, spectrum_enum)
    return out


# ----------------------------------------------------------------------- doses and labels


def annual_doses(scene):
    """{object name: (H, W) lux·h per year} from the baked maps and the emitters' schedules."""
    from lightfade_addon.blender.exposure import lights_and_exposure

    doses = {}
    for obj in scene.objects:
        if obj.type != "MESH" or not len(obj.lightfade.exposure_maps):
            continue
        first = next((m.image for m in obj.lightfade.exposure_maps if m.image is not None), None)
        if first is None:
            continue
        shape = tuple(first.size)[::-1]
        lights, maps = lights_and_exposure(scene, obj, shape)
        doses[obj.name] = sum(light.annual_dose * m for light, m in zip(lights, maps))
    return doses


def peak_annual_dose(doses):
    """The dose rate (lux·h a year) at the brightest point: 99.9th percentile of all texels."""
    if not doses:
        return 0.0
    return float(np.percentile(np.concatenate([d.ravel() for d in doses.values()]), 99.9))


def years_label(years):
    if years == 0:
        return "0 years"
    if years < 1 / 12 - 1e-9:
        d = round(years * 365)
        return f"{d} day{'s' * (d != 1)}"
    if years < 1 - 1e-9:
        m = round(years * 12)
        return f"{m} month{'s' * (m != 1)}"
    return f"{years:g} year{'s' * (years != 1)}"


def years_slug(years):
    if years == 0 or years >= 1 - 1e-9:
        return f"{years:g}y"
    if years < 1 / 12 - 1e-9:
        return f"{round(years * 365)}d"
    return f"{round(years * 12)}mo"


def dose_label(mlxh):
    if mlxh == 0:
        return ""
    if mlxh < 10:
        return f"peak {mlxh:.2g} Mlx·h"
    return f"peak {mlxh:,.0f} Mlx·h"


# ----------------------------------------------------------------------- images (Pillow)


def _font(size):
    from PIL import ImageFont

    try:
        from matplotlib import font_manager

        return ImageFont.truetype(font_manager.findfont("DejaVu Sans"), size)
    except Exception:  # noqa: BLE001 - any font will do
        return ImageFont.load_default()


def labelled(path, label, sublabel="", bar=None):
    """The image at ``path`` with a caption bar under it."""
    from PIL import Image, ImageDraw

    im = Image.open(path).convert("RGB")
    w, h = im.size
    bar = bar or max(16, int(0.11 * h))
    out = Image.new("RGB", (w, h + bar), (24, 24, 24))
    out.paste(im, (0, 0))
    d = ImageDraw.Draw(out)
    size = max(9, int(bar * 0.55))
    font = _font(size)
    d.text((6, h + (bar - size) // 2 - 1), label, fill=(240, 240, 240), font=font)
    if sublabel:
        small = _font(max(8, int(size * 0.8)))
        tw = d.textlength(sublabel, font=small)
        d.text((w - tw - 6, h + (bar - size) // 2), sublabel, fill=(170, 170, 170), font=small)
    return out


def write_contact_sheet(frames, path, title="", columns=3):
    """Frames ``[(png, label, sublabel), ...]`` at their rendered size in a grid of
    ``columns``, labelled under each, with a title (:mod:`lightfade_addon.contact_sheet`)."""
    from PIL import Image

    from lightfade_addon.contact_sheet import contact_sheet, thumbnail

    tiles = []
    for png, _, _ in frames:
        rgb = np.asarray(Image.open(png).convert("RGB"), np.float32) / 255.0
        tiles.append(thumbnail(rgb, size=max(rgb.shape[:2])))
    sheet = contact_sheet(tiles, [f[1] for f in frames], [f[2] for f in frames], title=title,
                          columns=columns)
    sheet.save(path, optimize=True)
    return sheet


def write_gif(frames, path, width=None, ms=900, hold_ms=2200):
    """Animated GIF of labelled frames ``[(png, label, sublabel), ...]``, looping."""
    from PIL import Image

    tiles = [labelled(p, lab, sub) for p, lab, sub in frames]
    if width and tiles[0].width > width:
        h = round(tiles[0].height * width / tiles[0].width)
        tiles = [t.resize((width, h), Image.LANCZOS) for t in tiles]
    # Pillow dithers only when mapping to a given palette: make the palette, then map.
    pal = [t.quantize(palette=t.quantize(colors=255, method=Image.Quantize.MEDIANCUT),
                      dither=Image.Dither.FLOYDSTEINBERG) for t in tiles]
    durations = [ms] * len(pal)
    durations[0] = durations[-1] = hold_ms
    pal[0].save(path, save_all=True, append_images=pal[1:], duration=durations, loop=0,
                optimize=True, disposal=1)
    return path


def save_small_png(image, path, limit=DOCS_PNG_LIMIT):
    """Save ``image`` as PNG under ``limit`` bytes: full colour, scaled down to 70 % if need
    be (palette PNGs band on smooth walls), else 256 colours, else smaller still."""
    from PIL import Image

    image = image.convert("RGB")
    for scale in (1.0, 0.9, 0.8, 0.7):
        im = image if scale == 1.0 else image.resize(
            (round(image.width * scale), round(image.height * scale)), Image.LANCZOS)
        im.save(path, optimize=True)
        if os.path.getsize(path) <= limit:
            return path
    for scale in (1.0, 0.8, 0.6, 0.4):
        im = image if scale == 1.0 else image.resize(
            (round(image.width * scale), round(image.height * scale)), Image.LANCZOS)
        im.quantize(colors=256, method=Image.Quantize.FASTOCTREE,
                    dither=Image.Dither.FLOYDSTEINBERG).save(path, optimize=True)
        if os.path.getsize(path) <= limit:
            return path
    raise RuntimeError(f"could not fit {path} under {limit} bytes")


def side_by_side(frames, width=None):
    """Labelled frames ``[(png, label, sublabel), ...]`` in one row (each ``width`` px wide)."""
    from PIL import Image

    tiles = [labelled(p, lab, sub) for p, lab, sub in frames]
    if width and tiles[0].width != width:
        h = round(tiles[0].height * width / tiles[0].width)
        tiles = [t.resize((width, h), Image.LANCZOS) for t in tiles]
    gap = 4
    tw, th = tiles[0].size
    out = Image.new("RGB", (len(tiles) * tw + (len(tiles) - 1) * gap, th), (12, 12, 12))
    for i, t in enumerate(tiles):
        out.paste(t, (i * (tw + gap), 0))
    return out


# ----------------------------------------------------------------------- the room's extra view


@contextlib.contextmanager
def sky_light_only(scene, stops=3.0):
    """Hide the sun lamps from the render and open the exposure by ``stops``."""
    suns = [o for o in scene.objects if o.type == "LIGHT" and o.data.type == "SUN" and not o.hide_render]
    exposure = scene.view_settings.exposure
    try:
        for o in suns:
            o.hide_render = True
        scene.view_settings.exposure = exposure + stops
        yield
    finally:
        for o in suns:
            o.hide_render = False
        scene.view_settings.exposure = exposure


def add_floor_camera():
    """A camera looking steeply down at the rug's place (the floor footprint after the reveal)."""
    cx, cy = room.RUG["center"]
    cam = C.add_camera("Camera.Floor", (cx + 0.55, cy - 1.95, 2.35), (cx + 0.1, cy + 0.15, 0.0), lens=18.0)
    return cam.name


# ----------------------------------------------------------------------- saving


def save_blend(path):
    """Save the aged scene with every image packed.

    Like :func:`scenes.common.save_blend`, except that LightFade's aged images
    (``LF_Aged_*``) are left to the add-on's own ``save_pre`` handler, which packs them:
    packing them here as well would make that handler pack them a second time, and in
    bpy 5.0 ``Image.pack()`` on an already packed, unchanged float image drops its packed
    data (the file would then hold no aged pixels).
    """
    for img in bpy.data.images:
        if img.name.startswith("LF_Aged_"):
            continue
        if img.source in {"GENERATED", "FILE"} and img.packed_file is None and img.has_data:
            img.pack()
    bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(path), compress=True)
    missing = [i.name for i in bpy.data.images if i.name.startswith("LF_Aged_") and i.packed_file is None]
    if missing:
        raise RuntimeError(f"{path}: aged images not packed: {', '.join(missing)}")


# ----------------------------------------------------------------------- one scene


def run_scene(name, out, preset, years=None, verbose=False):
    """Build, tag, bake, age and render one scene; returns a dict of outputs and timings."""
    spec = SCENES[name]
    module = spec["module"]
    years = list(years if years is not None else spec["years"])
    timings = {}
    out = Path(out)
    t_scene = time.perf_counter()

    t0 = time.perf_counter()
    if addon_utils.check(ADDON)[1]:
        addon_utils.disable(ADDON, default_set=True)
    info = module.build(resolution=max(32, int(preset["texture"] * spec["texture_scale"])))
    api = _addon()
    scene = bpy.context.scene
    tags = apply_tags(scene)
    floor_cam = add_floor_camera() if name == "room" else None
    timings["build"] = time.perf_counter() - t0
    mats = ", ".join(f"{m} {v['recipe']} BW{v['blue_wool']}" for m, v in tags["materials"].items())
    log(f"{name}: built, {len(tags['materials'])} aging materials "
        f"({mats}) "
        f"... {timings['build']:.1f} s")
    for em, sch in tags["emitters"].items():
        if sch is None:
            log(f"{name}:   emitter {em}: untagged, excluded")
        else:
            log(f"{name}:   emitter {em}: {sch['spectrum']}, {sch['hours_per_day']:g} h/day"
                f"{', UV filter' if sch['uv_filter'] else ''}")

    # bake
    t0 = time.perf_counter()
    with quiet(not verbose):
        bake_resolution = min(preset["bake_resolution"],
                              spec.get("max_bake_resolution", preset["bake_resolution"]))
        result = api.bake(scene, resolution=bake_resolution, samples=preset["bake_samples"],
                          margin=preset["bake_margin"])
    n_maps = sum(len(v) for v in result["maps"].values())
    timings["bake"] = time.perf_counter() - t0
    log(f"{name}: baking {n_maps} maps ({len(result['maps'])} objects x {len(result['emitters'])} emitters, "
        f"{bake_resolution} px, {preset['bake_samples']} samples) ... {timings['bake']:.1f} s")
    for msg in result.get("skipped", []):
        log(f"{name}:   bake skipped: {msg}")

    # age (prepare once)
    t0 = time.perf_counter()
    with quiet(not verbose):
        api.age_scene(scene, years=0.0)
    timings["age"] = time.perf_counter() - t0
    peak = peak_annual_dose(annual_doses(scene))
    log(f"{name}: aging prepared (grids, unmixing) ... {timings['age']:.1f} s; "
        f"peak dose {peak / 1e6:.3g} Mlx·h a year")

    # render the years
    C.configure_render(scene, *preset["size"], samples=preset["samples"])
    C.apply_view_settings(scene, info["view"])
    main_cam = info["camera"]
    groups = {"years": [], "reveal": [], "dresser": [], "floor": []}
    renders, set_times = [], []
    last = years[-1]

    def set_years(y):
        t0 = time.perf_counter()
        api.set_years(scene, y)
        set_times.append(time.perf_counter() - t0)

    def shot(group, fname, camera, y, label=None):
        path = out / fname
        with quiet(not verbose):
            t = C.render_still(str(path), camera=camera, scene=scene)
        renders.append(t)
        groups[group].append((str(path), label or years_label(y), dose_label(peak * y / 1e6)))
        log(f"{name}: {years_label(y):>9} -> {path.name} ({t:.1f} s)")

    for y in years:
        set_years(y)
        shot("years", f"{name}_{years_slug(y)}.png", main_cam, y)
        if name == "room" and y in (years[0], last):
            shot("dresser", f"{name}_dresser_{years_slug(y)}.png", "Camera.Dresser", y)
    if spec["reveal"]:
        what = "rug and lamp removed" if name == "room" else "card removed"
        module.set_reveal(True)
        shot("reveal", f"{name}_reveal_{years_slug(last)}.png", main_cam, last,
             f"{years_label(last)}, {what}")
        if name == "room":
            shot("dresser", f"{name}_dresser_reveal_{years_slug(last)}.png", "Camera.Dresser", last,
                 f"{years_label(last)}, lamp removed")
            # The rug's footprint on the floor, seen in sky light only (the sun patch's
            # brightness would otherwise dominate): the floor as new, and after the years.
            with sky_light_only(scene):
                for y in (0, last):
                    set_years(y)
                    shot("floor", f"{name}_floor_reveal_{years_slug(y)}.png", floor_cam, y,
                         f"{years_label(y)}, rug removed, sky light")
        module.set_reveal(False)
    timings["render"] = sum(renders)
    timings["set_years"] = sum(set_times)
    log(f"{name}: {len(renders)} renders {preset['size'][0]}x{preset['size'][1]}, {preset['samples']} samples "
        f"... {timings['render']:.1f} s (set_years total {timings['set_years']:.2f} s)")
    frames, reveal_frames = groups["years"], groups["reveal"]
    extra = {"Camera.Dresser": groups["dresser"], "Camera.Floor": groups["floor"]} if name == "room" else {}

    # contact sheet, animation, .blend
    t0 = time.perf_counter()
    sheet_frames = frames + reveal_frames
    for v in extra.values():
        sheet_frames += v
    title = f"LightFade - {name}: " + ", ".join(
        f"{em} {s['spectrum']} {s['hours_per_day']:g} h/day" for em, s in tags["emitters"].items() if s)
    contact = out / f"contact_{name}.png"
    write_contact_sheet(sheet_frames, contact, title=title, columns=3)
    outputs = dict(frames=[f[0] for f in frames], reveal=[f[0] for f in reveal_frames],
                   extra={cam: [f[0] for f in v] for cam, v in extra.items()}, contact=str(contact))
    if name == "room":
        gif = out / "room.gif"
        write_gif(frames + reveal_frames, gif)
        outputs["gif"] = str(gif)
    api.set_years(scene, last)
    scene.camera = bpy.data.objects[main_cam]
    blend = out / f"{name}.blend"
    with quiet(not verbose):
        save_blend(blend)
    outputs["blend"] = str(blend)
    timings["outputs"] = time.perf_counter() - t0
    timings["total"] = time.perf_counter() - t_scene
    log(f"{name}: contact sheet{', gif' if name == 'room' else ''}, {blend.name} ... "
        f"{timings['outputs']:.1f} s; scene total {timings['total']:.1f} s")
    return dict(name=name, years=years, timings=timings, outputs=outputs, tags=tags,
                peak_annual_dose=peak, frames=frames, reveal_frames=reveal_frames, extra=extra)


# ----------------------------------------------------------------------- docs images


def write_docs(results, docs=DOCS_IMG):
    """Small images for the README: before/after/reveal strips, contact sheets, the GIF."""
    docs = Path(docs)
    docs.mkdir(parents=True, exist_ok=True)
    written = []
    r = results.get("room")
    if r:
        strip = [r["frames"][0], r["frames"][-1], *r["reveal_frames"]]
        p = docs / "demo_room_before_after.png"
        save_small_png(side_by_side(strip, width=480), p)
        written.append(p)
        dresser = r["extra"].get("Camera.Dresser", [])
        if dresser:
            p = docs / "demo_dresser.png"
            save_small_png(side_by_side(dresser, width=400), p)
            written.append(p)
        floor = r["extra"].get("Camera.Floor", [])
        if floor:
            p = docs / "demo_floor.png"
            save_small_png(side_by_side(floor, width=400), p)
            written.append(p)
        p = docs / "demo.gif"
        write_gif(r["frames"] + r["reveal_frames"], p, width=DOCS_GIF_WIDTH)
        if os.path.getsize(p) > DOCS_GIF_LIMIT:
            write_gif(r["frames"] + r["reveal_frames"], p, width=DOCS_GIF_WIDTH // 2)
        written.append(p)
    for name in ("gallery", "swatches"):
        s = results.get(name)
        if s:
            p = docs / f"demo_{name}.png"
            strip = [s["frames"][0], s["frames"][len(s["frames"]) // 2], s["frames"][-1], *s["reveal_frames"]]
            save_small_png(side_by_side(strip, width=360), p)
            written.append(p)
    return written


# ----------------------------------------------------------------------- CLI


def main(argv=None):
    p = argparse.ArgumentParser(prog="python -m scenes.demo", description=__doc__.splitlines()[0])
    p.add_argument("--scenes", nargs="+", choices=list(SCENES), default=list(SCENES),
                   help="scenes to run, in order (default: all three)")
    p.add_argument("--out", default=str(ROOT / "out" / "demo"), help="output folder (default out/demo/)")
    p.add_argument("--quick", action="store_true", help="tiny textures, bakes and renders (a smoke test)")
    p.add_argument("--docs", action="store_true", help="also write small images to docs/img/")
    p.add_argument("--size", type=int, nargs=2, metavar=("W", "H"), help="render size (override)")
    p.add_argument("--samples", type=int, help="render samples (override)")
    p.add_argument("--bake-resolution", type=int, help="exposure map size (override)")
    p.add_argument("--bake-samples", type=int, help="bake samples (override)")
    p.add_argument("--verbose", action="store_true", help="show Cycles' and the bake's own output")
    args = p.parse_args(argv)

    preset = dict(PRESETS["quick" if args.quick else "full"])
    for key in ("size", "samples", "bake_resolution", "bake_samples"):
        if getattr(args, key) is not None:
            preset[key] = tuple(getattr(args, key)) if key == "size" else getattr(args, key)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    t_start = time.perf_counter()
    log(f"{'quick' if args.quick else 'full'} run: scenes {', '.join(args.scenes)} -> {out}")
    results = {}
    for name in args.scenes:
        spec = SCENES[name]
        results[name] = run_scene(name, out, preset, spec["quick_years"] if args.quick else None,
                                  verbose=args.verbose)
    docs = write_docs(results) if args.docs else []
    total = time.perf_counter() - t_start
    log("summary")
    for name, r in results.items():
        t = r["timings"]
        log(f"  {name:9s} build {t['build']:5.1f} s  bake {t['bake']:6.1f} s  age {t['age']:5.1f} s  "
            f"render {t['render']:6.1f} s  outputs {t['outputs']:4.1f} s  total {t['total']:6.1f} s")
    log(f"  total {total:.1f} s ({total / 60:.1f} min)")
    log(f"  outputs in {out}/")
    for name, r in results.items():
        o = r["outputs"]
        log(f"    {name}: {len(o['frames'])} frames, contact sheet {Path(o['contact']).name}"
            f"{', ' + Path(o['gif']).name if 'gif' in o else ''}, {Path(o['blend']).name}")
    for d in docs:
        log(f"  docs: {d} ({os.path.getsize(d) / 1000:.0f} kB)")
    return dict(results=results, total=total, out=str(out), docs=[str(d) for d in docs])


if __name__ == "__main__":
    main()
