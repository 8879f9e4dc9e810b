"""Instances in the aged material: each reads its own tile of its source's exposure atlas.

The bake packs a source's placements into one atlas per light group
(:mod:`..bake.instances`) and writes each placement's tile ``(u0, v0, s)`` under the
source's tile attribute: a custom property of the instancing empty (or of the source,
where it renders itself).  The aging group then samples the atlas at

    uv_atlas = uv · s + (u0, v0)

with ``(u0, v0, s)`` read by an Attribute node of type *Instancer*: in Cycles and EEVEE
an instance reads its instancer's property, an object that is not an instance its own.
Nothing of this needs LightFade at render time.
"""

from __future__ import annotations

import bpy

from ..exposure import stale_placements


def tile_uv(g, uv, name):
    """The atlas UV of the exposure UV ``uv`` (a :class:`.graph.Sock`) for the instance
    being shaded: its tile from the attribute ``name``."""
    attr = g.node("ShaderNodeAttribute", depth=0, attribute_type="INSTANCER",
                  attribute_name=name)
    u0, v0, s = g.separate(g.out(attr, "Vector"))
    scaled = g.out(g.node("ShaderNodeVectorMath", {0: uv, "Scale": s}, operation="SCALE"),
                   "Vector")
    return g.vector("ADD", scaled, g.combine(u0, v0, 0.0))


def apply_problem(copy):
    """One line when ``copy``'s object is aged per instance (Apply bakes one image per
    object, not per instance), else None."""
    obj = copy.lightfade.aged_object
    if obj is not None and obj.lightfade.instance_tiles:
        return (f"Material '{copy.name}': '{obj.name}' is aged per instance (its instances read "
                "their own tiles of one exposure atlas); Apply to Images makes one image per "
                "object: keep Live Aging for it, or make its instances real to apply them")
    return None


#: How a stale instance is said (panel, ``info``, ``set_years``).
INSTANCES_STALE = "instances moved, appeared or went since the bake"


def instances_stale(scene, obj):
    """``"instances moved ... (names)"`` when ``obj``'s placements are not those baked
    into its atlas, else ''."""
    if obj is None or not obj.lightfade.instance_tiles:
        return ""
    layer = bpy.context.view_layer if bpy.context.scene == scene else scene.view_layers[0]
    keys = stale_placements(bpy.context.evaluated_depsgraph_get(), layer, obj)
    if not keys:
        return ""
    names = sorted({k.split("|")[0] or obj.name for k in keys})
    return f"{INSTANCES_STALE} ({', '.join(names[:3])}{'…' if len(names) > 3 else ''})"
