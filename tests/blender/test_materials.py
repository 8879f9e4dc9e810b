"""Every kind of artist material in scenes/materials.py ages: lit halves fade, shaded halves
keep their colour, originals stay pixel-identical and Reset restores every link.

The final Base Color each object renders with is evaluated by Cycles (an EMIT bake of
its colour socket, in the exposure UV map) before and after aging.
"""

import hashlib
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

bpy = pytest.importorskip("bpy")
import addon_utils  # noqa: E402

from lightfade_addon.core.colour.colorimetry import (
    XYZ_to_Lab,
    delta_E_2000,
    linear_srgb_to_XYZ,
)  # noqa: E402
from scenes import materials as M  # noqa: E402

RES = 64


def lab(rgb):
    return XYZ_to_Lab(linear_srgb_to_XYZ(np.asarray(rgb, float).reshape(-1, 3)))


def base_colour(obj):
    """(H, W, 3) linear Base Color ``obj`` renders with, baked in its exposure UV map."""
    from lightfade_addon.blender.albedo import bake_albedos
    from lightfade_addon.blender.aging.copies import assign, make_copy, remove_copy
    from lightfade_addon.blender.source import find_colour_socket

    scene = bpy.context.scene
    material = obj.material_slots[0].material
    colour, problem = find_colour_socket(material)
    assert problem is None
    probe = make_copy(obj, material, colour)
    assign(obj, material, probe)
    image = bpy.data.images.new("probe", RES, RES, float_buffer=True)
    try:
        out = bake_albedos(scene, bpy.context.view_layer, obj, [(probe, colour, image)],
                           obj.lightfade.uv_map)
    finally:
        remove_copy(probe)
        bpy.data.images.remove(image)
    return next(iter(out.values()))


def lux(obj):
    image = obj.lightfade.exposure_maps["Sun"].image
    a = np.empty(len(image.pixels), np.float32)
    image.pixels.foreach_get(a)
    return a.reshape(RES, RES, image.channels)[..., 0]


def image_hashes():
    out = {}
    for image in bpy.data.images:
        if not image.name.startswith("LF_") and image.has_data:
            a = np.empty(len(image.pixels), np.float32)
            image.pixels.foreach_get(a)
            out[image.name] = hashlib.sha256(a.tobytes()).hexdigest()
    return out


def graph(material_or_tree):
    tree = getattr(material_or_tree, "node_tree", material_or_tree)
    return sorted((l.from_node.name, l.from_socket.identifier, l.to_node.name,
                   l.to_socket.identifier, l.is_muted) for l in tree.links), \
        sorted((n.name, n.type) for n in tree.nodes)


def file_state():
    return dict(
        materials={m.name: graph(m) for m in bpy.data.materials},
        groups={g.name: (graph(g), [i.name for i in g.interface.items_tree])
                for g in bpy.data.node_groups},
        slots={o.name: [(s.link, s.material.name if s.material else None) for s in o.material_slots]
               for o in bpy.data.objects if o.type == "MESH"},
        users={m.name: m.users for m in bpy.data.materials},
        images=sorted(i.name for i in bpy.data.images),
        uv={o.name: [u.name for u in o.data.uv_layers] for o in bpy.data.objects if o.type == "MESH"},
        lock=bpy.context.scene.render.use_lock_interface,
        engine=bpy.context.scene.render.engine,
    )


@pytest.fixture(scope="module")
def aged():
    """The materials scene baked (32 px) and aged to 5 years; what it looked like before."""
    M.build(resolution=RES)
    addon_utils.enable("lightfade_addon", default_set=True)
    from lightfade_addon import api

    scene = bpy.context.scene
    for m in bpy.data.materials:
        if "lightfade_recipe" in m:
            m.lightfade.enabled = True
            m.lightfade.recipe = "DYED_FABRIC"
            m.lightfade.blue_wool = M.BLUE_WOOL
    api.bake(scene, resolution=RES, samples=4, margin=2)
    objects = [o for o in scene.objects if o.name.startswith(("Plate_", "Shared_", "Duplicate_"))]
    before = {o.name: base_colour(o) for o in objects}
    state, hashes = file_state(), image_hashes()
    plan = {row["object"]: row for row in api.material_plan(scene)}
    api.age_scene(scene, years=5)
    after = {o.name: base_colour(o) for o in objects}
    yield dict(before=before, after=after, state=state, hashes=hashes, plan=plan, api=api)
    addon_utils.disable("lightfade_addon", default_set=True)
    bpy.ops.wm.read_factory_settings(use_empty=True)


def _dE(aged, name):
    return delta_E_2000(lab(aged["after"][name]), lab(aged["before"][name])).reshape(RES, RES)


PLATES = ["Plate_" + k for k in ("image", "tiled", "procedural", "adjusted", "grouped", "attribute")]


@pytest.mark.parametrize("name", PLATES)
def test_lit_half_fades_shaded_half_keeps_its_colour(aged, name):
    lx = lux(bpy.data.objects[name])
    lit, shade = lx > 0.5 * M.SUN_LUX, lx < 0.02 * M.SUN_LUX
    assert lit.sum() > 100 and shade.sum() > 100
    dE = _dE(aged, name)
    assert np.median(dE[lit]) > 3
    assert np.median(dE[shade]) < 1 and np.percentile(dE[shade], 90) < 1


@pytest.mark.parametrize("kind", ["shared", "duplicates"])
def test_each_object_ages_with_its_own_light(aged, kind):
    prefix = "Shared" if kind == "shared" else "Duplicate"
    sunny, shaded = f"{prefix}_Sun", f"{prefix}_Shade"
    assert np.median(_dE(aged, sunny)) > 3
    assert np.percentile(_dE(aged, shaded), 90) < 1
    a, b = (bpy.data.objects[n] for n in (sunny, shaded))
    assert a.material_slots[0].material != b.material_slots[0].material
    if kind == "duplicates":
        assert a.data == b.data                       # the mesh stays shared


def test_plan_names_the_path_and_why(aged):
    plan = aged["plan"]
    assert plan["Plate_image"]["path"] == "DIRECT"
    assert plan["Shared_Sun"]["path"] == "FLAT"
    for name in ("Plate_tiled", "Plate_procedural", "Plate_adjusted", "Plate_grouped",
                 "Plate_attribute"):
        assert plan[name]["path"] == "BAKED", plan[name]
    assert "Mapping" in plan["Plate_tiled"]["reason"]
    assert "group" in plan["Plate_grouped"]["reason"]
    rows = aged["api"].material_plan(bpy.context.scene)
    assert all(row["status"] == "aged" for row in rows), [r["status"] for r in rows]


def test_originals_untouched_and_reset_restores_everything(aged):
    for name, digest in aged["hashes"].items():
        assert image_hashes()[name] == digest, name
    for name in aged["state"]["materials"]:
        assert graph(bpy.data.materials[name]) == aged["state"]["materials"][name], name
    aged["api"].reset(bpy.context.scene)
    assert file_state() == aged["state"]
    assert image_hashes() == aged["hashes"]
