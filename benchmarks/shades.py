"""Light through lampshades: LightFade's bake against a plain Cycles bake, per light group.

Usage (from the repository root; about 3 minutes on 2 cores, ``--quick`` under one)::

    python benchmarks/shades.py [--quick]
    python benchmarks/shades.py --timing     # the cost only, each bake twice, alternated
    python benchmarks/shades.py --seeds      # rug and poster, same seed as a plain bake
    python benchmarks/shades.py --draws 5    # the default bake at seeds 0-4: its spread
    python benchmarks/shades.py --clean      # the panel alone: adaptive against fixed 8

A 4 × 4 m room (floor, two walls, ceiling, a sofa), a rug on the floor and a poster on the
wall, lit by three light groups:

* ``Table lamps`` (6 h/day): two 60 W bulbs in open linen cylinders (Translucent + Diffuse
  BSDF) and a small area light in an open linen cone;
* ``Pendant`` (4 h/day): a 100 W bulb in an open frosted-glass cone (Principled BSDF,
  transmission 1, roughness 0.5): the floor below sees the bulb, the walls and the poster
  get most of its light through the glass (a *closed* glass shade lights the room only
  by caustic paths that a texel's bounce must find: at 128 samples a plain bake's means
  still scatter by ±10 %, too noisy to compare anything);
* ``Panel`` (8 h/day): a bare ceiling area light, the control.

Targets: floor, rug, poster, walls and the three shades.  Floor, rug, poster and walls are
plain Diffuse BSDFs, so that a plain Cycles DIFFUSE bake of them (no colour) *is* their
irradiance.  Printed per group and object: the mean lux of LightFade's default bake (Final
preset: adaptive, passes of 4 samples until each map's noise is at its target), of the
same bake at a fixed 8 samples (the Final preset before), of a plain Cycles bake at 512
samples without sample clamping (the reference, converged), and of the same plain bake
with Blender's default clamp (10 on indirect light); the largest difference of 8 ×
8-block means against the reference (blocks above a tenth of the object's mean); the
default's own estimate of its noise and the samples it spent; and the time of both
LightFade bakes against a plain bake at 8 samples and LightFade's sizes (one Cycles call
per group, same images: the issue's "plain bake").
"""

import argparse
import math
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import bpy  # noqa: E402
import addon_utils  # noqa: E402  (Blender's module: importable once bpy is)
import bmesh  # noqa: E402
import numpy as np  # noqa: E402

RECEIVERS = ("Floor", "Rug", "Poster")
REF_SAMPLES, REF_SIZE = 512, 128


def fresh():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    addon_utils.enable("lightfade_addon", default_set=True)


def material(name, build):
    mat = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    tree = mat.node_tree
    tree.nodes.remove(tree.nodes["Principled BSDF"])
    tree.links.new(build(tree), tree.nodes["Material Output"].inputs["Surface"])
    return mat


def diffuse(colour):
    def build(tree):
        node = tree.nodes.new("ShaderNodeBsdfDiffuse")
        node.inputs["Color"].default_value = (*colour, 1.0)
        return node.outputs["BSDF"]
    return build


def linen(tree):
    """Thin linen: 60 % diffuse reflection, 40 % diffuse transmission."""
    colour = (0.9, 0.85, 0.7, 1.0)
    refl, trans = tree.nodes.new("ShaderNodeBsdfDiffuse"), tree.nodes.new("ShaderNodeBsdfTranslucent")
    refl.inputs["Color"].default_value = trans.inputs["Color"].default_value = colour
    mix = tree.nodes.new("ShaderNodeMixShader")
    mix.inputs["Fac"].default_value = 0.4
    tree.links.new(refl.outputs["BSDF"], mix.inputs[1])
    tree.links.new(trans.outputs["BSDF"], mix.inputs[2])
    return mix.outputs["Shader"]


def frosted(tree):
    node = tree.nodes.new("ShaderNodeBsdfPrincipled")
    node.inputs["Base Color"].default_value = (0.95, 0.95, 0.95, 1.0)
    node.inputs["Transmission Weight"].default_value = 1.0
    node.inputs["Roughness"].default_value = 0.5
    return node.outputs["BSDF"]


def plane(name, size, location, rotation, mat):
    bpy.ops.mesh.primitive_plane_add(size=1.0, location=location, rotation=rotation)
    obj = bpy.context.active_object
    obj.name = name
    obj.scale = (*size, 1.0)
    bpy.ops.object.transform_apply(scale=True)
    obj.data.materials.append(mat)
    return obj


def shade(name, location, mat, radius2=None):
    """A lampshade: an open cylinder, or an open cone when ``radius2`` is given."""
    if radius2 is None:
        bpy.ops.mesh.primitive_cylinder_add(vertices=32, radius=0.18, depth=0.28, location=location)
    else:
        bpy.ops.mesh.primitive_cone_add(vertices=32, radius1=0.25, radius2=radius2, depth=0.25,
                                        location=location)
    obj = bpy.context.active_object
    obj.name = name
    bm = bmesh.new()
    bm.from_mesh(obj.data)
    caps = [f for f in bm.faces if abs(f.normal.z) > 0.99]
    bmesh.ops.delete(bm, geom=caps, context="FACES_ONLY")
    bm.to_mesh(obj.data)
    bm.free()
    obj.data.materials.append(mat)
    return obj


def lamp(kind, name, energy, location, hours, size=0.03):
    data = bpy.data.lights.new(name, kind)
    data.energy = energy
    if kind == "AREA":
        data.shape, data.size = "DISK", size
    else:
        data.shadow_soft_size = size
    data.lightfade.hours_per_day = hours
    obj = bpy.data.objects.new(name, data)
    bpy.context.scene.collection.objects.link(obj)
    obj.location = location
    return obj


def room():
    """The room; returns the bake targets."""
    fresh()
    wall = material("Wall", diffuse((0.7, 0.68, 0.62)))
    targets = [
        plane("Floor", (4, 4), (0, 0, 0), (0, 0, 0), material("Floor", diffuse((0.35, 0.25, 0.15)))),
        plane("Rug", (2.0, 1.4), (0.3, 0.2, 0.004), (0, 0, 0), material("Rug", diffuse((0.5, 0.12, 0.1)))),
        plane("Poster", (0.8, 1.0), (0.2, 1.995, 1.5), (math.radians(90), 0, 0),
              material("Poster", diffuse((0.8, 0.75, 0.6)))),
        plane("BackWall", (4, 2.6), (0, 2, 1.3), (math.radians(90), 0, 0), wall),
        plane("SideWall", (4, 2.6), (-2, 0, 1.3), (math.radians(90), 0, math.radians(90)),
              material("SideWall", diffuse((0.7, 0.68, 0.62)))),
    ]
    plane("Ceiling", (4, 4), (0, 0, 2.6), (math.radians(180), 0, 0), material("Ceiling", diffuse((0.8, 0.8, 0.8))))
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0.3, 1.5, 0.4))
    sofa = bpy.context.active_object
    sofa.name, sofa.scale = "Sofa", (1.8, 0.8, 0.8)
    sofa.data.materials.append(material("Sofa", diffuse((0.1, 0.4, 0.15))))
    targets += [
        shade("ShadeLeft", (-1.4, 1.5, 1.0), material("LinenLeft", linen)),
        shade("ShadeRight", (1.6, 1.5, 1.0), material("LinenRight", linen)),
        shade("ShadeCone", (-1.3, -1.2, 1.4), material("LinenCone", linen), radius2=0.1),
        shade("Pendant", (0.3, 0.0, 2.1), material("Frosted", frosted), radius2=0.06),
    ]
    lamp("POINT", "BulbLeft", 60.0, (-1.4, 1.5, 1.0), 6.0)
    lamp("POINT", "BulbRight", 60.0, (1.6, 1.5, 1.0), 6.0)
    lamp("AREA", "ConeBulb", 40.0, (-1.3, -1.2, 1.4), 6.0, size=0.08)
    lamp("POINT", "PendantBulb", 100.0, (0.3, 0.0, 2.1), 4.0, size=0.05)
    lamp("AREA", "Panel", 80.0, (-1.0, -1.0, 2.59), 8.0, size=0.5)
    bpy.context.scene.world = None
    return targets


def plain_bake(job, samples, clamp, names=None, size=None):
    """A plain Cycles bake per group: the job's isolation, the real materials (no white
    texels), ``clamp`` on indirect light; the job's targets and sizes, or the objects
    ``names`` at ``size``² each.  {group: {object: lux}}."""
    from lightfade_addon.blender.bake.common import LUX_PER_BAKE_UNIT, luminance
    from lightfade_addon.blender.bake.emitters import isolate
    from lightfade_addon.blender.bake.state import BakeState
    from lightfade_addon.blender.bake.targets import _add_target_node

    scene, layer = job.scene, job.view_layer
    out = {}
    with BakeState(scene, layer) as state:
        state.configure(samples, job.settings.margin, job.settings.seed)
        state.set(scene.cycles, "sample_clamp_indirect", float(clamp))
        objects = [o for o in job.targets if names is None or o.name in names]
        nodes = {o.name: [_add_target_node(state, s.material) for s in o.material_slots]
                 for o in objects}
        for step in (s for s in job.steps if s.index == 0):  # one call per group
            with BakeState(scene, layer) as inner:
                isolate(inner, scene, step.group)
                images = {}
                for obj in objects:
                    images[obj.name] = state.new_image(obj.name, size or job.sizes[obj.name])
                    for node in nodes[obj.name]:
                        node.image = images[obj.name]
                inner.select_only(objects)
                state.bake()
            out[step.group.name] = {name: LUX_PER_BAKE_UNIT * luminance(pixels(img)[..., :3])
                                    for name, img in images.items()}
    return out


def pixels(image):
    w, h = image.size
    a = np.empty(w * h * 4, dtype=np.float32)
    image.pixels.foreach_get(a)
    return a.reshape(h, w, 4).astype(np.float64)


def blocks(lux, n=8):
    h = lux.shape[0] // n * n
    return lux[:h, :h].reshape(n, h // n, n, h // n).mean(axis=(1, 3))


def same_seed(targets, quiet):
    """LightFade and a plain bake of rug and poster with the same seed, per group."""
    from lightfade_addon.blender.bake import BakeSettings, ExposureBake, bake_exposure

    objs = [o for o in targets if o.name in ("Rug", "Poster")]
    for seed in (1, 2):
        settings = BakeSettings(resolution=64, samples=64, margin=2, denoise=False, seed=seed)
        ours = bake_exposure(bpy.context.scene, objs, settings, **quiet)["maps"]
        job = ExposureBake(bpy.context.scene, objs, settings, **quiet).plan()
        plain = plain_bake(job, settings.samples, 0.0)
        for group, by_obj in plain.items():
            for name, lux in by_obj.items():
                lf = pixels(ours[name][group])[..., 0].mean()
                print(f"seed {seed} {group:<14}{name:<8} LightFade {lf:9.1f}  plain {lux.mean():9.1f}"
                      f"  {lf / lux.mean() - 1:+.2%}")


def timed(fn):
    wall, cpu = time.perf_counter(), time.process_time()
    out = fn()
    return out, time.perf_counter() - wall, time.process_time() - cpu


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="64 texels/m, 128-sample reference")
    parser.add_argument("--seeds", action="store_true",
                        help="rug and poster at 64 samples, 64², undenoised, against a plain "
                             "bake with the same seed (1 and 2): bias apart from noise")
    parser.add_argument("--draws", type=int, default=1,
                        help="LightFade's default bake at seeds 0 ... N-1 against the one "
                             "reference: each seed's difference, their mean and spread")
    parser.add_argument("--timing", action="store_true",
                        help="only the cost: LightFade (adaptive and fixed 8) and the plain "
                             "bake, alternated twice")
    parser.add_argument("--clean", action="store_true",
                        help="only the ceiling panel (a scene clean at the first passes): "
                             "the adaptive bake's cost against the fixed 8-sample bake, "
                             "alternated twice")
    args = parser.parse_args()
    from lightfade_addon.blender.bake import BakeSettings, ExposureBake, bake_exposure

    targets = room()
    scene = bpy.context.scene
    if args.clean:
        for obj in [o for o in scene.objects if o.type == "LIGHT" and o.name != "Panel"]:
            bpy.data.objects.remove(obj)
    settings = BakeSettings.from_scene(scene)
    settings.texels_per_metre = 64 if args.quick else 128
    fixed = BakeSettings(**{**settings.__dict__, "noise_target": None, "samples": 8})
    ref_samples = 128 if args.quick else REF_SAMPLES
    quiet = {"progress": lambda f, m: None, "report": lambda m: None}
    job = ExposureBake(scene, targets, fixed, **quiet).plan()
    print(f"Lampshade room: {len(targets)} targets, groups "
          f"{[(g.name, g.member_names) for g in job.groups]}, "
          f"{sum(job.sizes[o.name] ** 2 for o in targets) / 1e6:.2f} M texels; LightFade "
          f"default (Final, adaptive: passes of {settings.pass_samples}, target "
          f"{settings.noise_target:.0%} p95 / ±{settings.mean_target:.1%} mean, cap "
          f"{settings.max_samples} spp) and fixed 8 samples (denoised), reference "
          f"{ref_samples}")
    if args.seeds:
        same_seed(targets, quiet)
        return
    if args.timing or args.clean:
        bakes = {"LightFade default (adaptive)": lambda: bake_exposure(scene, targets, settings,
                                                                       **quiet),
                 "LightFade fixed 8": lambda: bake_exposure(scene, targets, fixed, **quiet)}
        if args.timing:
            bakes["plain Cycles, 8 samples"] = lambda: plain_bake(job, 8, 0.0)
        cost = {name: np.zeros(2) for name in bakes}  # (wall, CPU)
        for _ in range(2):
            for name, fn in bakes.items():
                cost[name] += timed(fn)[1:]
        base = cost["LightFade fixed 8"]
        print(f"{'two runs each, alternated':<32}{'wall s':>8}{'CPU s':>8}{'wall ÷ fixed':>14}"
              f"{'CPU ÷ fixed':>13}")
        for name, (wall, cpu) in cost.items():
            print(f"{name:<32}{wall:>8.1f}{cpu:>8.1f}{wall / base[0]:>14.2f}"
                  f"{cpu / base[1]:>13.2f}")
        return

    def means(maps):  # read at once: the next bake writes into the same images
        return {(g, n): pixels(image)[..., 0].mean() for n in RECEIVERS
                for g, image in maps[n].items()}

    draws = []
    for seed in range(1, max(args.draws, 1)):
        settings.seed = seed
        draws.append(means(bake_exposure(scene, targets, settings, **quiet)["maps"]))
    settings.seed = 0
    fx, fx_wall, fx_cpu = timed(lambda: bake_exposure(scene, targets, fixed, **quiet))
    fixed_means = means(fx["maps"])
    result, lf_wall, lf_cpu = timed(lambda: bake_exposure(scene, targets, settings, **quiet))
    draws.insert(0, means(result["maps"]))
    _, pl_wall, pl_cpu = timed(lambda: plain_bake(job, fixed.samples, 0.0))
    ref = plain_bake(job, ref_samples, 0.0, RECEIVERS, REF_SIZE)
    clamped = plain_bake(job, ref_samples // 4, 10.0, RECEIVERS, REF_SIZE)
    print(f"{'group':<22}{'object':<12}{'default':>10}{'plain ref':>11}{'default/ref':>12}"
          f"{'fixed 8/ref':>12}{'blocks max':>12}{'clamp 10/ref':>14}   default's own estimate")
    worst, worst_fixed = 0.0, 0.0
    spread = []
    for group, by_obj in ref.items():
        for name in RECEIVERS:
            lf = pixels(result["maps"][name][group])[..., 0]
            r, c = by_obj[name], clamped[group][name]
            ratio = lf.mean() / r.mean()
            ratio_fixed = fixed_means[group, name] / r.mean()
            bl, br = blocks(lf), blocks(r)  # 8 × 8 blocks of either size
            lit = br > 0.1 * r.mean()
            block = np.max(np.abs(bl[lit] / br[lit] - 1.0)) if lit.any() else 0.0
            worst = max(worst, abs(ratio - 1.0))
            worst_fixed = max(worst_fixed, abs(ratio_fixed - 1.0))
            found = result["noise"].get((name, group))
            print(f"{group:<22}{name:<12}{lf.mean():>10.1f}{r.mean():>11.1f}{ratio - 1:>+12.2%}"
                  f"{ratio_fixed - 1:>+12.2%}{block:>12.1%}{c.mean() / r.mean() - 1:>+14.2%}   "
                  + (found.text() if found else ""))
            spread.append((group, name, [d[group, name] / r.mean() - 1.0 for d in draws]))
    if len(draws) > 1:
        print(f"\nThe default against the reference at seeds 0-{len(draws) - 1} (one seed is "
              "one draw of the noise):")
        for group, name, d in spread:
            d = np.array(d)
            print(f"{group:<22}{name:<12}" + " ".join(f"{x:+7.2%}" for x in d)
                  + f"   mean {d.mean():+.2%}, sd {d.std(ddof=1):.2%}")
    print(f"worst floor/rug/poster mean: default {worst:.2%}, fixed 8 {worst_fixed:.2%} "
          "(target <= 2 %)")
    print(f"{'bake':<34}{'wall s':>8}{'CPU s':>8}{'CPU ÷ fixed 8':>15}")
    for label, wall, cpu in (("LightFade default (adaptive)", lf_wall, lf_cpu),
                             ("LightFade fixed 8", fx_wall, fx_cpu),
                             ("plain Cycles, 8 samples", pl_wall, pl_cpu)):
        print(f"{label:<34}{wall:>8.1f}{cpu:>8.1f}{cpu / fx_cpu:>15.2f}")


if __name__ == "__main__":
    main()
