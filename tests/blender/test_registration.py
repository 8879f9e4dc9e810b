"""Registration is symmetric and repeatable; the data model has its documented defaults."""

import subprocess
import sys
from pathlib import Path

import addon_utils
import bpy

ADDON = "lightfade_addon"
ROOT = Path(__file__).resolve().parents[2]

POINTERS = [
    (bpy.types.Scene, "lightfade"),
    (bpy.types.Light, "lightfade"),
    (bpy.types.World, "lightfade"),
    (bpy.types.Object, "lightfade"),
    (bpy.types.Object, "lightfade_emitter"),
    (bpy.types.Material, "lightfade"),
]


class TestRegister:
    def test_enable_disable_twice(self, blender):
        for _ in range(2):
            addon_utils.disable(ADDON, default_set=True)
            assert not any(hasattr(t, a) for t, a in POINTERS)
            assert not hasattr(bpy.types, "LIGHTFADE_OT_bake_exposure")
            assert not hasattr(bpy.types, "VIEW3D_PT_lightfade_bake")
            addon_utils.enable(ADDON, default_set=True)
            assert all(hasattr(t, a) for t, a in POINTERS)
            assert hasattr(bpy.ops.lightfade, "bake_exposure")
            assert bpy.context.scene.lightfade.bake_resolution == 1024

    def test_register_unregister_directly_twice(self, blender):
        import lightfade_addon

        addon_utils.disable(ADDON, default_set=True)
        for _ in range(2):
            lightfade_addon.register()
            assert hasattr(bpy.types.Scene, "lightfade")
            lightfade_addon.unregister()
            assert not hasattr(bpy.types.Scene, "lightfade")
        addon_utils.enable(ADDON, default_set=True)

    def test_register_touches_no_scene_data(self, blender):
        addon_utils.disable(ADDON, default_set=True)
        kinds = ("objects", "materials", "images", "scenes", "worlds", "node_groups", "texts")
        before = {k: len(getattr(bpy.data, k)) for k in kinds}
        scene_keys = set(bpy.context.scene.keys())
        addon_utils.enable(ADDON, default_set=True)
        assert {k: len(getattr(bpy.data, k)) for k in kinds} == before
        assert set(bpy.context.scene.keys()) == scene_keys

    def test_names_and_ui(self, blender):
        from lightfade_addon import blender as shell

        for cls in shell.classes:
            name = cls.__name__
            assert name.startswith(("LIGHTFADE_PG_", "LIGHTFADE_OT_", "VIEW3D_PT_lightfade_", "MATERIAL_PT_lightfade"))
            if name.startswith("VIEW3D_PT_"):
                assert cls.bl_category == "LightFade" and cls.bl_region_type == "UI"
            if name.startswith("LIGHTFADE_OT_"):
                assert cls.bl_idname.startswith("lightfade.")
                assert cls.bl_options == {"REGISTER", "UNDO"}
        assert shell.panels.MATERIAL_PT_lightfade.bl_context == "material"

    def test_every_property_has_a_tooltip(self, blender):
        from lightfade_addon.blender import properties

        for cls in properties.CLASSES:
            for prop in cls.bl_rna.properties:
                if prop.identifier in {"rna_type", "name"}:
                    continue
                assert prop.description, f"{cls.__name__}.{prop.identifier} has no description"

    def test_import_without_bpy(self):
        code = (
            "import sys, importlib.abc\n"
            "class B(importlib.abc.MetaPathFinder):\n"
            "    def find_spec(self, name, path, target=None):\n"
            "        if name.split('.')[0] in {'bpy', 'addon_utils'}: raise ImportError(name)\n"
            "sys.meta_path.insert(0, B())\n"
            "import lightfade_addon\n"
            "assert 'bpy' not in sys.modules\n"
        )
        subprocess.run([sys.executable, "-c", code], cwd=ROOT, check=True)


class TestDefaults:
    def test_scene(self, blender):
        s = bpy.context.scene.lightfade
        assert (s.years, s.bake_resolution, s.bake_samples, s.bake_margin) == (0.0, 1024, 64, 16)
        prop = s.bl_rna.properties["bake_resolution"]
        assert (prop.hard_min, prop.hard_max) == (64, 8192)
        assert s.bl_rna.properties["years"].is_animatable
        s.years = -3.0
        assert s.years == 0.0

    def test_light_world_schedule(self, blender):
        light = bpy.data.lights.new("L", "SPOT")
        world = bpy.data.worlds.new("W")
        for sched in (light.lightfade, world.lightfade):
            assert sched.enabled and sched.spectrum == "AUTO" and not sched.uv_filter
            assert (sched.hours_per_day, sched.days_per_year) == (8.0, 365.0)
            sched.hours_per_day = 30
            assert sched.hours_per_day == 24.0
        items = {i.identifier for i in light.lightfade.bl_rna.properties["spectrum"].enum_items}
        assert items == {"AUTO", "DAYLIGHT", "DAYLIGHT_GLASS", "INCANDESCENT", "FLUORESCENT", "LED"}

    def test_auto_spectrum(self, blender):
        from lightfade_addon.blender.properties import resolve_spectrum

        light = bpy.data.lights.new("L", "POINT")
        assert resolve_spectrum(light.lightfade, "SUN") == "daylight-glass"
        assert resolve_spectrum(light.lightfade, "WORLD") == "daylight-glass"
        assert resolve_spectrum(light.lightfade, "POINT") == "led"
        light.lightfade.spectrum = "INCANDESCENT"
        assert resolve_spectrum(light.lightfade, "SUN") == "incandescent"

    def test_material(self, blender):
        from lightfade_addon.blender.properties import RECIPE_IDS

        from lightfade_addon.core.recipes import RECIPES

        m = bpy.data.materials.new("M").lightfade
        assert (m.enabled, m.recipe, m.sensitivity_mode, m.blue_wool, m.source) == (
            False, "PRINTED_PAPER", "BLUE_WOOL", 2, None)     # the print's magenta: class 2
        assert set(RECIPE_IDS.values()) == {"printed-paper", "dyed-fabric", "painted-wood", "bare-wood"}
        m.recipe = "DYED_FABRIC"
        assert m.blue_wool == min(RECIPES["dyed-fabric"].blue_wool)  # the recipe's weakest class
        m.blue_wool = 9
        assert m.blue_wool == 8

    def test_object(self, blender):
        obj = bpy.data.objects.new("O", bpy.data.meshes.new("O"))
        assert len(obj.lightfade.exposure_maps) == 0 and obj.lightfade.uv_map == ""
        assert obj.lightfade_emitter.enabled
        item = obj.lightfade.exposure_maps.add()
        item.emitter, item.emitter_kind = "World", "WORLD"
        item.image = bpy.data.images.new("X", 4, 4, float_buffer=True)
        assert obj.lightfade.exposure_maps[0].image.name == "X"
