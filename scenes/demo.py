"""The LightFade demo: the paper's Figure 9 redone, plus a gallery wall, a test chart and
eight kinds of artist materials.

For each scene (``room``, ``gallery``, ``swatches``, ``materials``) it builds the scripted
scene, maps the scene's ``lightfade_*`` custom tags to LightFade settings
(:func:`scenes.tags.apply_tags`), bakes the exposure maps, prepares aging once, and
renders a sequence of years with ``api.set_years`` between renders (only the
dose-dependent part runs). The room and the swatches also get the reveal state (rug and
lamp, or the card, removed) at the last year.
Outputs, all in one folder (``--out``, default ``out/demo/``)::

    room_0y.png ... room_25y.png    the years sequence (main camera)
    room_reveal_25y.png             rug and lamp removed after 25 years
    room_dresser_*.png              the dresser close-up: 0 y, 25 y, lamp removed
    room_floor_*.png                looking down at the rug's place: 25 y, rug removed
    gallery_*.png, swatches_*.png   the other scenes' sequences
    materials_*.png                 eight kinds of material graphs, half of each in shade
    contact_<scene>.png             labelled contact sheet per scene
    room.gif                        the room's years as an animation
    <scene>.blend                   the aged scene: open it and drag Scene > LightFade > Years

Run ``python -m scenes.demo`` (or ``./run demo``); ``--quick`` makes a tiny version in
seconds (used by the tests); ``--docs`` also writes small images to ``docs/img/``.

This module is the run (presets, one scene, the command line); the pictures it writes
are drawn by :mod:`scenes.demo_figures`.
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

from scenes import common as C  # noqa: E402
from scenes import gallery, materials, room, swatches  # noqa: E402
from scenes.demo_figures import (  # noqa: E402
    dose_label, write_contact_sheet, write_docs, write_gif, years_label, years_slug)
from scenes.render import apply_view_settings, configure_render, render_still  # noqa: E402
from scenes.tags import annual_doses, apply_tags, peak_annual_dose  # noqa: E402

ADDON = "lightfade_addon"

#: Render and bake sizes. "full" keeps the whole demo (four scenes) well under 10 minutes
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
    # linked duplicates, an image control), labelled, half of each in shade; 2,000 lux
    # 8 h a day (5.8 Mlx·h a year): a visible fade after 2 years, clearly faded after 10;
    # small maps suffice
    "materials": dict(module=materials, years=(0, 2, 10), quick_years=(0, 10), reveal=False,
                      texture_scale=0.0625, max_bake_resolution=128),
}


def log(msg):
    print(f"[demo] {msg}", flush=True)


def quiet(enabled=True):
    """Silence what Cycles prints to stdout (per-tile and bake chatter) when ``enabled``."""
    from lightfade_addon.blender.bake.state import quiet_stdout

    return quiet_stdout() if enabled else contextlib.nullcontext()


# ----------------------------------------------------------------------- the add-on


def _addon():
    if str(ROOT) not in sys.path:
        sys.path.insert(0, str(ROOT))
    addon_utils.enable(ADDON, default_set=True)
    if not hasattr(bpy.types.Scene, "lightfade"):
        raise RuntimeError(f"could not enable the {ADDON} add-on")
    from lightfade_addon import api

    return api


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

    Like :func:`scenes.render.save_blend`, except that LightFade's aged images
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
    from lightfade_addon.output import maps_made, plural   # once enabled: no addon_utils warning
    scene = bpy.context.scene
    tags = apply_tags(scene)
    floor_cam = add_floor_camera() if name == "room" else None
    timings["build"] = time.perf_counter() - t0
    mats = ", ".join(f"{m} {v['recipe']} BW{v['blue_wool']}" for m, v in tags["materials"].items())
    log(f"{name}: built, {plural(len(tags['materials']), 'aging material')} ({mats}) "
        f"... {timings['build']:.1f} s")
    for em, sch in tags["emitters"].items():
        if sch is None:
            log(f"{name}:   emitter {em}: untagged, excluded")
        else:
            log(f"{name}:   emitter {em}: {sch['spectrum']}, {sch['hours_per_day']:g} h/day"
                f"{', UV filter' if sch['uv_filter'] else ''}")
    if tags.get("daylight"):
        day = tags["daylight"]
        log(f"{name}:   daylight: {day['latitude']:g}° N, {day['longitude']:g}° E, north "
            f"{day['north']:g}°, {day.get('weather') or 'clear sky'}: one annual bake "
            "(sun lamps and sky standing for daylight muted in the exposure bake)")

    # bake
    t0 = time.perf_counter()
    with quiet(not verbose):
        bake_resolution = min(preset["bake_resolution"],
                              spec.get("max_bake_resolution", preset["bake_resolution"]))
        result = api.bake(scene, resolution=bake_resolution, samples=preset["bake_samples"],
                          margin=preset["bake_margin"])
    timings["bake"] = time.perf_counter() - t0
    log(f"{name}: baked {maps_made(result)}, {bake_resolution} px, "
        f"{plural(preset['bake_samples'], 'sample')} ... {timings['bake']:.1f} s")
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
    configure_render(scene, *preset["size"], samples=preset["samples"])
    apply_view_settings(scene, info["view"])
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
            t = render_still(str(path), camera=camera, scene=scene)
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
    log(f"{name}: {plural(len(renders), 'render')} {preset['size'][0]}x{preset['size'][1]}, "
        f"{plural(preset['samples'], 'sample')} ... {timings['render']:.1f} s "
        f"(set_years total {timings['set_years']:.2f} s)")
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


# ----------------------------------------------------------------------- CLI


def outputs_line(name, outputs):
    """What one scene wrote, every rendered frame counted: "room: 11 frames rendered
    (5 of the years, 1 reveal, 5 from Camera.Dresser and Camera.Floor), contact_room.png,
    room.gif, room.blend"."""
    from lightfade_addon.output import plural

    years, reveal = len(outputs["frames"]), len(outputs["reveal"])
    views = {cam: len(paths) for cam, paths in outputs["extra"].items() if paths}
    parts = [f"{years} of the years"] + ([f"{reveal} reveal"] if reveal else [])
    if views:
        parts.append(f"{sum(views.values())} from {' and '.join(views)}")
    files = [Path(outputs[k]).name for k in ("contact", "gif", "blend") if k in outputs]
    total = years + reveal + sum(views.values())
    return f"{name}: {plural(total, 'frame')} rendered ({', '.join(parts)}), {', '.join(files)}"


def main(argv=None):
    p = argparse.ArgumentParser(prog="python -m scenes.demo", description=__doc__.splitlines()[0])
    p.add_argument("--scenes", nargs="+", choices=list(SCENES), default=list(SCENES),
                   help="scenes to run, in order (default: all four)")
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
        log(f"    {outputs_line(name, r['outputs'])}")
    for d in docs:
        log(f"  docs: {d} ({os.path.getsize(d) / 1000:.0f} kB)")
    return dict(results=results, total=total, out=str(out), docs=[str(d) for d in docs])


if __name__ == "__main__":
    main()
