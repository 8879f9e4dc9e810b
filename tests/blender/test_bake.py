"""Exposure bake: occlusion, calibration in lux, light groups, real materials, UV checks,
texel density, cancel, exact restoration, errors, persistence.

Calibration (see ``lightfade_addon.blender.bake.common``): Cycles' DIFFUSE bake without
colour gives ``E / pi`` for irradiance ``E`` in Blender's nominal W/m²; maps store
``683 * pi * Y`` lux, so a sun of strength S at zenith angle θ gives 683 S cosθ lux and
a point lamp of P watts at distance r gives 683 P / (4 pi r²) lux.
"""

import math

import bpy
import numpy as np
import pytest

from lightfade_addon.blender.bake import (
    BakeCancelled,
    BakeSettings,
    BakeState,
    LightFadeBakeError,
    bake_exposure,
    exposure_signature,
    lights_and_exposure,
    remove_exposure,
)

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

    def test_point_lamp_calibration_and_one_map_per_group(self, floor_scene, lf):
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
        world.lightfade.spectrum = "DAYLIGHT"  # a world counts once it has a spectrum
        world.lightfade.hours_per_day = 10.0
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
        panel.lightfade_emitter.enabled = True  # an emissive mesh counts once asked to
        panel.lightfade_emitter.hours_per_day = 4.0  # its own group (the sun has 8 h)
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
        lf.add_point()  # LED: a second group
        floor_scene["box"].select_set(True)
        before = snapshot()
        calls = []
        real = BakeState.bake

        def failing(state):
            calls.append(1)
            if len(calls) == 2:
                raise RuntimeError("simulated Cycles failure")
            return real(state)

        monkeypatch.setattr(BakeState, "bake", failing)
        with pytest.raises(RuntimeError, match="simulated"):
            bake_exposure(bpy.context.scene, [floor_scene["floor"]], SMALL)
        assert len(calls) == 2
        after = snapshot()
        assert after == before  # no partial map, no temporaries
        assert len(floor_scene["floor"].lightfade.exposure_maps) == 0

    def test_rebake_replaces_the_map_everywhere(self, floor_scene, lf):
        first = bake_exposure(bpy.context.scene, [floor_scene["floor"]], SMALL)["maps"]["Floor"]["Sun"]
        user = floor_scene["material"].node_tree.nodes.new("ShaderNodeTexImage")
        user.image = first  # e.g. the lead's aging nodes
        floor_scene["sun"].data.energy = 4.0
        second = bake_exposure(bpy.context.scene, [floor_scene["floor"]], BakeSettings(32, 8, 1))
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


def _count_bakes(monkeypatch):
    """Record each Cycles call: the selected objects and their slots' materials."""
    calls = []
    real = BakeState.bake

    def counting(state):
        vl = state.view_layer
        calls.append({o.name: [s.material.name for s in o.material_slots if s.material]
                      for o in vl.objects if o.select_get()})
        return real(state)

    monkeypatch.setattr(BakeState, "bake", counting)
    return calls


def _lit_median(lf, image):
    lux = lf.pixels(image)
    _, lit = _footprint_and_lit(lux)
    return float(np.median(lux[lit]))


class TestLightGroups:
    def test_same_schedule_lamps_add_into_one_map(self, floor_scene, lf, monkeypatch):
        second = lf.add_sun(strength=1.0, name="Sun2")  # same angle, spectrum and schedule
        calls = _count_bakes(monkeypatch)
        result = bake_exposure(bpy.context.scene, [floor_scene["floor"]], SMALL)
        assert list(result["maps"]["Floor"]) == ["Sun +1"]
        assert result["groups"] == [("Sun +1", ["Sun", "Sun2"])]
        assert len(calls) == 1
        item = floor_scene["floor"].lightfade.exposure_maps["Sun +1"]
        assert sorted(m.name for m in item.members) == ["Sun", "Sun2"]
        # 2 + 1: the lamps add; one overwriting the other would give 2 or 1.
        expected = 683.0 * 3.0 * math.cos(math.radians(40))
        assert _lit_median(lf, item.image) == pytest.approx(expected, rel=0.03)
        second.data.lightfade.hours_per_day = 2.0  # now two groups: two maps
        result = bake_exposure(bpy.context.scene, [floor_scene["floor"]], SMALL)
        assert sorted(result["maps"]["Floor"]) == ["Sun", "Sun2"]
        assert "LF_Exposure_Floor_Sun +1" not in bpy.data.images  # the old group's map is gone

    def test_all_targets_in_one_call_per_group(self, floor_scene, lf, monkeypatch):
        lf.add_point()  # LED: a second group
        calls = _count_bakes(monkeypatch)
        result = bake_exposure(bpy.context.scene, [floor_scene["floor"], floor_scene["box"]], SMALL)
        assert len(calls) == 2 and all(set(c) == {"Floor", "Box"} for c in calls)
        assert set(result["maps"]["Box"]) == {"Sun", "Lamp"}

    def test_regroup_sums_maps_without_baking(self, floor_scene, lf, monkeypatch):
        second = lf.add_sun(strength=1.0, name="Sun2")
        second.data.lightfade.hours_per_day = 2.0
        scene = bpy.context.scene
        maps = bake_exposure(scene, [floor_scene["floor"]], SMALL)["maps"]["Floor"]
        parts = lf.pixels(maps["Sun"]) + lf.pixels(maps["Sun2"])
        signature = exposure_signature(scene, floor_scene["floor"])
        second.data.lightfade.hours_per_day = 8.0  # same schedule as Sun: one group
        assert exposure_signature(scene, floor_scene["floor"]) != signature
        lights, lux = lights_and_exposure(scene, floor_scene["floor"], (64, 64))
        assert len(lights) == 1  # maps of one schedule add when read
        np.testing.assert_allclose(lux[0], parts, rtol=1e-5)
        calls = _count_bakes(monkeypatch)
        result = bake_exposure(scene, [floor_scene["floor"]], SMALL, only_changed=True)
        assert calls == [] and list(result["maps"]["Floor"]) == ["Sun +1"]
        np.testing.assert_allclose(lf.pixels(result["maps"]["Floor"]["Sun +1"]), parts, rtol=1e-5)

    def test_split_group_is_stale_until_baked(self, floor_scene, lf):
        second = lf.add_sun(strength=1.0, name="Sun2")
        scene = bpy.context.scene
        bake_exposure(scene, [floor_scene["floor"]], SMALL)
        second.data.lightfade.uv_filter = True
        with pytest.raises(LightFadeBakeError, match="Floor.*Sun \\+1.*bake exposure again"):
            lights_and_exposure(scene, floor_scene["floor"], (64, 64))


    def test_every_schedule_setting_splits_a_group_and_changes_the_signature(self, floor_scene,
                                                                            lf):
        """Spectrum, UV filter, hours a day, days a year: lamps that differ in any are two
        groups, and a change to any changes the exposure signature (aged copies go stale)."""
        from lightfade_addon.blender.bake import find_groups

        scene, floor = bpy.context.scene, floor_scene["floor"]
        schedule = lf.add_sun(strength=1.0, name="Sun2").data.lightfade
        bake_exposure(scene, [floor], SMALL)
        signature = exposure_signature(scene, floor)
        for name, value in (("spectrum", "LED"), ("uv_filter", True), ("hours_per_day", 2.0),
                            ("days_per_year", 100.0)):
            old = getattr(schedule, name)
            setattr(schedule, name, value)
            assert len(find_groups(scene)) == 2, name
            assert exposure_signature(scene, floor) != signature, name
            setattr(schedule, name, old)
        assert exposure_signature(scene, floor) == signature


class TestPhotometry:
    def test_luminance_not_red(self, floor_scene, lf):
        floor_scene["sun"].data.color = (0.0, 1.0, 0.0)  # green light: no red at all
        image = bake_exposure(bpy.context.scene, [floor_scene["floor"]], SMALL)["maps"]["Floor"]["Sun"]
        expected = 683.0 * 2.0 * math.cos(math.radians(40)) * 0.7152  # Y of pure green
        assert _lit_median(lf, image) == pytest.approx(expected, rel=0.03)

    def test_world_counts_only_with_a_spectrum(self, floor_scene, lf):
        world = bpy.data.worlds.new("Sky")
        if bpy.app.version < (5, 0, 0):  # Blender 4.x: no node tree until this (5.0+: always on)
            world.use_nodes = True
        world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.5
        world.node_tree.nodes["Background"].inputs["Color"].default_value = (1, 1, 1, 1)
        bpy.context.scene.world = world
        floor_scene["box"].hide_render = True
        result = bake_exposure(bpy.context.scene, [floor_scene["floor"]], SMALL)
        assert set(result["maps"]["Floor"]) == {"Sun"}  # default world: not counted
        assert _lit_median(lf, result["maps"]["Floor"]["Sun"]) == pytest.approx(
            683.0 * 2 * math.cos(math.radians(40)), rel=0.03)  # and not in the sun's map either
        world.lightfade.spectrum = "DAYLIGHT"
        floor_scene["sun"].data.lightfade.enabled = False
        sky = bake_exposure(bpy.context.scene, [floor_scene["floor"]], SMALL)["maps"]["Floor"]["World"]
        assert np.median(lf.pixels(sky)) == pytest.approx(683 * math.pi * 0.5, rel=0.04)

    def test_real_material_used_and_restored(self, floor_scene, lf, monkeypatch):
        before = snapshot()
        seen = []
        real = BakeState.bake

        def spying(state):
            mat = floor_scene["floor"].material_slots[0].material
            nodes = [n for n in mat.node_tree.nodes if n.type == "TEX_IMAGE"]
            seen.append((mat.name, mat.node_tree.nodes.active.image.name, len(nodes)))
            return real(state)

        monkeypatch.setattr(BakeState, "bake", spying)
        bake_exposure(bpy.context.scene, [floor_scene["floor"]], SMALL)
        assert seen == [("Carpet", "LF_TMP_Floor_Sun", 2)]  # the real material + one node
        after = snapshot()
        after.pop("images"), before.pop("images")
        assert after == before

    def test_bounce_off_a_coloured_surface_counts_by_luminance(self, floor_scene, lf):
        # A green wall lit by the sun bounces green light onto the floor's shadow.
        bpy.ops.mesh.primitive_plane_add(size=2.0, location=(0.0, 1.0, 1.0), rotation=(math.radians(90), 0, 0))
        wall = bpy.context.active_object
        green = bpy.data.materials.new("Green")
        if bpy.app.version < (5, 0, 0):  # Blender 4.x: no node tree until this (5.0+: always on)
            green.use_nodes = True
        green.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.0, 0.8, 0.0, 1.0)
        wall.data.materials.append(green)
        floor_scene["sun"].rotation_euler = (math.radians(-40), 0.0, 0.0)  # lights the wall's face
        image = bake_exposure(bpy.context.scene, [floor_scene["floor"]], SMALL)["maps"]["Floor"]["Sun"]
        lux = lf.pixels(image)
        green.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.8, 0.0, 0.0, 1.0)
        red = lf.pixels(bake_exposure(bpy.context.scene, [floor_scene["floor"]], SMALL)["maps"]["Floor"]["Sun"])
        near = lux[56:62, 8:56].mean(), red[56:62, 8:56].mean()  # the strip by the wall
        assert near[0] > near[1]  # a green wall returns more luminance than a red one


class TestUVChecks:
    def test_mirror_modifier_refused_before_any_bake(self, floor_scene, monkeypatch):
        calls = _count_bakes(monkeypatch)
        for obj in (floor_scene["floor"], floor_scene["box"]):
            obj.modifiers.new("Mirror", "MIRROR").mirror_offset_u = 0.0
        floor_scene["floor"].location.x = 1.5
        with pytest.raises(LightFadeBakeError) as err:
            bake_exposure(bpy.context.scene, [floor_scene["floor"], floor_scene["box"]], SMALL)
        lines = str(err.value).splitlines()
        assert len(lines) == 2 and all("Mirror modifier" in line and "apply it" in line for line in lines)
        assert lines[0].startswith('"Floor"') and lines[1].startswith('"Box"')
        assert calls == []
        assert "LightFadeUV" not in floor_scene["floor"].data.uv_layers

    def test_operator_reports_material_and_geometry_problems_in_one_message(self, floor_scene,
                                                                           monkeypatch):
        calls = _count_bakes(monkeypatch)
        floor_scene["floor"].modifiers.new("Mirror", "MIRROR").mirror_offset_u = 0.0
        missing = bpy.data.images.new("Missing", 8, 8)
        missing.source = "FILE"
        missing.filepath = "//nowhere.png"
        floor_scene["material"].node_tree.nodes["Image Texture"].image = missing
        with pytest.raises(RuntimeError) as err:
            bpy.ops.lightfade.bake_exposure()
        message = str(err.value)
        assert "2 problems" in message
        assert "Image 'Missing'" in message and "Mirror modifier" in message
        assert calls == [] and not floor_scene["floor"].lightfade.exposure_maps

    def test_overlapping_islands_get_a_lightfade_uv(self, floor_scene, lf):
        # Two floor tiles whose UVs both cover the whole square (a trim-sheet habit).
        mesh = bpy.data.meshes.new("Strip")
        mesh.from_pydata([(-1, -1, 0.01), (0, -1, 0.01), (0, 1, 0.01), (-1, 1, 0.01),
                          (1, -1, 0.01), (1, 1, 0.01)], [], [(0, 1, 2, 3), (1, 4, 5, 2)])
        uv = mesh.uv_layers.new(name="UVMap").data
        squashed = np.array([(0, 0), (1, 0), (1, 1), (0, 1)] * 2, dtype=np.float32)
        uv.foreach_set("uv", squashed.ravel())
        strip = bpy.data.objects.new("Strip", mesh)
        bpy.context.scene.collection.objects.link(strip)
        floor_scene["floor"].hide_render = True
        notes = []
        result = bake_exposure(bpy.context.scene, [strip], SMALL, report=notes.append)
        assert any("Strip" in n and "overlap" in n and "LightFadeUV" in n for n in notes)
        assert strip.lightfade.uv_map == "LightFadeUV" and strip.lightfade.uv_created
        assert strip.data.uv_layers.active.name == "UVMap"  # the user's map stays active
        mine = np.empty(len(strip.data.loops) * 2, dtype=np.float32)
        strip.data.uv_layers["UVMap"].data.foreach_get("uv", mine)
        np.testing.assert_array_equal(mine, squashed.ravel())
        # The box's shadow falls on the right tile only: with one texel per place, the
        # map shows it once (on overlapping UVs it would darken both tiles' texels).
        lux = lf.pixels(result["maps"]["Strip"]["Sun"])
        assert lux.max() > 900 and np.percentile(lux[lux > 0], 5) < 0.1 * lux.max()
        remove_exposure(bpy.context.scene, [strip])
        assert "LightFadeUV" not in strip.data.uv_layers and len(strip.lightfade.exposure_maps) == 0
        assert not any(i.name.startswith("LF_Exposure_Strip") for i in bpy.data.images)

    def test_unique_uvs_pass(self, floor_scene):
        result = bake_exposure(bpy.context.scene, [floor_scene["floor"], floor_scene["box"]], SMALL)
        assert result["notes"] == [] and floor_scene["box"].lightfade.uv_map == "UVMap"


class TestSizing:
    def test_texel_density(self, floor_scene):
        from lightfade_addon.blender.bake.sizing import density_size

        assert density_size(4.0, 1.0, 64, 1024) == 128  # 2 m at 64 texels/m
        assert density_size(4.0, 1.0, 100, 1024) == 200  # a multiple of 8
        assert density_size(4.0, 0.25, 64, 1024) == 256  # islands fill a quarter
        assert density_size(4.0, 1.0, 1000, 1024) == 1024  # the cap
        assert density_size(1e-4, 1.0, 64, 1024) == 16
        settings = BakeSettings(samples=2, margin=2, denoise=False, texels_per_metre=20, max_size=64)
        maps = bake_exposure(bpy.context.scene, [floor_scene["floor"], floor_scene["box"]], settings)["maps"]
        assert tuple(maps["Floor"]["Sun"].size) == (40, 40)  # 2 m × 20 /m
        # The box: 6 faces of 0.36 m²; its UV islands cover a share a of the square.
        uv = np.empty(len(floor_scene["box"].data.loops) * 2)
        floor_scene["box"].data.uv_layers[0].data.foreach_get("uv", uv)
        quads = uv.reshape(6, 4, 2)
        d1, d2 = quads[:, 2] - quads[:, 0], quads[:, 3] - quads[:, 1]
        a = np.sum(0.5 * np.abs(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]))
        n = math.ceil(20 * math.sqrt(6 * 0.36 / a) / 8) * 8
        assert tuple(maps["Box"]["Sun"].size) == (n, n) and n != 40


class TestProgressAndCancel:
    def test_cancel_restores_everything_and_stores_nothing(self, floor_scene, lf):
        lf.add_point()
        first = bake_exposure(bpy.context.scene, [floor_scene["floor"]], SMALL)["maps"]["Floor"]
        old = {k: lf.pixels(v).copy() for k, v in first.items()}
        floor_scene["box"].select_set(True)
        before = snapshot()
        checks = []

        def cancel():
            checks.append(1)
            return len(checks) >= 2  # after the first group's bake

        with pytest.raises(BakeCancelled):
            bake_exposure(bpy.context.scene, [floor_scene["floor"]], SMALL, cancel=cancel)
        assert snapshot() == before
        maps = floor_scene["floor"].lightfade.exposure_maps
        assert {m.name for m in maps} == set(old)
        for m in maps:
            np.testing.assert_array_equal(lf.pixels(m.image), old[m.name])

    def test_esc_in_the_modal_bake_restores_everything_and_stores_nothing(self, floor_scene, lf):
        """The operator's modal path (the UI's): a timer tick bakes one group, Esc then
        cancels. There is no window here, so the operator's Blender calls go to a stand-in
        window manager; the bake itself is real."""
        from types import SimpleNamespace

        from lightfade_addon.blender.bake import ExposureBake
        from lightfade_addon.blender.operators.bake_exposure import (
            LIGHTFADE_OT_bake_exposure as Op,
        )

        lf.add_point()
        floor = floor_scene["floor"]
        before = snapshot()
        reports, calls = [], []
        context = SimpleNamespace(window_manager=SimpleNamespace(
            event_timer_remove=lambda t: calls.append("timer off")))
        op = SimpleNamespace(_cancel=False, _timer=object(),
                             _window=SimpleNamespace(end=lambda: calls.append("progress end")),
                             report=lambda level, msg: reports.append((level, msg)))
        for name in ("_finish", "_end"):
            setattr(op, name, getattr(Op, name).__get__(op))
        op._job = ExposureBake(bpy.context, [floor], SMALL, report=lambda m: None,
                               progress=lambda f, m: None).plan()
        op._job.__enter__()
        assert Op.modal(op, context, SimpleNamespace(type="TIMER")) == {"RUNNING_MODAL"}
        assert op._job.done == 1                      # one of the two groups baked
        assert Op.modal(op, context, SimpleNamespace(type="ESC")) == {"CANCELLED"}
        assert reports == [({"WARNING"}, "Bake cancelled: nothing was changed")]
        assert calls == ["timer off", "progress end"]
        assert snapshot() == before
        assert len(floor.lightfade.exposure_maps) == 0
        assert not [i for i in bpy.data.images if i.name.startswith("LF_")]

    def test_headless_one_progress_line_per_bake_and_quiet(self, floor_scene, lf, capfd):
        lf.add_point()
        bake_exposure(bpy.context.scene, [floor_scene["floor"], floor_scene["box"]], SMALL)
        out = capfd.readouterr().out
        assert "save it externally" not in out
        lines = [line for line in out.splitlines() if line.startswith("LightFade:")]
        assert len(lines) == 2 and "[1/2]" in lines[0] and "[2/2]" in lines[1] and "left" in lines[1]

    def test_progress_callback(self, floor_scene, lf):
        lf.add_point()
        seen = []
        bake_exposure(bpy.context.scene, [floor_scene["floor"]], SMALL,
                      progress=lambda fraction, message: seen.append((fraction, message)))
        assert [f for f, _ in seen] == [0.5, 1.0] and "Floor" in seen[0][1]


class TestSettings:
    def test_preset_samples_custom_samples(self, blender):
        scene = bpy.context.scene
        scene.lightfade.bake_samples = 24
        settings = BakeSettings.from_scene(scene)
        assert (settings.samples, settings.denoise, settings.resolution) == (8, True, None)
        scene.lightfade_bake.quality = "PREVIEW"
        assert BakeSettings.from_scene(scene).samples == 4
        scene.lightfade_bake.quality = "CUSTOM"
        scene.lightfade_bake.denoise = False
        settings = BakeSettings.from_scene(scene)
        assert (settings.samples, settings.denoise) == (24, False)

    def test_margin_density_and_largest_size_come_from_the_scene(self, blender):
        scene = bpy.context.scene
        scene.lightfade.bake_margin, scene.lightfade.bake_resolution = 5, 256
        scene.lightfade_bake.texels_per_metre = 100.0
        settings = BakeSettings.from_scene(scene)
        assert (settings.margin, settings.max_size, settings.texels_per_metre) == (5, 256, 100.0)

    def test_calibration_gives_an_estimate(self, floor_scene):
        from lightfade_addon.blender.bake import calibrate, sizing

        scene = bpy.context.scene
        assert sizing.estimate(scene, [[64, 32]], 8, True).seconds is None
        rate, overhead = calibrate(scene, floor_scene["floor"])
        assert rate > 1e4 and overhead >= 0
        est = sizing.estimate(scene, [[64, 32], [64]], 8, True)
        assert est.texel_samples == (64 * 64 * 2 + 32 * 32) * 8 and est.calls == 2
        assert est.seconds > 0 and "s" in est.text()


def test_calibration_does_not_time_the_first_bake():
    """A fresh scene's first bake also prepares what later bakes reuse (the sky map,
    Cycles' kernels): timed, it made the rate look many times too fast."""
    from lightfade_addon.blender.bake import sizing

    now, sizes = [0.0], []

    def run(size, samples):  # 0.1 s a call, 2 µs a texel-sample, 0.5 s more the first time
        now[0] += (0.0 if sizes else 0.5) + 0.1 + size * size * samples * 2e-6
        sizes.append((size, samples))

    rate, overhead = sizing.calibrate(run, clock=lambda: now[0])
    assert sizes == [sizing.WARM_UP, *sizing.TIMED]
    assert rate == pytest.approx(5e5) and overhead == pytest.approx(0.1)


def test_api_bake_sets_quality_density_and_custom_samples(floor_scene):
    """``api.bake`` stores its overrides in the scene, so the file remembers how it was baked."""
    from lightfade_addon import api

    scene = bpy.context.scene
    api.bake(scene, quality="CUSTOM", samples=3, density=32.0)
    assert scene.lightfade_bake.quality == "CUSTOM"
    assert scene.lightfade.bake_samples == 3
    assert scene.lightfade_bake.texels_per_metre == 32.0
    assert len(floor_scene["floor"].lightfade.exposure_maps) == 1
