"""The aging group's colour in EEVEE against Cycles (Linear table lookups, mip-maps).

    ./run py -m benchmarks.eevee_vs_cycles

A plane with a photograph-like 512² Base Color, lit by a sun (daylight) and a lamp
(incandescent), baked and aged to 25 years; the aged colour is shown through an
Emission shader (Standard view, black world), rendered by Cycles and by EEVEE at
256², one sample, compared inside the plane's border. Printed: ΔE00 between the two engines for the aged material and for
the original (what texture filtering alone gives), p50 / p99 / max.
"""

from __future__ import annotations

import math
import os
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import bpy  # noqa: E402
import addon_utils  # noqa: E402

from benchmarks.problem import synthetic_photo  # noqa: E402
from lightfade_addon.core.colour.colorimetry import (
    XYZ_to_Lab,
    delta_E_2000,
    linear_srgb_to_XYZ,
)  # noqa: E402


def scene_with_plane():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    addon_utils.enable("lightfade_addon", default_set=True)
    bpy.ops.mesh.primitive_plane_add(size=2.0)
    plane = bpy.context.active_object
    mat = bpy.data.materials.new("Photo")
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    image = bpy.data.images.new("Photo", 512, 512)
    rgba = np.ones((512, 512, 4), np.float32)
    rgba[..., :3] = synthetic_photo(512, 512)
    image.pixels.foreach_set(rgba.ravel())
    image.pack()
    tree = mat.node_tree
    tex = tree.nodes.new("ShaderNodeTexImage")
    tex.image = image
    tree.links.new(tex.outputs["Color"], tree.nodes["Principled BSDF"].inputs["Base Color"])
    mat.lightfade.enabled = True
    plane.data.materials.append(mat)
    scene = bpy.context.scene
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 6.0
    scene.collection.objects.link(sun)
    lamp = bpy.data.objects.new("Lamp", bpy.data.lights.new("Lamp", "POINT"))
    lamp.data.energy = 200.0
    lamp.data.lightfade.spectrum = "INCANDESCENT"
    lamp.location = (-0.8, -0.8, 0.6)
    scene.collection.objects.link(lamp)
    cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = 2.0
    cam.location = (0, 0, 3)
    scene.collection.objects.link(cam)
    scene.camera = cam
    return scene, plane


def emission_view(material):
    """Route the BSDF's colour input into an Emission on the output (what is compared)."""
    tree = material.node_tree
    bsdf = tree.nodes["Principled BSDF"]
    feed = bsdf.inputs["Base Color"].links[0].from_socket
    em = tree.nodes.new("ShaderNodeEmission")
    tree.links.new(feed, em.inputs["Color"])
    out = tree.get_output_node("ALL") or tree.get_output_node("CYCLES")
    tree.links.new(em.outputs[0], out.inputs["Surface"])


def render(scene, engine, folder, name):
    scene.render.engine = engine
    scene.render.resolution_x = scene.render.resolution_y = 256
    scene.view_settings.view_transform = "Standard"
    if engine == "CYCLES":
        scene.cycles.samples = 1
        scene.cycles.device = "CPU"
        scene.cycles.filter_width = 0.01
    else:
        scene.eevee.taa_render_samples = 1
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.filepath = os.path.join(folder, name + ".exr")
    bpy.ops.render.render(write_still=True)
    image = bpy.data.images.load(scene.render.filepath)
    px = np.empty(len(image.pixels), np.float32)
    image.pixels.foreach_get(px)
    return px.reshape(256, 256, 4)[..., :3]


def dE(a, b):
    a, b = a[16:-16, 16:-16], b[16:-16, 16:-16]          # the plane's inside
    lab = [XYZ_to_Lab(linear_srgb_to_XYZ(np.clip(x, 0, 1).reshape(-1, 3))) for x in (a, b)]
    return delta_E_2000(*lab)


def main():
    from lightfade_addon import api

    folder = tempfile.mkdtemp(prefix="lf_eevee_")
    scene, plane = scene_with_plane()
    eevee = next(e.identifier for e in
                 bpy.types.RenderSettings.bl_rna.properties["engine"].enum_items
                 if e.identifier.startswith("BLENDER_EEVEE"))
    api.bake(scene, quality="CUSTOM", samples=8)
    for o in (o for o in scene.objects if o.type == "LIGHT"):
        o.hide_render = True                           # the emission alone
    original = plane.material_slots[0].material
    view = original.copy()
    emission_view(view)
    plane.material_slots[0].material = view
    base = dE(render(scene, "CYCLES", folder, "c0"), render(scene, eevee, folder, "e0"))
    plane.material_slots[0].material = original
    api.age_scene(scene, years=25.0)
    aged = plane.material_slots[0].material
    emission_view(aged)
    d = dE(render(scene, "CYCLES", folder, "c1"), render(scene, eevee, folder, "e1"))
    for name, x in (("original", base), ("aged 25 y", d)):
        print(f"EEVEE vs Cycles, {name}: dE00 p50 {np.median(x):.2f}, p99 "
              f"{np.percentile(x, 99):.2f}, max {x.max():.2f}")


if __name__ == "__main__":
    main()
