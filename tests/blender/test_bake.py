"""Exposure bake: occlusion, calibration in lux, exact restoration, errors, persistence.

Calibration (see ``lightfade_addon.blender.bake``): Cycles' DIFFUSE bake without colour
gives ``E / pi`` for irradiance ``E`` in Blender's nominal W/m²; maps store
``683 * pi * value`` lux, so a sun of strength S at zenith angle θ gives 683 S cosθ lux and
a point lamp of P watts at distance r gives 683 P / (4 pi r²) lux.
"""

import math

import bpy
import numpy as np
import pytest

from lightfade_addon.blender import bake as bake_mod
from lightfade_addon.blender.bake import BakeSettings, bake_exposure

SMALL = BakeSettings(resolution=64, samples=8, margin=2)


def _footprint_and_lit(lux):
    """Texel masks of the 64² floor map: under the box, and in open sun far from it.

    Floor x, y in [-1, 1] -> u, v = (x + 1) / 2; the box covers x, y in [0.1, 0.7]; the sun
    leans toward +y so the shadow falls to +y; the lit region is y < -0.3.
    """
    n = lux.shape[0]
    coord = (np.arange(n) + 0.5) / n * 2 - 1
    y, x = np.meshgrid(coord, coord, indexing="ij")
    under = (x > 0.18) & (x < 0.62) & (y > 0.18) & (y < 0.62)
    lit = (y < -0.3) & (np.abs(x) < 0.85) & (y > -0.85)
    return under, lit


def snapshot():
    """Everything the bake may touch, as plain values."""
    scene = bpy.context.scene
    vl = bpy.context.view_layer

    def rna_values(struct):
        out = {}
        for p in struct.bl_rna.properties:
            if p.identifier == "rna_type" or p.type in {"POINTER", "COLLECTION"}:
                continue
            v = getattr(struct, p.identifier)
            out[p.identifier] = tuple(v) if hasattr(v, "__len__") and not isinstance(v, str) else v
        return out

    def tree(nt):
        nodes = []
        for n in nt.nodes:
            inputs = []
            for s in n.inputs:
                v = getattr(s, "default_value", None)
                inputs.append((s.identifier, tuple(v) if hasattr(v, "__len__") else v, s.is_linked))
            nodes.append((n.name, n.bl_idname, n.mute, getattr(n, "image", None) and n.image.name, inputs))
        links = sorted((l.from_node.name, l.from_socket.identifier, l.to_node.name, l.to_socket.identifier)
                       for l in nt.links)
        return nodes, links, nt.nodes.active.name if nt.nodes.active else None

    return {
        "render": rna_values(scene.render),
        "bake": rna_values(scene.render.bake),
        "cycles": rna_values(scene.cycles),
        "world": scene.world and scene.world.name,
        "override": vl.material_override,
        "active": vl.objects.active and vl.objects.active.name,
        "objects": {o.name: (o.hide_render, o.hide_get(), o.select_get(),
                             [s.material and s.material.name for s in o.material_slots])
                    for o in scene.objects},
        "materials": {m.name: tree(m.node_tree) for m in bpy.data.materials if m.node_tree},
        "worlds": {w.name: tree(w.node_tree) for w in bpy.data.worlds if w.node_tree},
        "images": sorted(i.name for i in bpy.data.images),
        "meshes": {m.name: (len(m.materials), [u.name for u in m.uv_layers]) for m in bpy.data.meshes},
    }


class TestBakeExposure:
    def test_occlusion_and_sun_calibration(self, floor_scene, lf):
        S, theta = 2.0, 40.0
        result = bake_exposure(bpy.context.scene, [floor_scene["floor"]], SMALL)
        image = result["maps"]["Floor"]["Sun"]
        assert image.name == "LF_Exposure_Floor_Sun"
        assert image.is_float and image.packed_file is not None
        lux = lf.pixels(image)
        under, lit = _footprint_and_lit(lux)
        lit_lux = np.median(lux[lit])
        assert lux[under].max() < 0.05 * lit_lux
        expected = 683.0 * S * math.cos(math.radians(theta))  # 1046.6 lx
        assert lit_lux == pytest.approx(expected, rel=0.03)
        maps = floor_scene["floor"].lightfade.exposure_maps
        assert [(m.emitter, m.emitter_kind, m.image.name) for m in maps] == [("Sun", "SUN", image.name)]
        assert floor_scene["floor"].lightfade.uv_map == "UVMap"

    def test_point_lamp_calibration_and_one_map_per_emitter(self, floor_scene, lf):
        P, r = 100.0, 2.0
        lf.add_point(P, (-0.5, -0.5, r))
        result = bake_exposure(bpy.context.scene, [floor_scene["floor"]], SMALL)
        assert set(result["maps"]["Floor"]) == {"Sun", "Lamp"}
        lux = lf.pixels(result["maps"]["Floor"]["Lamp"])
        # Texels around the foot of the lamp (x, y = -0.5): cos^3 falloff < 1 % within 0.1 m.
        centre = lux[14:18, 14:18].mean()
        assert centre == pytest.approx(683.0 * P / (4 * math.pi * r**2), rel=0.04)
        # The sun map is unaffected by the lamp.
        sun = lf.pixels(result["maps"]["Floor"]["Sun"])
        _, lit = _footprint_and_lit(sun)
        assert np.median(sun[lit]) == pytest.approx(683.0 * 2 * math.cos(math.radians(40)), rel=0.03)

    def test_world_and_emissive_mesh_are_emitters(self, floor_scene, lf):
        world = bpy.data.worlds.new("Sky")
        if bpy.app.version < (5, 0, 0):  # Blender 4.x: no node tree until this (5.0+: always on)
            world.use_nodes = True
        world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.5
        world.node_tree.nodes["Background"].inputs["Color"].default_value = (1, 1, 1, 1)
        bpy.context.scene.world = world
        bpy.ops.mesh.primitive_plane_add(size=0.5, location=(-0.5, 0.5, 1.0))
        panel = bpy.context.active_object
        panel.name = "Panel"
        mat = bpy.data.materials.new("Glow")
        if bpy.app.version < (5, 0, 0):  # Blender 4.x, as above
            mat.use_nodes = True
        bsdf = mat.node_tree.nodes["Principled BSDF"]
        bsdf.inputs["Emission Color"].default_value = (1, 1, 1, 1)
        bsdf.inputs["Emission Strength"].default_value = 5.0
        panel.data.materials.append(mat)
        before = snapshot()
        result = bake_exposure(bpy.context.scene, [floor_scene["floor"]], SMALL)
        assert set(result["maps"]["Floor"]) == {"Sun", "World", "Panel"}
        after = snapshot()
        assert set(after.pop("images")) - set(before.pop("images")) == {
            "LF_Exposure_Floor_Sun", "LF_Exposure_Floor_World", "LF_Exposure_Floor_Panel"}
        assert after == before
        sky = lf.pixels(result["maps"]["Floor"]["World"])
        # Open sky of radiance W on a plane: 683 pi W lux, less what the box and panel hide.
        assert np.median(sky) == pytest.approx(683 * math.pi * 0.5, rel=0.15)
        assert np.median(sky) < 683 * math.pi * 0.5 * 1.02
        glow = lf.pixels(result["maps"]["Floor"]["Panel"])
        assert glow.max() > 0 and glow[:8, :8].mean() < glow[40:56, 8:24].mean()

    def test_state_restored_and_albedo_untouched(self, floor_scene, lf):
        albedo = floor_scene["albedo"]
        original = lf.pixels(albedo).copy()
        # EEVEE is "BLENDER_EEVEE_NEXT" in Blender 4.2-4.5.
        bpy.context.scene.render.engine = "BLENDER_EEVEE" if bpy.app.version >= (5, 0, 0) else "BLENDER_EEVEE_NEXT"
        floor_scene["box"].select_set(True)
        before = snapshot()
        result = bake_exposure(bpy.context.scene, [floor_scene["floor"]], SMALL)
        after = snapshot()
        new_images = set(after.pop("images")) - set(before.pop("images"))
        assert new_images == {"LF_Exposure_Floor_Sun"}
        assert after == before
        np.testing.assert_array_equal(lf.pixels(albedo), original)
        assert not albedo.is_dirty
        assert not any(m.name.startswith("LF_TMP") for m in bpy.data.materials)
        assert result["maps"]["Floor"]["Sun"].users >= 1

    def test_state_restored_when_bake_raises(self, floor_scene, lf, monkeypatch):
        lf.add_point()
        floor_scene["box"].select_set(True)
        before = snapshot()
        calls = []

        def failing(settings, uv_name):
            calls.append(1)
            if len(calls) == 2:
                raise RuntimeError("simulated Cycles failure")
            return {"FINISHED"}

        monkeypatch.setattr(bake_mod, "_cycles_bake", failing)
        with pytest.raises(RuntimeError, match="simulated"):
            bake_exposure(bpy.context.scene, [floor_scene["floor"]], SMALL)
        after = snapshot()
        made = set(after.pop("images")) - set(before.pop("images"))
        assert made <= {"LF_Exposure_Floor_Sun"}  # the pair that finished; no temporaries
        assert after == before

    def test_rebake_replaces_the_map_everywhere(self, floor_scene, lf):
        first = bake_exposure(bpy.context.scene, [floor_scene["floor"]], SMALL)["maps"]["Floor"]["Sun"]
        user = floor_scene["material"].node_tree.nodes.new("ShaderNodeTexImage")
        user.image = first  # e.g. the lead's aging nodes
        floor_scene["sun"].data.energy = 4.0
        second = bake_exposure(bpy.context.scene, [floor_scene["floor"]], BakeSettings(32, 4, 1))
        image = second["maps"]["Floor"]["Sun"]
        assert tuple(image.size) == (32, 32) and user.image == image
        assert image["lightfade_bake_id"] == 2
        _, lit = _footprint_and_lit(lf.pixels(image))
        assert np.median(lf.pixels(image)[lit]) == pytest.approx(683.0 * 4 * math.cos(math.radians(40)), rel=0.03)
        assert [i.name for i in bpy.data.images if i.name.startswith("LF_")] == ["LF_Exposure_Floor_Sun"]
        assert len(floor_scene["floor"].lightfade.exposure_maps) == 1


class TestOperator:
    def test_selected(self, floor_scene):
        floor_scene["floor"].select_set(True)
        assert bpy.ops.lightfade.bake_exposure() == {"FINISHED"}
        assert "LF_Exposure_Floor_Sun" in bpy.data.images
        assert "LF_Exposure_Box_Sun" not in bpy.data.images

    def test_nothing_selected_bakes_enabled_materials(self, floor_scene):
        assert bpy.ops.lightfade.bake_exposure() == {"FINISHED"}
        assert "LF_Exposure_Floor_Sun" in bpy.data.images
        assert "LF_Exposure_Box_Sun" not in bpy.data.images

    def test_nothing_selected_nothing_enabled(self, floor_scene):
        floor_scene["material"].lightfade.enabled = False
        with pytest.raises(RuntimeError, match="Nothing to bake.*enable LightFade"):
            bpy.ops.lightfade.bake_exposure()

    def test_no_emitters(self, floor_scene):
        floor_scene["sun"].data.lightfade.enabled = False
        floor_scene["floor"].select_set(True)
        with pytest.raises(RuntimeError, match="No emitters"):
            bpy.ops.lightfade.bake_exposure()

    def test_non_mesh_skipped_with_its_name(self, floor_scene):
        empty = bpy.data.objects.new("Marker", None)
        bpy.context.scene.collection.objects.link(empty)
        bpy.context.view_layer.update()
        result = bake_exposure(bpy.context.scene, [empty, floor_scene["floor"]], SMALL)
        assert any("Marker" in m and "not a mesh" in m for m in result["skipped"])
        assert list(result["maps"]) == ["Floor"]
        empty.select_set(True)
        with pytest.raises(RuntimeError, match="Marker.*not a mesh"):
            bpy.ops.lightfade.bake_exposure()  # only the empty selected: nothing to bake

    def test_missing_uvs_skipped_or_unwrapped(self, floor_scene):
        box = floor_scene["box"]
        box.data.uv_layers.remove(box.data.uv_layers[0])
        result = bake_exposure(bpy.context.scene, [box, floor_scene["floor"]], SMALL)
        assert any("Box" in m and "no UV map" in m for m in result["skipped"])
        box.select_set(True)
        with pytest.raises(RuntimeError, match="Box.*no UV map"):
            bpy.ops.lightfade.bake_exposure()
        assert bpy.ops.lightfade.bake_exposure(unwrap=True) == {"FINISHED"}
        assert len(box.data.uv_layers) == 1 and box.lightfade.uv_map == box.data.uv_layers[0].name
        assert "LF_Exposure_Box_Sun" in bpy.data.images

    def test_linked_library_refused(self, blender, lf, tmp_path):
        bpy.ops.mesh.primitive_cube_add()
        bpy.context.active_object.name = "LibCube"
        lib = tmp_path / "lib.blend"
        bpy.ops.wm.save_as_mainfile(filepath=str(lib))
        bpy.ops.wm.read_factory_settings(use_empty=True)
        import addon_utils

        addon_utils.enable(lf.ADDON, default_set=True)
        with bpy.data.libraries.load(str(lib), link=True) as (src, dst):
            dst.objects = ["LibCube"]
        bpy.context.scene.collection.objects.link(dst.objects[0])
        lf.add_sun()
        bpy.context.view_layer.update()
        dst.objects[0].select_set(True)
        with pytest.raises(RuntimeError, match="LibCube.*make local first"):
            bpy.ops.lightfade.bake_exposure()


def test_save_reload_round_trip(floor_scene, lf, tmp_path):
    scene = bpy.context.scene
    scene.lightfade.years = 12.5
    floor_scene["sun"].data.lightfade.hours_per_day = 5.5
    floor_scene["sun"].data.lightfade.spectrum = "DAYLIGHT"
    floor_scene["material"].lightfade.recipe = "DYED_FABRIC"
    image = bake_exposure(scene, [floor_scene["floor"]], SMALL)["maps"]["Floor"]["Sun"]
    lux = lf.pixels(image).copy()
    path = tmp_path / "round.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.read_factory_settings(use_empty=True)
    import addon_utils

    addon_utils.enable(lf.ADDON, default_set=True)
    bpy.ops.wm.open_mainfile(filepath=str(path))
    scene = bpy.context.scene
    assert scene.lightfade.years == 12.5 and scene.lightfade.bake_resolution == 64
    sun = bpy.data.objects["Sun"].data.lightfade
    assert (sun.hours_per_day, sun.spectrum) == (5.5, "DAYLIGHT")
    assert bpy.data.materials["Carpet"].lightfade.recipe == "DYED_FABRIC"
    item = bpy.data.objects["Floor"].lightfade.exposure_maps["Sun"]
    assert item.emitter_kind == "SUN" and item.image.packed_file is not None
    np.testing.assert_allclose(lf.pixels(item.image), lux, rtol=1e-3)
