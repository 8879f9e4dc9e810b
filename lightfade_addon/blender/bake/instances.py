"""Instances baked where each one stands: one atlas of tiles per instanced source mesh.

A collection instance (an empty instancing a collection) and a geometry-nodes instance
render their source object's mesh and materials at another place.  The bake finds every
placement of a source whose materials age (``depsgraph.object_instances``), puts a
temporary object sharing the source's mesh at each placement's world matrix, bakes them
all in the one Cycles call of each light group (the source itself made invisible to
every ray meanwhile, so that neither it nor its instances shadow their stand-ins), and
packs the maps into one **atlas** per source and light group: tile ``k`` of a
``G × G`` grid (``G = ceil(√n)``) holds placement ``k``, each tile as wide as the
largest placement needs on the scene's texel density.

Each placement's tile is written where the material can read it per instance, as a
rectangle ``(u0, v0, s)`` (the tile's corner and width in the atlas's 0-1 square):

* a collection instance: a custom property on the instancing empty, named
  :func:`tile_attribute` of the source;
* the source standing in the scene itself: the same property on the source;
* a geometry-nodes instance: an instance attribute of the same name, stored by a
  LightFade modifier added after the artist's (:mod:`..aging.instances`).

The aging group reads it with an Attribute node of type *Instancer* (Cycles and EEVEE:
an instance reads its instancer's property or its instance attribute, an object that is
not an instance its own property) and samples the atlas at ``uv · s + (u0, v0)``.
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import dataclass

import bpy
import numpy as np

from . import instance_tiles
from .maps import prune_maps, store_map
from .sizing import planned_map

#: Prefix of the per-source attribute (a custom property, or an instance attribute)
#: holding a placement's tile ``(u0, v0, s)``.
TILE_PREFIX = "lf_tile_"

#: A persistent id's unused levels.
_UNUSED = 2 ** 31 - 1


def tile_attribute(source):
    """The attribute name holding ``source``'s tiles (stable: the source's name and library)."""
    lib = source.library.filepath if source.library is not None else ""
    return TILE_PREFIX + hashlib.sha1(f"{lib}|{source.name}".encode()).hexdigest()[:8]


@dataclass
class Placement:
    """One place a source is rendered: itself (``instancer`` None) or an instance."""

    instancer: object          # bpy.types.Object or None
    kind: str                  # "OWN", "COLLECTION", "GEOMETRY"
    pid: tuple                 # persistent id within the instancer
    matrix: object             # mathutils.Matrix, world

    @property
    def index(self):
        """A geometry-nodes instance's index in its instancer's top-level instances: the
        last level of Blender's persistent id (innermost level first, unused ones at
        the int32 maximum): ``(0, i)`` for an object, ``(k, 0, i)`` for object ``k`` of
        an instanced collection."""
        return [v for v in self.pid if v != _UNUSED][-1]

    @property
    def key(self):
        """Identity of the placement: instancer name, kind and persistent id; for a
        geometry-nodes instance the levels inside its top-level instance and its world
        location (to 0.1 mm) instead of its index, which shifts when instances are added
        before it (its tile is found by its position, :mod:`.instance_tiles`)."""
        name = self.instancer.name if self.instancer else ""
        if self.kind == "GEOMETRY":
            used = [v for v in self.pid if v != _UNUSED]
            where = ",".join(f"{v:.4f}" for v in self.matrix.translation)
            return f"{name}|GEOMETRY|{','.join(str(i) for i in used[:-1])}@{where}"
        return f"{name}|{self.kind}|{','.join(str(i) for i in self.pid)}"


@dataclass
class SourcePlan:
    """The placements of one source mesh, their tiles and tile width."""

    source: object
    placements: list
    tile: int = 16
    uv: object = None          # the UvPlan of the source (once planned)
    stand_in: object = None    # the temporary object baked in their place
    changes: str = ""          # how its placements change between frames (one line)

    @property
    def grid(self):
        return max(1, math.ceil(math.sqrt(len(self.placements))))

    @property
    def size(self):
        """Atlas width: ``grid × tile`` texels."""
        return self.grid * self.tile

    def regions(self):
        """``{placement key: (rows, columns)}``: each placement's tile of the atlas, as
        slices (rows from v = 0, as the image's pixels)."""
        out = {}
        for k, placement in enumerate(self.placements):
            u0, v0, s = self.rect(k)
            x, y, n = (round(u0 * self.size), round(v0 * self.size), round(s * self.size))
            out[placement.key] = (slice(y, y + n), slice(x, x + n))
        return out

    def rect(self, k):
        """Tile ``k``'s ``(u0, v0, s)`` in the atlas's 0-1 square (row 0 at v = 0)."""
        g = self.grid
        return ((k % g) / g, (k // g) / g, 1.0 / g)


def _ages(obj):
    return obj.type == "MESH" and any(
        s.material is not None and s.material.lightfade.enabled for s in obj.material_slots)


def _own_rendered(obj, view_layer):
    """``obj`` itself renders in ``view_layer`` (not only through instances)."""
    return (view_layer.objects.get(obj.name) is obj and not obj.hide_render
            and obj.visible_get(view_layer=view_layer))


def find_placements(depsgraph, view_layer, chosen=(), warn=None):
    """``{source: [Placement]}`` of every instanced mesh whose materials age, with its own
    placement first when it renders itself; ``chosen`` (objects) limits the search to
    the sources chosen or instanced by a chosen instancer (all their placements: an
    atlas holds every placement of its source).  A source linked from a library is left out, said in
    one line to ``warn``."""
    found = {}
    chosen = set(chosen)
    for inst in depsgraph.object_instances:
        if not inst.is_instance or inst.object is None:
            continue
        source = inst.object.original
        parent = inst.parent.original if inst.parent is not None else None
        if parent is None or not _ages(source):
            continue
        kind = "COLLECTION" if (parent.instance_type == "COLLECTION"
                                and parent.instance_collection is not None) else "GEOMETRY"
        found.setdefault(source, []).append(
            Placement(parent, kind, tuple(inst.persistent_id), inst.matrix_world.copy()))
    plans = {}
    for source, placements in found.items():
        if chosen and source not in chosen and not chosen & {p.instancer for p in placements}:
            continue
        if source.library is not None or source.override_library is not None:
            if warn is not None:
                warn(linked_note(source, placements))
            continue
        placements.sort(key=lambda p: p.key)
        if _own_rendered(source, view_layer):
            placements.insert(0, Placement(None, "OWN", (), source.matrix_world.copy()))
        plans[source] = SourcePlan(source, placements)
    return plans


def linked_note(source, placements):
    """One line for a source linked from a library: its instances are not aged (what to
    do: Age Linked Instances for collection instances, :mod:`.linked`)."""
    lib = source.library or source.override_library.reference.library
    head = (f"Skipped \"{source.name}\" ({len(placements)} instances): it is linked from "
            f"\"{lib.filepath if lib else 'a library'}\", whose objects cannot keep an aged "
            "material; ")
    if any(p.kind == "COLLECTION" for p in placements):
        return head + ("press Age Linked Instances (Exposure Bake panel) to age its collection "
                       "instances through local copies of its aging objects (the meshes stay "
                       "the library's; Reset puts the library's collection back)")
    return head + ("geometry nodes instance it: make its collection local (Object > "
                   "Relations > Make Local) to age them")


def planned(depsgraph, view_layer, settings, chosen=()):
    """``{source: SourcePlan}`` sized as the bake will size them, for the panel's list
    and estimate (no diagnosis, nothing changed; sources that would refuse left out)."""
    plans = find_placements(depsgraph, view_layer, chosen)
    kept = list(plans.values())
    plan_tiles(kept, depsgraph, settings, lambda note: None, diagnose=False)
    return {p.source: p for p in kept if p.uv is not None}


def _scale(matrix):
    """Linear scale of a world matrix: ``|det|^(1/3)``."""
    return abs(matrix.to_3x3().determinant()) ** (1.0 / 3.0)


def tile_width(source_size, source_matrix, placements, max_size):
    """The tile width (texels, a multiple of 8, at least 16): the source's map width at its
    own scale times the largest placement's scale over it."""
    own = max(_scale(source_matrix), 1e-9)
    n = max(source_size * _scale(p.matrix) / own for p in placements)
    return int(min(max(16, math.ceil(n / 8.0) * 8), max(16, int(max_size) // 8 * 8)))


def shared_note(plan):
    """Geometry-nodes placements of one source under one top-level instance (a collection
    instanced by geometry nodes that holds the source twice), or at one place, share that
    instance's attribute: the first is baked, the others read its tile.  Drops them; one
    line."""
    seen, kept, dropped = set(), [], 0
    for p in plan.placements:
        keys = {(p.instancer, p.index), p.key} if p.kind == "GEOMETRY" else {id(p)}
        if keys & seen:
            dropped += 1
            continue
        seen |= keys
        kept.append(p)
    plan.placements = kept
    if not dropped:
        return ""
    return (f"\"{plan.source.name}\" appears {dropped + 1}+ times inside one geometry-nodes "
            "instance or at one place: its copies there share one tile (the first one's light)")


def plan_tiles(plans, depsgraph, settings, note, diagnose=True):
    """Size each source's tiles and check its UV map; returns problem lines.
    ``diagnose``: as :func:`.sizing.planned_map` (False in a panel's draw)."""
    problems = []
    for plan in plans:
        note(shared_note(plan))
        size, uv = planned_map(plan.source, depsgraph, settings, diagnose)
        if isinstance(uv, str):
            problems.append(uv)
            continue
        if uv.make:
            problems.append(f"\"{plan.source.name}\" is instanced and its UVs overlap or are "
                            "missing: give its mesh a UV map without overlaps (U > Smart UV "
                            "Project) and bake again")
            continue
        plan.uv = uv
        plan.tile = tile_width(size, plan.source.matrix_world, plan.placements,
                               settings.max_size)
    return problems


def bakeable(targets, view_layer, warn):
    """The targets Cycles can bake where they stand; each other one (its collection
    excluded, or disabled in viewports, and nothing instancing it) is skipped with one
    line to ``warn``."""
    out = []
    for obj in targets:
        if view_layer.objects.get(obj.name) is obj and not obj.hide_viewport:
            out.append(obj)
        else:
            warn(f"Skipped \"{obj.name}\": hidden from the bake (its collection is excluded "
                 "or it is disabled in viewports) and nothing instances it; show it to bake it")
    return out


# ----------------------------------------------------------------------- baking


def store_atlas(state, plan, baked):
    """The stand-in's maps (``{group name: (group, image)}``: each light group's atlas)
    stored as the source's; the tiles written where each instance reads them."""
    for group, image in baked.values():
        state.keep(image)
        store_map(plan.source, group, image, plan.uv.uv_name)
    prune_maps(plan.source, set(baked))
    write_tiles(plan)


# ----------------------------------------------------------------------- records


def record(plan):
    """JSON of the placements baked (key and rounded world matrix), for staleness."""
    return json.dumps([[p.key, [round(v, 4) for row in p.matrix for v in row]]
                       for p in plan.placements])


def write_tiles(plan):
    """Store each placement's tile where the material reads it; forget older tiles."""
    name = tile_attribute(plan.source)
    clear_tiles(name)
    scattered = {}                                # geometry-nodes instancer -> {id: k}
    for k, placement in enumerate(plan.placements):
        holder = placement.instancer if placement.instancer is not None else plan.source
        if placement.kind in ("OWN", "COLLECTION"):
            holder[name] = list(plan.rect(k))
        else:
            scattered.setdefault(holder, {})[placement.index] = k
    for instancer, tiles in scattered.items():
        matrices = {i: plan.placements[k].matrix for i, k in tiles.items()}
        found = sorted(instance_tiles.positions(instancer, tiles, matrices).items(),
                       key=lambda t: t[1][0])
        instance_tiles.write(instancer, name, [pos for _i, (_row, pos) in found],
                             [plan.rect(tiles[i]) for i, _ in found])
    props = plan.source.lightfade
    props.instance_tiles = name
    props.instance_record = record(plan)
    props.instance_changes = plan.changes


def clear_tiles(name):
    """Remove the tile property ``name`` from every object of the file, and the
    geometry-nodes instances' tile data (:mod:`.instance_tiles`)."""
    instance_tiles.remove({name})
    for obj in bpy.data.objects:
        if obj.library is None and name in obj.keys():
            del obj[name]


def remove_instance_data(objects):
    """Reset: the tile properties of ``objects`` (sources) and their records gone."""
    for obj in objects:
        props = obj.lightfade
        if props.instance_tiles:
            clear_tiles(props.instance_tiles)
            props.instance_tiles = ""
            props.instance_record = ""
            props.instance_changes = ""


def instance_sources(scene=None):
    """Sources aged per instance (objects with an atlas), in the file."""
    return [o for o in bpy.data.objects if o.type == "MESH" and o.lightfade.instance_tiles]


def baked_placements(source):
    """``{key: rounded world matrix}`` of the placements baked into ``source``'s atlas."""
    try:
        return dict((k, m) for k, m in json.loads(source.lightfade.instance_record or "[]"))
    except ValueError:
        return {}


def atlas_grid(source):
    """``(placements, G)`` of ``source``'s atlas (``(0, 1)``: not aged per instance)."""
    n = len(baked_placements(source)) if source.lightfade.instance_tiles else 0
    return n, max(1, math.ceil(math.sqrt(n)))


def tiled(source, tile_array, size, fill):
    """``(size, size, ...)``: ``tile_array(width)`` (an array over the source's own UV
    square at a tile's width) in each placement's tile of ``source``'s atlas, ``fill``
    elsewhere; without instances, ``tile_array(size)``.  What the atlas's texels hold
    of anything laid out in the source's UVs (its texture, its material slots)."""
    n, g = atlas_grid(source)
    if n == 0:
        return tile_array(size)
    width = size // g
    one = tile_array(width)
    out = np.full((size, size, *one.shape[2:]), fill, dtype=one.dtype)
    for k in range(n):
        row, col = divmod(k, g)
        out[row * width:(row + 1) * width, col * width:(col + 1) * width] = one
    return out


def stale_placements(depsgraph, view_layer, source):
    """Keys of ``source``'s placements that moved, appeared or went since its bake."""
    baked = baked_placements(source)
    plan = find_placements(depsgraph, view_layer, ()).get(source)
    now = {} if plan is None else {p.key: [round(v, 4) for row in p.matrix for v in row]
                                   for p in plan.placements}
    stale = [k for k in now if k not in baked or not np.allclose(baked[k], now[k], atol=1e-3)]
    return stale + [k for k in baked if k not in now]
