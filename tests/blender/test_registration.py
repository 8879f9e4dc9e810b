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
            assert name.startswith(("LIGHTFADE_PG_", "LIGHTFADE_OT_", "LIGHTFADE_UL_", "VIEW3D_PT_lightfade_",
                                    "MATERIAL_PT_lightfade"))
            if name.startswith("VIEW3D_PT_"):
                assert cls.bl_category == "LightFade" and cls.bl_region_type == "UI"
            if name.startswith("LIGHTFADE_OT_"):
                assert cls.bl_idname.startswith("lightfade.")
                assert cls.bl_options == {"REGISTER", "UNDO"}
        assert shell.aging_panel.MATERIAL_PT_lightfade.bl_context == "material"

    def test_every_property_has_a_tooltip(self, blender):
        import bpy
        from lightfade_addon import blender as shell

        groups = [c for c in shell.classes if issubclass(c, bpy.types.PropertyGroup)]
        assert {"LIGHTFADE_PG_material", "LIGHTFADE_PG_part", "LIGHTFADE_PG_scene"} <= {
            c.__name__ for c in groups}
        for cls in groups:
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


def _enum(rna_owner, prop):
    """{identifier: (name, description)} of an enum property as Blender registered it."""
    return {i.identifier: (i.name, i.description)
            for i in rna_owner.bl_rna.properties[prop].enum_items}


class TestOneVocabulary:
    """The UI's words and defaults are the core's tables, as registered in Blender."""

    def test_spectra_are_the_core_lights_with_their_descriptions(self, blender):
        from lightfade_addon.core.fading.spectra import LIGHTS

        items = _enum(bpy.data.lights.new("L", "SPOT").lightfade, "spectrum")
        assert list(items) == ["AUTO"] + [n.upper().replace("-", "_") for n in LIGHTS]
        for name, text in LIGHTS.items():
            assert items[name.upper().replace("-", "_")][1] == text
        assert LIGHTS["daylight-glass"] in items["AUTO"][1] and LIGHTS["led"] in items["AUTO"][1]

    def test_recipes_are_the_core_recipes_with_their_descriptions(self, blender):
        from lightfade_addon.core.fading.recipes import RECIPES

        items = _enum(bpy.data.materials.new("M").lightfade, "recipe")
        assert list(items) == [n.upper().replace("-", "_") for n in RECIPES]
        for name, recipe in RECIPES.items():
            assert items[name.upper().replace("-", "_")][1] == recipe.description

    def test_every_emitter_kind_resolves_to_a_core_light(self, blender):
        from lightfade_addon.blender.vocabulary import EMITTER_KIND_ITEMS, resolve_spectrum
        from lightfade_addon.core.fading.spectra import LIGHTS

        light = bpy.data.lights.new("L", "POINT")
        kinds = [kind for kind, *_ in EMITTER_KIND_ITEMS]
        auto = {kind: resolve_spectrum(light.lightfade, kind) for kind in kinds}
        assert auto == {"SUN": "daylight-glass", "WORLD": "daylight-glass",
                        "EMISSIVE": "daylight-glass", "POINT": "led", "SPOT": "led",
                        "AREA": "led", "DAYLIGHT": "daylight-glass"}
        for name in LIGHTS:
            light.lightfade.spectrum = name.upper().replace("-", "_")
            assert {resolve_spectrum(light.lightfade, kind) for kind in kinds} == {name}

    def test_schedule_defaults_are_the_core_light_defaults(self, blender):
        from lightfade_addon.core.aging.ager import Light

        core = Light()
        for sched in (bpy.data.lights.new("L", "SPOT").lightfade,
                      bpy.data.worlds.new("W").lightfade,
                      bpy.data.objects.new("O", None).lightfade_emitter):
            assert sched.spectrum == "AUTO"
            assert (sched.uv_filter, sched.hours_per_day, sched.days_per_year) == (
                core.uv_filter, core.hours_per_day, core.days_per_year)
        # lamps and the world count by default; an emissive mesh only when asked to
        assert bpy.data.lights.new("L2", "AREA").lightfade.enabled
        assert bpy.data.worlds.new("W2").lightfade.enabled
        assert not bpy.data.objects.new("O2", None).lightfade_emitter.enabled

    def test_a_recipe_brings_its_weakest_blue_wool_class(self, blender):
        from lightfade_addon.core.fading.recipes import RECIPES

        m = bpy.data.materials.new("M").lightfade
        weakest = {n: min(k for k in r.blue_wool if k is not None) for n, r in RECIPES.items()}
        assert m.recipe == "PRINTED_PAPER" and m.blue_wool == weakest["printed-paper"]
        assert len(set(weakest.values())) > 1             # the recipes really differ
        for name in reversed(list(RECIPES)):
            m.recipe = name.upper().replace("-", "_")
            assert m.blue_wool == weakest[name], name


class TestLimits:
    """What Blender itself enforces: hard limits clamp, the slider is animatable."""

    def test_scene(self, blender):
        scene = bpy.context.scene
        s = scene.lightfade
        for value, kept in ((-3.0, 0.0), (250.0, 250.0)):          # no cap above 100 years
            s.years = value
            assert s.years == kept
        # the years live in a keyframable custom property with the slider's settings
        assert scene["lightfade_years"] == 250.0
        assert scene.id_properties_ui("lightfade_years").as_dict()["min"] == 0.0
        assert scene.keyframe_insert('["lightfade_years"]', frame=3)
        for value, kept in ((1, 64), (10 ** 6, 8192), (512, 512)):
            s.bake_resolution = value
            assert s.bake_resolution == kept

    def test_schedule_clamps_to_a_day_and_a_year(self, blender):
        sched = bpy.data.lights.new("L", "SPOT").lightfade
        for attr, value, kept in (("hours_per_day", 30, 24.0), ("hours_per_day", -1, 0.0),
                                  ("days_per_year", 400, 366.0), ("days_per_year", -5, 0.0)):
            setattr(sched, attr, value)
            assert getattr(sched, attr) == kept, attr

    def test_blue_wool_class_is_1_to_8(self, blender):
        m = bpy.data.materials.new("M").lightfade
        for value, kept in ((9, 8), (0, 1), (5, 5)):
            m.blue_wool = value
            assert m.blue_wool == kept

    def test_object_holds_exposure_maps(self, blender):
        obj = bpy.data.objects.new("O", bpy.data.meshes.new("O"))
        assert len(obj.lightfade.exposure_maps) == 0 and obj.lightfade.uv_map == ""
        item = obj.lightfade.exposure_maps.add()
        item.emitter, item.emitter_kind = "World", "WORLD"
        item.image = bpy.data.images.new("X", 4, 4, float_buffer=True)
        assert obj.lightfade.exposure_maps[0].image.name == "X"
