"""The panels draw without errors and only reference properties and operators that exist.

Panels cannot be drawn in background mode, so ``draw`` runs against a recording layout
that checks every ``prop`` and ``operator`` call.
"""

from types import SimpleNamespace

import bpy

from lightfade_addon.blender.bake import BakeSettings, bake_exposure


class OperatorProperties:
    """What ``layout.operator`` returns: setting a property the operator lacks fails."""

    def __init__(self, op):
        object.__setattr__(self, "_names", op.get_rna_type().properties.keys())

    def __setattr__(self, name, value):
        assert name in self._names, f"the operator has no property {name!r}"


class RecordingLayout:
    def __init__(self, calls):
        self.calls = calls
        self.use_property_split = False
        self.active = True

    def _child(self, *args, **kwargs):
        return RecordingLayout(self.calls)

    row = column = box = split = _child

    def prop(self, data, name, **kwargs):
        assert name in data.bl_rna.properties, f"{data!r} has no property {name!r}"
        self.calls.append(("prop", name))

    def operator(self, idname, **kwargs):
        module, name = idname.split(".")
        assert hasattr(getattr(bpy.ops, module), name), idname
        self.calls.append(("operator", idname))
        return OperatorProperties(getattr(getattr(bpy.ops, module), name))

    def label(self, text="", **kwargs):
        self.calls.append(("label", text))

    def template_list(self, list_type, list_id, data, name, active_data, active_name, **kw):
        assert hasattr(bpy.types, list_type) and name in data.bl_rna.properties
        assert active_name in active_data.bl_rna.properties
        self.calls.append(("list", name))

    def template_ID(self, data, name, **kwargs):
        assert name in data.bl_rna.properties
        self.calls.append(("prop", name))


def draw_all(context):
    from lightfade_addon import blender as shell

    calls = []
    for cls in (c for c in shell.classes if issubclass(c, bpy.types.Panel)):
        if hasattr(cls, "poll") and not cls.poll(context):
            continue
        panel = SimpleNamespace(layout=RecordingLayout(calls))
        if hasattr(cls, "draw_header"):
            cls.draw_header(panel, context)
        cls.draw(panel, context)
    return calls


def test_panels_draw(floor_scene, lf):
    scene = bpy.context.scene
    world = bpy.data.worlds.new("Sky")
    scene.world = world
    bake_exposure(scene, [floor_scene["floor"]], BakeSettings(32, 2, 1))
    floor, sun = floor_scene["floor"], floor_scene["sun"]
    for active in (floor, sun):
        ctx = SimpleNamespace(scene=scene, object=active, material=floor_scene["material"])
        calls = draw_all(ctx)
        assert ("operator", "lightfade.bake_exposure") in calls
        assert ("prop", "years") in calls and ("prop", "recipe") in calls
    # Active lamp: its schedule and the brightest texel and annual dose of each lit object.
    sun.data.lightfade.hours_per_day, sun.data.lightfade.days_per_year = 10.0, 100.0
    ctx = SimpleNamespace(scene=scene, object=sun, material=None)
    labels = [text for kind, text in draw_all(ctx) if kind == "label"]
    from lightfade_addon.blender.stats import image_max

    image = floor.lightfade.exposure_maps["Sun"].image
    max_lux = image_max(image)
    assert max_lux == lf.pixels(image).max() and max_lux > 683 * 2 * 0.766 * 0.97
    assert f"{max_lux:,.0f} lx" in labels
    assert any(f"({max_lux * 1000 / 1e6:.3g} Mlx·h)" in t for t in labels)


def test_material_panel_says_each_colourants_class(floor_scene):
    """The material panel shows the recipe's description and each colourant's class as
    the Blue Wool setting shifts them (printed paper at 2: yellow 2, magenta 2.5, cyan 4)."""
    from lightfade_addon.core.fading.recipes import RECIPES

    mat = floor_scene["material"]
    mat.lightfade.enabled = True
    mat.lightfade.recipe = "PRINTED_PAPER"
    mat.lightfade.blue_wool = 2
    ctx = SimpleNamespace(scene=bpy.context.scene, object=floor_scene["floor"], material=mat)
    labels = [text for kind, text in draw_all(ctx) if kind == "label"]
    assert RECIPES["printed-paper"].description in labels
    assert "Per colourant: cyan 4 · magenta 2.5 · yellow 2" in labels
