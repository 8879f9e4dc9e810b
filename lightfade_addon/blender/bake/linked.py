"""Collections linked from another .blend, aged where the artist asks: local copies of
their aging objects in a local collection, their meshes still the library's.

A linked collection's objects belong to the library: an aged material on them (a slot
linked to the object) and LightFade's exposure records cannot be saved there.  Blender
takes such edits of linked data in memory but drops them on reload, and a library
override keeps only what Blender lets it override: a material slot's material and
link and an add-on's properties come back from the library on reload (measured on bpy
4.2 and 5.2).  So the bake skips a linked source in one line
(:func:`.instances.linked_note`), and only when the artist asks (*Age Linked
Instances* in the Exposure Bake panel, ``api.localize_linked``) :func:`localize` makes,
for each linked collection an empty instances, a local collection ``LF <name>`` holding
a local copy of each of its objects whose materials age (sharing the library's mesh: no
mesh is copied) and the library's other objects as they are, and points the empties at
it, each empty remembering the library's collection.  The copies are ordinary local
sources: baked per instance, aged, saved.  Reset with the exposure (:func:`restore`)
points the empties back and removes the local collections and copies.
"""

from __future__ import annotations

import bpy

#: Custom property of an empty: the library's collection it instanced before.
LINKED_KEY = "lightfade_linked_collection"
#: Custom property of a local collection or object: the library's one it stands for.
MIRROR_KEY = "lightfade_local_of"
#: Name prefix of the local collections.
PREFIX = "LF "


def _ages(obj):
    return obj.type == "MESH" and any(
        s.material is not None and s.material.lightfade.enabled for s in obj.material_slots)


def _linked(collection):
    return collection is not None and (collection.library is not None
                                       or collection.override_library is not None)


def is_local_copy(obj):
    """``obj`` is a local copy made by :func:`localize` (aged per instance: its mesh and
    materials, the library's, are only read: the aged copy is a local material)."""
    return obj.library is None and obj.get(MIRROR_KEY) is not None


def linked_instancers(scene):
    """``scene``'s empties instancing a linked collection that holds an aging object."""
    return [o for o in scene.objects
            if o.instance_type == "COLLECTION" and _linked(o.instance_collection)
            and any(_ages(x) for x in o.instance_collection.all_objects)]


def _local(collection, made):
    """The local collection standing for the library's ``collection`` (made once)."""
    if collection in made:
        return made[collection]
    local = bpy.data.collections.new(PREFIX + collection.name)
    local[MIRROR_KEY] = collection
    local.instance_offset = collection.instance_offset
    local.hide_render, local.hide_viewport = collection.hide_render, collection.hide_viewport
    made[collection] = local
    for obj in collection.objects:
        if _ages(obj):
            copy = obj.copy()                    # local; its mesh stays the library's
            copy[MIRROR_KEY] = obj
            local.objects.link(copy)
        else:
            local.objects.link(obj)
    for child in collection.children:
        holds = any(_ages(o) for o in child.all_objects)
        local.children.link(_local(child, made) if holds else child)
    return local


def localize(scene):
    """Point each empty of ``scene`` instancing a linked collection at a local one of local
    copies of its aging objects; returns one line per collection (what was made)."""
    made, lines = {}, []
    by_collection = {}
    for empty in linked_instancers(scene):
        by_collection.setdefault(empty.instance_collection, []).append(empty)
    for collection, empties in by_collection.items():
        local = _local(collection, made)
        for empty in empties:
            empty[LINKED_KEY] = collection
            empty.instance_collection = local
        copies = [o.name for o in local.all_objects if o.get(MIRROR_KEY) is not None]
        lib = collection.library or collection.override_library.reference.library
        lines.append(f"\"{collection.name}\" (linked from \"{lib.filepath if lib else ''}\"): "
                     f"{len(empties)} instances now show \"{local.name}\", with local copies of "
                     f"{', '.join(copies)} (the meshes still the library's); bake to age them, "
                     "Reset with the exposure to put the library's collection back")
    return lines


def restore(scene=None):
    """Reset: the empties (of ``scene``, or all) instance the library's collection again;
    the local collections and copies nothing instances any more are removed."""
    objects = scene.objects if scene is not None else bpy.data.objects
    for empty in [o for o in objects if o.get(LINKED_KEY) is not None]:
        empty.instance_collection = empty[LINKED_KEY]
        del empty[LINKED_KEY]
    used = {o.instance_collection for o in bpy.data.objects if o.instance_collection}
    used |= {c for s in bpy.data.scenes for c in s.collection.children_recursive}
    locals_ = [c for c in bpy.data.collections if c.get(MIRROR_KEY) is not None]
    used |= {child for c in bpy.data.collections if c not in locals_ for child in c.children}
    for collection in locals_:
        if collection in used:
            continue
        copies = [o for o in collection.objects if o.get(MIRROR_KEY) is not None]
        bpy.data.collections.remove(collection)
        for copy in copies:
            if not copy.users_collection:
                bpy.data.objects.remove(copy)
