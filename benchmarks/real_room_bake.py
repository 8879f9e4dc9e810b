"""Exposure on real meshes: the default bake against a many-sample bake, at points on the
surface, in a furnished room of public glTF assets.

Usage (from the repository root; the assets are not part of the repository)::

    python benchmarks/real_room_bake.py ASSET_DIR [--room furnished|open] [--density D]
        [--max-size N] [--seeds 2] [--samples 64] [--reference 256] [--reference-seeds 2]
        [--radius 0.06] [--reference-cache out/ref.npz]

The room is ``tools/furnished_room.py``'s by default (Drake's furnished living room, the
one issue 26 measured: its south window, the sofa with its back to it, the curtains
beside it; annual clear-sky daylight at 52° N); ``--room open`` takes
``tools/real_room.py``'s (an open south window, the sofa facing it).  The scene's own
density and max size (the defaults a user gets) unless given.  Its sofa and curtain are
baked, in this order and on the same UV maps (the first bake makes them), with

* the default quality (Final preset), seeds 0 … ``--seeds`` − 1 (each is one draw of
  the noise: the figures of one seed can pass where the next one's do not),
* a fixed bake of 8 samples (Custom quality, denoised: the Final preset before the
  adaptive bake), seed 0, for the time and noise side by side,
* ``--samples`` samples per texel (Custom quality, denoised), seed 0,
* ``--reference`` samples per texel (Custom quality, denoised), the seeds after the
  default's: the first is the reference (independent of the bakes above: another seed
  shares no path); the others, measured against it, are the reference's own noise, the
  floor under every figure.

Points: one per polygon, the centroid of its first triangle, read from each map
(bilinear) at its UV.  A point is *lit* where the reference gets at least 5 % of the
object's 99th-percentile lux.  Printed per object and bake:

* ``p95 point``: the 95th percentile over lit points of ``|bake - ref| / ref``;
* ``p95 3D``: the same after each point is averaged with the points within ``--radius``
  metres of it in 3D whose normals face the same way (dot > 0.5), in both bakes: what
  is left is blotches, not grain;
* the share of the map inside its UV islands;
* the bake's own estimate of its noise (adaptive bakes: p95 per lit texel, the error
  of the object's mean, samples and passes spent, whether it hit the cap);
* wall and CPU seconds of each bake (all objects), and their ratio to the default's and
  to the fixed 8-sample bake's;
* the panel's estimate of the default bake (map sizes, seconds after Calibrate) against
  the sizes and time the bake made.

The reference bakes are long (256 samples on a sofa and a curtain at the default
density: ~32 min of CPU on 2 cores); ``--reference-cache`` keeps their values at the
points (the polygons do not change with the UV map), so later runs bake only the
default and ``--samples``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import bpy  # noqa: E402
import numpy as np  # noqa: E402


def timed(fn):
    wall, cpu = time.perf_counter(), time.process_time()
    out = fn()
    return out, time.perf_counter() - wall, time.process_time() - cpu


def surface_points(obj, uv_name):
    """World centroid, normal and UV of the first triangle of each polygon."""
    mesh = obj.data
    mesh.calc_loop_triangles()
    n = len(mesh.loop_triangles)
    poly = np.empty(n, np.int64)
    mesh.loop_triangles.foreach_get("polygon_index", poly)
    first = np.unique(poly, return_index=True)[1]
    loops = np.empty(n * 3, np.int64)
    mesh.loop_triangles.foreach_get("loops", loops)
    verts = np.empty(n * 3, np.int64)
    mesh.loop_triangles.foreach_get("vertices", verts)
    co = np.empty(len(mesh.vertices) * 3)
    mesh.vertices.foreach_get("co", co)
    m = np.array(obj.matrix_world)
    co = co.reshape(-1, 3) @ m[:3, :3].T + m[:3, 3]
    uv = np.empty(len(mesh.loops) * 2)
    mesh.uv_layers[uv_name].data.foreach_get("uv", uv)
    tri = co[verts].reshape(n, 3, 3)[first]
    tri_uv = uv.reshape(-1, 2)[loops].reshape(n, 3, 2)[first]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-12)
    return tri.mean(axis=1), normal, tri_uv.mean(axis=1)


def read_map(image, uv):
    """Lux of ``image`` at UV points (bilinear; texel centres at (i + 0.5) / N)."""
    from scipy.ndimage import map_coordinates

    w, h = image.size
    px = np.empty(w * h * 4, np.float32)
    image.pixels.foreach_get(px)
    lux = px.reshape(h, w, 4)[..., 0].astype(np.float64)
    return map_coordinates(lux, [uv[:, 1] * h - 0.5, uv[:, 0] * w - 0.5], order=1, mode="nearest")


def smooth(values, centre, normal, radius):
    """Mean of ``values`` over the points within ``radius`` (m) facing the same way."""
    from scipy.spatial import cKDTree

    tree = cKDTree(centre)
    out = np.empty_like(values)
    for i, near in enumerate(tree.query_ball_point(centre, radius)):
        near = np.asarray(near)
        near = near[normal[near] @ normal[i] > 0.5]
        out[i] = values[near].mean()
    return out


def fill(obj, uv_name, size):
    from lightfade_addon.blender.bake import raster
    from lightfade_addon.blender.bake.uvmaps import triangle_uvs

    tri, _ = triangle_uvs(obj.data, uv_name)
    count, _ = raster.rasterise(tri, size)
    return np.count_nonzero(count) / size ** 2


def save_png(image, path):
    """Write a lux map as an 8-bit PNG, scaled to its 99th percentile (for a look)."""
    w, h = image.size
    px = np.empty(w * h * 4, np.float32)
    image.pixels.foreach_get(px)
    lux = px.reshape(h, w, 4)[..., 0]
    top = max(float(np.percentile(lux[lux > 0], 99)) if (lux > 0).any() else 1.0, 1e-9)
    out = bpy.data.images.new("LF_look", w, h)
    grey = np.clip(lux / top, 0, 1) ** (1 / 2.2)
    out.pixels.foreach_set(np.dstack([grey, grey, grey, np.ones_like(grey)]).ravel())
    out.filepath_raw = str(path)
    out.file_format = "PNG"
    out.save()
    bpy.data.images.remove(out)


def bake(scene, objects, quality, samples, save=None, seed=0):
    from lightfade_addon.blender.bake import BakeSettings, bake_exposure

    scene.lightfade_bake.quality = quality
    scene.lightfade.bake_samples = samples
    settings = BakeSettings.from_scene(scene)
    settings.seed = seed
    result, wall, cpu = timed(lambda: bake_exposure(scene, objects, settings,
                                                    report=lambda m: None,
                                                    progress=lambda f, m: None))
    maps = {name: next(iter(m.values())) for name, m in result["maps"].items()}
    noise = {obj: found for (obj, _), found in result.get("noise", {}).items()}
    values = {}
    for obj in objects:
        image = maps[obj.name]
        if save:
            Path(save).mkdir(parents=True, exist_ok=True)
            save_png(image, Path(save) / f"{obj.name}_{quality.lower()}_{samples}_{seed}.png")
        centre, normal, uv = surface_points(obj, obj.lightfade.uv_map)
        values[obj.name] = (read_map(image, uv), centre, normal, image.size[0],
                            noise.get(obj.name))
    return values, wall, cpu


def planned_estimate(scene, objects):
    """The panel's estimate of the default bake (after Calibrate): sizes and seconds."""
    from lightfade_addon.blender.bake import BakeSettings, ExposureBake, calibrate

    calibrate(scene, objects[0])
    scene.lightfade_bake.quality = "FINAL"
    job = ExposureBake(scene, objects, BakeSettings.from_scene(scene),
                       report=lambda m: None).plan()
    return dict(job.sizes), job.estimate()


def build_room(room, assets):
    """The room's sofa and curtain objects (``furnished``: tools/furnished_room.py, the
    issue's room; ``open``: tools/real_room.py)."""
    if room == "furnished":
        from tools import furnished_room

        roles = furnished_room.build(assets)
    else:
        from tools import real_room

        roles = real_room.build(assets)
    names = [n for r in ("sofa", "curtain") for n in roles.get(r, [])]
    if not names:
        raise SystemExit(f"no sofa or curtain model in {assets}")
    return [bpy.data.objects[n] for n in names]


def compare(values, ref, lit, centre, normal, radius, r_smooth):
    """(p95 per point, p95 3D-smoothed, median per point) of ``values`` against ``ref``."""
    point = np.abs(values - ref)[lit] / ref[lit]
    v_smooth = smooth(values, centre, normal, radius)
    near = np.abs(v_smooth - r_smooth)[lit] / r_smooth[lit]
    return np.percentile(point, 95), np.percentile(near, 95), np.median(point)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("assets", help="directory of glTF models (see tools/furnished_room.py)")
    parser.add_argument("--room", choices=("furnished", "open"), default="furnished",
                        help="furnished: tools/furnished_room.py (the issue's room); "
                             "open: tools/real_room.py")
    parser.add_argument("--density", type=float, help="texels per metre (default: the scene's)")
    parser.add_argument("--max-size", type=int, help="largest map (default: the scene's)")
    parser.add_argument("--seeds", type=int, default=2,
                        help="default bakes with seeds 0, 1...: each is measured (one seed's "
                             "figures are one draw of the noise)")
    parser.add_argument("--samples", type=int, default=64)
    parser.add_argument("--reference", type=int, default=256)
    parser.add_argument("--reference-seeds", type=int, default=2,
                        help="reference bakes, seeds after the default's: the first is the "
                             "reference, the others measure its own noise (the floor)")
    parser.add_argument("--sky-width", type=int, help="annual sky map width (default: the scene's)")
    parser.add_argument("--radius", type=float, default=0.06, help="3D neighbourhood, m")
    parser.add_argument("--save-maps", help="write each map as a PNG into this directory")
    parser.add_argument("--reference-cache",
                        help="an .npz of the reference bakes' values at the points: read if it "
                             "exists (no reference bake), else written")
    args = parser.parse_args()

    objects = build_room(args.room, args.assets)
    scene = bpy.context.scene
    if args.density:
        scene.lightfade_bake.texels_per_metre = args.density
    if args.max_size:
        scene.lightfade.bake_resolution = args.max_size
    if args.sky_width:
        scene.lightfade_daylight.sky_width = args.sky_width
    cache = Path(args.reference_cache) if args.reference_cache else None
    cached = cache is not None and cache.exists()
    runs = [(f"default (Final) seed {k}", "FINAL", 8, k) for k in range(max(args.seeds, 1))]
    runs.append(("fixed 8 (old Final)", "CUSTOM", 8, 0))
    if args.samples:
        runs.append((f"{args.samples} samples", "CUSTOM", args.samples, 0))
    if not cached:
        first_ref = max(args.seeds, 1)  # after the default's seeds: no shared path
        runs += [(f"{args.reference} seed {k}", "CUSTOM", args.reference, k)
                 for k in range(first_ref, first_ref + max(args.reference_seeds, 1))]
    estimate = planned_estimate(scene, objects)
    results = [(label, *bake(scene, objects, q, s, args.save_maps, seed))
               for label, q, s, seed in runs]
    first = results[0][1]
    if cached:
        stored = np.load(cache)
        seeds = sorted({int(k.rsplit("@", 1)[1]) for k in stored.files})
        refs = [(f"{args.reference} seed {k} (cached)",
                 {n: (stored[f"{n}@{k}"], *first[n][1:]) for n in first}, np.nan, np.nan)
                for k in seeds]
        results += refs
    else:
        refs = results[-max(args.reference_seeds, 1):]
        if cache is not None:
            np.savez(cache, **{f"{n}@{label.split()[2]}": v[0] for label, vals, _, _ in refs
                               for n, v in vals.items()})
    ref = refs[0][1]
    print(f"\n{args.room} room ({args.assets}): {len(objects)} objects, "
          f"{scene.lightfade_bake.texels_per_metre:g} texels/m, max "
          f"{scene.lightfade.bake_resolution}², daylight 52° N; points: polygon centres, lit "
          f">= 5 % of p99; 3D radius {args.radius} m; reference: {refs[0][0]}")
    for obj in objects:
        r_val, centre, normal, size = ref[obj.name][:4]
        lit = r_val >= 0.05 * np.percentile(r_val, 99)
        r_smooth = smooth(r_val, centre, normal, args.radius)
        print(f"\n{obj.name}: {size}² map on \"{obj.lightfade.uv_map}\" "
              f"({fill(obj, obj.lightfade.uv_map, size):.0%} of it in islands), "
              f"{lit.sum()} lit points of {len(r_val)}, reference median "
              f"{np.median(r_val[lit]):,.0f} lx")
        print(f"{'bake':<22} {'p95 point':>10} {'p95 3D':>8} {'median':>8}   "
              "the bake's own estimate")
        for label, values, _, _ in results:
            if values is ref:
                continue
            p95, p95_3d, med = compare(values[obj.name][0], r_val, lit, centre, normal,
                                       args.radius, r_smooth)
            found = values[obj.name][4] if len(values[obj.name]) > 4 else None
            print(f"{label:<22} {p95:>10.1%} {p95_3d:>8.1%} {med:>8.1%}   "
                  + (found.text() if found is not None else ""))
    wall0, cpu0 = results[0][2], results[0][3]
    fixed = next(r for r in results if r[0].startswith("fixed 8"))
    print(f"\n{'bake':<22} {'wall s':>8} {'CPU s':>8} {'CPU ÷ default':>14} {'÷ fixed 8':>10}"
          f" {'wall ÷ fixed 8':>15}")
    for label, _, wall, cpu in results:
        print(f"{label:<22} {wall:>8.1f} {cpu:>8.1f} {cpu / cpu0:>14.2f} {cpu / fixed[3]:>10.2f}"
              f" {wall / fixed[2]:>15.2f}")
    sizes, est = estimate
    made = {name: v[3] for name, v in first.items()}
    print(f"estimate before the bake: sizes {sizes}, {est.text()}; the default bake made "
          f"{made} in {wall0:.1f} s")


if __name__ == "__main__":
    main()
