"""Geometry a bake cannot take, refused in one line before any Cycles work.

Cycles bakes the mesh as rendered (modifiers and geometry nodes applied) on one of its
UV maps, so an object is refused, naming it, the reason and what to do, when

* its geometry as rendered is only instances (a geometry-nodes scatter that is not
  realized) or has no faces at all: there is no surface to hold a map;
* the mesh as rendered lacks the UV map it would be baked on (a geometry-nodes tree
  that builds new geometry drops the original's UV maps);
* a ``LightFadeUV`` map to be made would have more UV islands than the capped map has
  room for: each island needs at least :data:`MIN_ISLAND_TEXELS` texels with its gaps.
"""

from __future__ import annotations

from .common import UV_MAP_NAME, LightFadeBakeError
from .sizing import PACK_FILL, planned_map
from .uvmaps import PACK_GAP_TEXELS, evaluated_mesh, polygon_islands, remove_made_uv

#: Texels an island needs at least in a packed map: two texels across and the packing
#: gap it shares with its neighbours, ``(2 + gap)²``.
MIN_ISLAND_TEXELS = (2 + PACK_GAP_TEXELS) ** 2


def _generator(obj):
    """The last modifier that makes geometry (geometry nodes), or the last one, or None."""
    mods = [m for m in obj.modifiers if m.show_render or m.show_viewport]
    nodes = [m for m in mods if m.type == "NODES"]
    return (nodes or mods or [None])[-1]


def _from(mod):
    """``from its Nodes modifier "Scatter"`` (or '' without one)."""
    return f"from its {mod.type.title().replace('_', ' ')} modifier \"{mod.name}\"" if mod else ""


def instance_count(obj, depsgraph):
    """Instances ``obj`` puts in the scene as rendered (geometry nodes, particles...)."""
    return sum(1 for inst in depsgraph.object_instances
               if inst.is_instance and inst.parent is not None and inst.parent.original == obj)


def baked_uv_name(obj):
    """The UV map of ``obj``'s mesh its exposure is baked on now: ``LightFadeUV`` once
    made, else the active map (None without one)."""
    layers = obj.data.uv_layers
    if obj.lightfade.uv_created and UV_MAP_NAME in layers:
        return UV_MAP_NAME
    return layers.active.name if layers.active else None


def evaluated_problem(obj, depsgraph, uv_name):
    """Why the mesh ``obj`` renders as cannot be baked on ``uv_name`` (None: only its
    faces are checked), or ''."""
    with evaluated_mesh(obj, depsgraph) as mesh:
        faces = len(mesh.polygons)
        layers = set(mesh.uv_layers.keys())
    mod = _generator(obj)
    by = f" ({_from(mod)})" if mod else ""
    if faces == 0:
        count = instance_count(obj, depsgraph)
        if count:
            where = f", {_from(mod)}" if mod else ""
            return (f"\"{obj.name}\": its geometry as rendered is only instances ({count} "
                    f"of them{where}), which hold no "
                    "map: realize them (a Realize Instances node before its Group Output, "
                    "or Object > Convert > Mesh) and bake again")
        return (f"\"{obj.name}\": its mesh as rendered has no faces{by}, so there is "
                "nothing to bake a map on: deselect it, or make its modifiers output faces")
    if uv_name and uv_name not in layers:
        return (f"\"{obj.name}\": its mesh as rendered has no UV map \"{uv_name}\"{by}: "
                f"keep the UV map in its node tree (Store Named Attribute, 2D Vector on Face "
                f"Corner, named \"{uv_name}\"), or apply the modifier, and bake again")
    return ""


def check_made_map(obj, depsgraph):
    """After ``LightFadeUV`` was made on ``obj``'s mesh: when the mesh as rendered lacks
    it (its modifiers drop UV maps), remove it and raise :class:`.LightFadeBakeError`."""
    problem = evaluated_problem(obj, depsgraph, UV_MAP_NAME)
    if problem:
        remove_made_uv(obj)
        raise LightFadeBakeError(problem)


def checked_plan(obj, depsgraph, settings):
    """:func:`.sizing.planned_map` of ``obj`` after the checks of the mesh as rendered:
    ``(width, UvPlan)``, or ``(width, problem line)``."""
    problem = evaluated_problem(obj, depsgraph, baked_uv_name(obj))
    if problem:
        return 0, problem
    size, plan = planned_map(obj, depsgraph, settings)
    if not isinstance(plan, str) and plan.make:
        plan = island_problem(obj, size) or plan
    return size, plan


def island_problem(obj, size):
    """Why the islands of ``obj``'s UV map cannot be packed into a ``size``²
    ``LightFadeUV`` map, or '' (also without a UV map: unwrapping makes the islands).

    Each island needs :data:`MIN_ISLAND_TEXELS`; packing fills about
    :data:`.sizing.PACK_FILL` of the square (0.55), so at most ``0.55 size² / 25``
    islands fit: 23 000 in a 1024² map."""
    mesh = obj.data
    layers = mesh.uv_layers
    source = layers.active.name if layers.active else None
    if source is None or len(mesh.polygons) == 0:
        return ""  # Smart UV Project makes the islands: their number is not known yet
    islands = int(polygon_islands(mesh, source).max()) + 1
    room = int(PACK_FILL * size * size / MIN_ISLAND_TEXELS)
    if islands <= room:
        return ""
    need = 8 * -(-int((islands * MIN_ISLAND_TEXELS / PACK_FILL) ** 0.5) // 8)
    return (f"\"{obj.name}\": its {islands} UV islands do not fit a {size}² map (room for "
            f"{room}, each needs {MIN_ISLAND_TEXELS} texels with its gaps): raise Max Size "
            f"(Exposure Bake) to at least {need}, join islands (fewer seams), or split the "
            "object into parts and bake again")

