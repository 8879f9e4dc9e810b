"""Annual daylight, Blender side: the place, the daylight group's one bake, its units,
what it does to sun lamps and the world, annual doses and the false-colour view.

Bakes are tiny (32–64² maps, a 64-wide sky map, few samples): each checks one behaviour
and would fail if it broke.
"""

import math

import numpy as np
import pytest

bpy = pytest.importorskip("bpy")
import bmesh  # noqa: E402

from lightfade_addon import api  # noqa: E402
from lightfade_addon.blender.bake import find_groups  # noqa: E402
from lightfade_addon.blender.daylight import place as place_mod  # noqa: E402
from lightfade_addon.core.daylight import annual as core_daylight  # noqa: E402

SKY_WIDTH = 64


def _settle(scene):
    scene.lightfade_daylight.sky_width = SKY_WIDTH
    scene.lightfade_bake.quality = "CUSTOM"


def _material(name, enabled=True, colour=(0.5, 0.3, 0.2)):
    mat = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (*colour, 1.0)
    mat.lightfade.enabled = enabled
    return mat


def _plane(name, size, location, rotation=(0.0, 0.0, 0.0), material=None):
    bpy.ops.mesh.primitive_plane_add(size=size, location=location, rotation=rotation)
    obj = bpy.context.active_object
    obj.name = name
    obj.data.materials.append(material or _material(name))
    return obj


def _mesh_object(name, quads):
    """An object of quads given as 4 corner tuples each (no UVs: occluders only)."""
    mesh = bpy.data.meshes.new(name)
    bm = bmesh.new()
    for quad in quads:
        bm.faces.new([bm.verts.new(v) for v in quad])
    bm.to_mesh(mesh)
    bm.free()
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def _wall_y(y, x0, x1, z0, z1):
    return [(x0, y, z0), (x1, y, z0), (x1, y, z1), (x0, y, z1)]


def build_room(bar=True, box=True):
    """A 4 × 4 × 2.5 m room with a window in its south wall (y = -2, scene +Y is north):
    the opening x ∈ [-1, 1], z ∈ [0.5, 2.0] split by a 0.1 m vertical bar at x = 0.
    The floor (a target) is a 4 m plane; a 0.6 m box stands on it at (1.2, 0.6)."""
    quads = [
        _wall_y(-2, -2, -1, 0, 2.5), _wall_y(-2, 1, 2, 0, 2.5),        # beside the window
        _wall_y(-2, -1, 1, 0, 0.5), _wall_y(-2, -1, 1, 2.0, 2.5),      # below and above
        _wall_y(2, -2, 2, 0, 2.5),                                      # north wall
        [(-2, -2, 0), (-2, 2, 0), (-2, 2, 2.5), (-2, -2, 2.5)],         # west
        [(2, -2, 0), (2, 2, 0), (2, 2, 2.5), (2, -2, 2.5)],             # east
        [(-2, -2, 2.5), (2, -2, 2.5), (2, 2, 2.5), (-2, 2, 2.5)],       # ceiling
    ]
    if bar:
        quads.append(_wall_y(-2, -0.05, 0.05, 0.5, 2.0))
    _mesh_object("Walls", quads)
    floor = _plane("Floor", 4.0, (0.0, 0.0, 0.0))
    if box:
        bpy.ops.mesh.primitive_cube_add(size=0.6, location=(1.2, 0.6, 0.3))
        bpy.context.active_object.name = "Box"
    return floor


def _bake(scene, objects, samples=16, resolution=64):
    """Bake ``objects`` so that the largest (by its widest dimension) gets ``resolution``²."""
    width = max(max(o.dimensions) for o in objects)
    return api.bake(scene, objects=objects, quality="CUSTOM", samples=samples,
                    resolution=max(resolution, 64), density=resolution / width, margin=2)


def _static_sun(elevation, azimuth_from_south=0.0):
    """A hard sun lamp from the south (scene -Y) at ``elevation`` degrees."""
    data = bpy.data.lights.new("Sun", "SUN")
    data.energy = 3.0
    data.angle = 0.0
    obj = bpy.data.objects.new("Sun", data)
    bpy.context.scene.collection.objects.link(obj)
    # a sun lamp shines along its local -Z: tilt it toward +Y by the zenith angle
    obj.rotation_euler = (math.radians(90.0 - elevation), 0.0, math.radians(azimuth_from_south))
    return obj


def _texel(shape, x, y, half=2.0):
    """(row, column) of the floor texel at (x, y) m on the 4 m floor plane."""
    h, w = shape
    return (int((y + half) / (2 * half) * h), int((x + half) / (2 * half) * w))


# ----------------------------------------------------------------------- set_daylight


class TestSetDaylight:
    def test_place_is_stored_and_daylight_turned_on(self, blender):
        scene = bpy.context.scene
        assert place_mod.place_source(scene) is None
        api.set_daylight(scene, 52.0, 4.5, north=30.0)
        d = scene.lightfade_daylight
        assert (d.latitude, d.longitude, d.north) == pytest.approx((52.0, 4.5, 30.0))
        assert place_mod.daylight_active(scene)
        place = place_mod.scene_place(scene)
        assert (place.latitude, place.longitude, place.north) == pytest.approx((52.0, 4.5, 30.0))
        assert place.weather is None                       # clear sky

    @pytest.mark.parametrize("args, word", [
        ((91.0, 0.0), "Latitude"), ((float("nan"), 0.0), "Latitude"),
        ((10.0, 181.0), "Longitude"), ((10.0, 0.0, float("inf")), "North"),
        ((10.0, "east"), "Longitude"),
    ])
    def test_bad_numbers_are_refused_before_anything_changes(self, blender, args, word):
        scene = bpy.context.scene
        with pytest.raises(ValueError, match=word):
            api.set_daylight(scene, *args)
        assert not scene.lightfade_daylight.place_set
        assert place_mod.place_source(scene) is None

    def test_missing_weather_file_is_named(self, blender, tmp_path):
        scene = bpy.context.scene
        missing = tmp_path / "nowhere.epw"
        with pytest.raises(ValueError, match="nowhere.epw.*not found"):
            api.set_daylight(scene, 52.0, 4.5, weather=missing)
        assert not scene.lightfade_daylight.place_set

    def test_unreadable_weather_file_is_named(self, blender, tmp_path):
        scene = bpy.context.scene
        bad = tmp_path / "garbage.epw"
        bad.write_text("this is not a weather file\n")
        with pytest.raises(ValueError, match="garbage.epw"):
            api.set_daylight(scene, 52.0, 4.5, weather=bad)
        assert scene.lightfade_daylight.weather == ""

    def test_a_weather_file_removed_later_stops_the_bake_with_its_name(self, blender, tmp_path):
        scene = bpy.context.scene
        scene.lightfade_daylight.latitude = 52.0        # typed: a place
        scene.lightfade_daylight.weather = str(tmp_path / "gone.epw")
        floor = _plane("Floor", 2.0, (0, 0, 0))
        with pytest.raises(RuntimeError, match="gone.epw.*not found"):  # before any Cycles work
            _bake(scene, [floor], samples=1, resolution=16)
        assert not len(floor.lightfade.exposure_maps)


class TestPlaceSources:
    def test_typing_a_latitude_sets_a_place(self, blender):
        scene = bpy.context.scene
        scene.lightfade_daylight.latitude = 40.0
        assert place_mod.place_source(scene)[:3] == pytest.approx((40.0, 0.0, 0.0))
        assert place_mod.daylight_active(scene)

    def test_a_preset_fills_the_place(self, blender):
        scene = bpy.context.scene
        from lightfade_addon.blender.daylight.settings import PLACE_IDS

        key, name = next(iter(PLACE_IDS.items()))
        scene.lightfade_daylight.preset = key
        preset = core_daylight.PLACES[name]
        assert place_mod.place_source(scene)[:2] == pytest.approx(
            (preset.latitude, preset.longitude), abs=1e-4)

    def test_sun_position_settings_are_honoured_enabled_or_not(self, blender):
        """The add-on's latitude, longitude and north_offset (clockwise, radians) are read
        while it is registered and from the ID properties it leaves when it is not."""

        class SunPosProps(bpy.types.PropertyGroup):
            latitude: bpy.props.FloatProperty()
            longitude: bpy.props.FloatProperty()
            north_offset: bpy.props.FloatProperty(subtype="ANGLE")

        scene = bpy.context.scene
        bpy.utils.register_class(SunPosProps)
        bpy.types.Scene.sun_pos_properties = bpy.props.PointerProperty(type=SunPosProps)
        try:
            assert place_mod.place_source(scene) is None      # nothing stored yet
            sp = scene.sun_pos_properties
            sp.latitude, sp.longitude, sp.north_offset = 48.0, 11.5, math.radians(30.0)
            lat, lon, north, where = place_mod.place_source(scene)
            assert (lat, lon, north) == pytest.approx((48.0, 11.5, -30.0), abs=1e-4)
            assert "Sun Position" in where
        finally:
            del bpy.types.Scene.sun_pos_properties
            bpy.utils.unregister_class(SunPosProps)
        lat, lon, north, _ = place_mod.place_source(scene)
        assert (lat, lon, north) == pytest.approx((48.0, 11.5, -30.0), abs=1e-4)
        api.set_daylight(scene, 10.0, 20.0)              # an explicit place wins
        assert place_mod.place_source(scene)[:2] == pytest.approx((10.0, 20.0))


# ----------------------------------------------------------------------- the group


class TestDaylightGroup:
    def test_sun_lamps_and_a_daylight_world_give_way_to_one_daylight_group(self, blender):
        scene = bpy.context.scene
        _static_sun(40.0)
        lamp = bpy.data.lights.new("Lamp", "POINT")
        lamp.energy = 50.0
        scene.collection.objects.link(bpy.data.objects.new("Lamp", lamp))
        world = bpy.data.worlds.new("Sky")
        scene.world = world
        if bpy.app.version < (5, 0, 0):
            world.use_nodes = True
        world.lightfade.spectrum = "DAYLIGHT"
        bpy.context.view_layer.update()
        before = {g.name: g.key for g in find_groups(scene)}
        assert "Sun" in before and "World" in before and "Lamp" in before
        api.set_daylight(scene, 52.0, 0.0)
        after = {g.name: g.key for g in find_groups(scene)}
        assert set(after) == {"Lamp", "Daylight"}
        assert after["Daylight"] == ("daylight-glass", False, 24.0, 365.0)
        assert after["Lamp"] == before["Lamp"]                     # lamps keep their schedules
        scene.lightfade_daylight.enabled = False
        assert {g.name for g in find_groups(scene)} == set(before)


def _open_plane_scene(north=0.0, lat=52.0):
    scene = bpy.context.scene
    _settle(scene)
    api.set_daylight(scene, lat, 0.0, north=north)
    return scene


class TestAnnualBake:
    def test_uniform_sky_calibration_gives_pi_L_a_year(self, blender, monkeypatch):
        """A uniform sky of radiance L (lux·h/yr/sr) gives an open plane π L lux·h a year."""
        scene = _open_plane_scene()
        L = 4.0e6
        monkeypatch.setattr(place_mod, "annual_sky",
                            lambda s: np.full((SKY_WIDTH // 2, SKY_WIDTH), L, np.float32))
        floor = _plane("Floor", 2.0, (0, 0, 0))
        _bake(scene, [floor], samples=8, resolution=16)
        dose = api.annual_dose(scene, floor)["Daylight"]
        assert dose.shape == (16, 16)
        assert float(dose.mean()) == pytest.approx(math.pi * L, rel=0.01)

    def test_open_plane_dose_matches_the_sky_maps_plane_dose(self, blender):
        scene = _open_plane_scene()
        floor = _plane("Floor", 2.0, (0, 0, 0))
        _bake(scene, [floor], samples=16, resolution=16)
        dose = float(api.annual_dose(scene, floor)["Daylight"].mean())
        expected = float(core_daylight.plane_dose(place_mod.annual_sky(scene), (0.0, 0.0, 1.0)))
        assert dose == pytest.approx(expected, rel=0.03)
        # the lamp-style bookkeeping agrees: stored mean lux × 24 h × 365 d
        item = floor.lightfade.exposure_maps["Daylight"]
        assert item.emitter_kind == "DAYLIGHT"

    @pytest.mark.parametrize("north", [0.0, 180.0])
    def test_north_decides_which_wall_gets_the_sun(self, blender, north):
        """At 52° N the wall facing geographic south gets far more than the one facing
        north; turning north by 180° swaps them."""
        scene = _open_plane_scene(north=north)
        facing_minus_y = _plane("WallA", 1.0, (0, -3, 1), rotation=(math.radians(90), 0, 0))
        facing_plus_y = _plane("WallB", 1.0, (0, 3, 1), rotation=(math.radians(-90), 0, 0))
        _bake(scene, [facing_minus_y, facing_plus_y], samples=8, resolution=16)
        a = float(api.annual_dose(scene, facing_minus_y)["Daylight"].mean())
        b = float(api.annual_dose(scene, facing_plus_y)["Daylight"].mean())
        south, north_facing = (a, b) if north == 0.0 else (b, a)
        assert south > 2.0 * north_facing

    def test_users_world_and_lamps_are_as_before_and_nothing_is_left(self, blender):
        scene = _open_plane_scene()
        world = bpy.data.worlds.new("Mine")
        scene.world = world
        if bpy.app.version < (5, 0, 0):
            world.use_nodes = True
        nodes_before = sorted(n.name for n in world.node_tree.nodes)
        sun = _static_sun(40.0)
        worlds, images = set(bpy.data.worlds), set(bpy.data.images)
        floor = _plane("Floor", 2.0, (0, 0, 0))
        _bake(scene, [floor], samples=2, resolution=16)
        assert scene.world == world
        assert sorted(n.name for n in world.node_tree.nodes) == nodes_before
        assert set(bpy.data.worlds) == worlds
        new_images = set(bpy.data.images) - images
        assert {i.name for i in new_images} == {"LF_Exposure_Floor_Daylight"}
        assert not sun.hide_render

    def test_mullion_leaves_no_sharp_shadow_but_a_box_leaves_a_crisp_footprint(self, blender):
        """The issue's room: under one static sun the bar's shadow is a dark stripe across
        the sunlit floor; over the year it is swept away, while the box standing on the
        floor keeps a dark footprint with a sharp edge."""
        scene = bpy.context.scene
        _settle(scene)
        floor = build_room()
        sun = _static_sun(38.0)                # noon at the equinox, 52° N
        _bake(scene, [floor], samples=16, resolution=64)
        static = api.annual_dose(scene, floor)["Sun"]
        api.set_daylight(scene, 52.0, 0.0)
        _bake(scene, [floor], samples=48, resolution=64)
        annual = api.annual_dose(scene, floor)["Daylight"]
        assert not sun.hide_render and "Sun" not in api.annual_dose(scene, floor)

        def dip(dose, y):
            row = dose[_texel(dose.shape, 0.0, y)[0]]
            c = _texel(dose.shape, 0.0, y)[1]
            centre = row[c - 1:c + 1].mean()
            sides = np.concatenate([row[c - 7:c - 4], row[c + 4:c + 7]]).mean()
            return 1.0 - centre / sides

        # static sun at 38°: the bar's shadow crosses y from -1.36 to 0.56 m
        assert dip(static, -0.4) > 0.5
        assert dip(annual, -0.4) < 0.10
        # the box's footprint: texels under it against texels just outside, same row
        r, c = _texel(annual.shape, 1.2, 0.6)
        inside = annual[r - 2:r + 3, c - 2:c + 3].mean()
        outside = np.concatenate([annual[r - 2:r + 3, c + 7:c + 9].ravel(),
                                  annual[r - 2:r + 3, c - 9:c - 7].ravel()]).mean()
        assert inside < 0.15 * outside
        edge = _texel(annual.shape, 1.5, 0.6)[1]          # the box's east face at x = 1.5
        ramp = annual[r, edge - 2:edge + 3]
        assert ramp[-1] > 3.0 * ramp[0]                  # dark to lit within 5 texels (30 cm)


# ----------------------------------------------------------------------- doses


class TestAnnualDose:
    def test_lamp_groups_count_their_hours(self, floor_scene):
        scene = bpy.context.scene
        floor, sun = floor_scene["floor"], floor_scene["sun"]
        sun.data.lightfade.hours_per_day = 6.0
        sun.data.lightfade.days_per_year = 200.0
        api.bake(scene, objects=[floor])
        lux = floor.lightfade.exposure_maps["Sun"].image
        w, h = lux.size
        px = np.empty(w * h * 4, np.float32)
        lux.pixels.foreach_get(px)
        dose = api.annual_dose(scene, floor)
        assert list(dose) == ["Sun"] and dose["Sun"].dtype == np.float32
        np.testing.assert_allclose(dose["Sun"], px.reshape(h, w, 4)[..., 0] * 1200.0, rtol=1e-6)

    def test_no_maps_is_an_error_naming_the_object(self, floor_scene):
        with pytest.raises(RuntimeError, match="Floor"):
            api.annual_dose(bpy.context.scene, floor_scene["floor"])


class TestDoseView:
    def test_view_leaves_the_users_object_and_material_alone(self, floor_scene, tmp_path):
        from lightfade_addon.blender.daylight import colours, view

        scene = bpy.context.scene
        floor, mat = floor_scene["floor"], floor_scene["material"]
        api.bake(scene, objects=[floor])
        links_before = len(mat.node_tree.links)
        nodes_before = sorted(n.name for n in mat.node_tree.nodes)
        shown, scale, _note = view.show_view(scene, floor, "DOSE")
        assert shown.material_slots[0].material.name.startswith("LF_DoseView")
        assert floor.material_slots[0].material == mat and floor.material_slots[0].link == "DATA"
        assert sorted(n.name for n in mat.node_tree.nodes) == nodes_before
        assert len(mat.node_tree.links) == links_before
        assert floor.hide_get() and shown.hide_render
        assert "LF_DoseView.Floor" not in {g.name for g in find_groups(scene)}
        # the shadow of the box is the darkest part of the false colour
        px = np.empty(len(bpy.data.images["LF_DoseView.Floor"].pixels), np.float32)
        bpy.data.images["LF_DoseView.Floor"].pixels.foreach_get(px)
        assert px.reshape(-1, 4)[:, :3].sum(axis=1).min() < 0.7
        pytest.importorskip("matplotlib")
        legend = colours.write_legend(str(tmp_path / "legend.png"), scale, "note")
        image = bpy.data.images.load(legend)
        assert image.size[0] > 300 and image.size[1] > 50
        bpy.data.images.remove(image)
        assert view.clear_view(scene) == 1
        assert not floor.hide_get()
        assert not any(n.startswith("LF_DoseView") for n in
                       [*bpy.data.objects.keys(), *bpy.data.materials.keys(),
                        *bpy.data.images.keys()])

    def test_years_to_noticeable_fade_follow_reciprocity(self, floor_scene):
        """One colour on the floor: the years to a just-noticeable fade are the same dose
        everywhere (years × annual dose constant), so the shaded texels take longer."""
        from lightfade_addon.blender.daylight.doses import total_dose, years_until_noticeable
        from tests.blender.conftest import COARSE_GRID

        scene = bpy.context.scene
        floor, mat = floor_scene["floor"], floor_scene["material"]
        for link in list(mat.node_tree.links):
            if link.to_socket.name == "Base Color":
                mat.node_tree.links.remove(link)
        mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = \
            (0.2, 0.1, 0.5, 1.0)
        mat.lightfade.recipe = "DYED_FABRIC"
        api.bake(scene, objects=[floor])
        years = years_until_noticeable(scene, floor, mat, settings=COARSE_GRID)
        dose = total_dose(scene, floor)
        assert years.shape == dose.shape
        lit = dose > 0.5 * dose.max()
        assert np.isfinite(years[lit]).all()
        jnd_dose = years[lit] * dose[lit]
        assert jnd_dose.std() / jnd_dose.mean() < 0.05
        shade = (dose < 0.2 * dose.max()) & (dose > 0)
        assert np.all(years[shade] > 2.0 * np.median(years[lit]))


class TestPanel:
    def test_panel_says_what_happens_to_the_sun_and_shows_doses_per_material(self, floor_scene):
        from types import SimpleNamespace

        from lightfade_addon.blender.daylight.panel import VIEW3D_PT_lightfade_daylight
        from tests.blender.test_panels import RecordingLayout as Recording

        class RecordingLayout(Recording):       # operator() gives the properties to set
            def _child(self, *args, **kwargs):
                return RecordingLayout(self.calls)

            row = column = box = split = _child

            def operator(self, idname, **kwargs):
                super().operator(idname, **kwargs)
                return SimpleNamespace()

        scene = bpy.context.scene
        _settle(scene)
        floor = floor_scene["floor"]

        def draw(obj):
            calls = []
            panel = SimpleNamespace(layout=RecordingLayout(calls))
            VIEW3D_PT_lightfade_daylight.draw(panel, SimpleNamespace(scene=scene, object=obj))
            return calls

        labels = [t for k, t in draw(floor) if k == "label"]
        assert any(t.startswith("No place") for t in labels)
        api.set_daylight(scene, 52.0, 4.5)
        _bake(scene, [floor], samples=2, resolution=16)
        calls = draw(floor)
        labels = [t for k, t in calls if k == "label"]
        assert any("Muted in the bake" in t and "Sun" in t for t in labels)
        assert any(t.startswith("Carpet ← Daylight") for t in labels)
        dose = api.annual_dose(scene, floor)["Daylight"]
        assert any(f"{dose.max() / 1e6:.3g} Mlx·h /" in t for t in labels)
        assert ("operator", "lightfade.dose_view") in calls
        from lightfade_addon.blender.panels import VIEW3D_PT_lightfade_emitter

        sun = floor_scene["sun"]
        calls = []
        VIEW3D_PT_lightfade_emitter.draw(SimpleNamespace(layout=RecordingLayout(calls)),
                                         SimpleNamespace(scene=scene, object=sun))
        assert any("replaces this sun" in t for k, t in calls if k == "label")


class TestInfo:
    def test_info_shows_the_place_and_annual_doses_per_material_and_a_moved_place(
            self, floor_scene):
        from lightfade_addon.pipeline import info

        scene = bpy.context.scene
        _settle(scene)
        floor = floor_scene["floor"]
        report = info.gather(scene)
        assert report["daylight"] is None
        api.set_daylight(scene, 52.0, 4.5, north=10.0)
        _bake(scene, [floor], samples=2, resolution=16)
        report = info.gather(scene)
        assert report["daylight"]["annual"] and report["daylight"]["muted_lamps"] == ["Sun"]
        (row,) = report["material_doses"]
        dose = api.annual_dose(scene, floor)["Daylight"]
        assert (row["material"], row["group"]) == ("Carpet", "Daylight")
        assert row["max"] == pytest.approx(float(dose.max()), rel=1e-5)
        text = info.as_text({**report, "file": "x.blend"})
        assert "daylight: 52.00°, 4.50°, north 10°" in text and "Carpet <- Daylight" in text
        assert not any("another place" in line for line in report["stale"])
        api.set_daylight(scene, 40.0, 4.5, north=10.0)
        assert any("another place" in line for line in info.gather(scene)["stale"])


class TestOperators:
    def test_dose_view_operator_shows_writes_a_legend_and_clears(self, floor_scene, tmp_path):
        scene = bpy.context.scene
        floor = floor_scene["floor"]
        api.bake(scene, objects=[floor])
        bpy.context.view_layer.objects.active = floor
        legend = tmp_path / "legend.png"
        assert bpy.ops.lightfade.dose_view(mode="DOSE", legend=str(legend)) == {"FINISHED"}
        assert "LF_DoseView.Floor" in bpy.data.objects and floor.hide_get()
        try:
            import matplotlib  # noqa: F401

            assert legend.stat().st_size > 1000
        except ImportError:
            assert not legend.exists()
        assert bpy.ops.lightfade.dose_view_clear() == {"FINISHED"}
        assert "LF_DoseView.Floor" not in bpy.data.objects and not floor.hide_get()

    def test_reset_clears_dose_views(self, floor_scene):
        scene = bpy.context.scene
        floor = floor_scene["floor"]
        api.bake(scene, objects=[floor])
        bpy.context.view_layer.objects.active = floor
        assert bpy.ops.lightfade.dose_view(mode="DOSE") == {"FINISHED"}
        assert bpy.ops.lightfade.reset() == {"FINISHED"}
        assert "LF_DoseView.Floor" not in bpy.data.objects and not floor.hide_get()

    def test_dose_view_without_maps_is_refused_with_the_objects_name(self, floor_scene):
        bpy.context.view_layer.objects.active = floor_scene["floor"]
        with pytest.raises(RuntimeError, match="Floor"):
            bpy.ops.lightfade.dose_view(mode="DOSE")
        assert "LF_DoseView.Floor" not in bpy.data.objects


class TestMaterialDoses:
    def test_each_material_counts_its_own_texels(self, blender):
        """A floor whose right half is another material and lies in a shadow: each
        material's dose is read over its own faces."""
        from lightfade_addon.blender.daylight.doses import material_doses

        scene = bpy.context.scene
        bpy.ops.mesh.primitive_grid_add(x_subdivisions=4, y_subdivisions=4, size=2.0,
                                        calc_uvs=True)
        floor = bpy.context.active_object
        floor.name = "Floor"
        floor.data.materials.append(_material("Left"))
        floor.data.materials.append(_material("Right"))
        for poly in floor.data.polygons:
            poly.material_index = int(poly.center.x > 0)
        _mesh_object("Shade", [[(0.0, -3, 1), (3, -3, 1), (3, 3, 1), (0.0, 3, 1)]])
        sun = _static_sun(90.0)                               # straight down
        sun.data.lightfade.hours_per_day = 10.0
        bpy.context.view_layer.update()
        _bake(scene, [floor], samples=4, resolution=32)
        rows = {r["material"]: r for r in material_doses(scene, floor)}
        assert set(rows) == {"Left", "Right"}
        dose = api.annual_dose(scene, floor)["Sun"]
        assert rows["Left"]["max"] == pytest.approx(float(dose.max()), rel=1e-5)
        assert rows["Right"]["mean"] < 0.3 * rows["Left"]["mean"]
