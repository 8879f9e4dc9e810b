"""Reset: the file as it was before Age (and, optionally, before Bake Exposure).

Slots and links come back exactly (:func:`.copies.remove_copy`), LightFade's images
(aging data, baked albedo, applied pixels), its aging node groups and copied node
groups are removed, only grids still named by an aged copy stay in
the file, and Render > Lock Interface is put back as the user had it.
"""

from __future__ import annotations

import bpy

from .aging import data as agingdata, frames, parts, runtime
from .albedo import ALBEDO_PREFIX
from .aging.copies import copies_of, remove_copy
from .daylight.view import clear_view
from .exposure import remove_exposure, remove_instance_data, scene_objects
from .aging.grids import purge
from .bake import linked


def remove_aged(copy):
    """Remove one aged copy: slots restored, its images (if nothing else uses them) gone."""
    runtime.forget(copy)
    frames.remove_frame_images(copy)
    parts.remove(copy)
    props = copy.lightfade
    props.table_image = None
    images = [props.aged_image]
    if props.albedo is not None and props.albedo.name.startswith(ALBEDO_PREFIX):
        images.append(props.albedo)
    props.aged_image = None
    props.albedo = None
    remove_copy(copy)
    for image in images:    # private to the copy (Blender 4.2 may still count a user)
        if image is not None:
            bpy.data.images.remove(image)


def reset_scene(scene, exposure=False):
    """Undo Age for every aged copy of ``scene``'s objects; returns how many.

    With ``exposure=True`` the exposure maps (and the UV maps the bake made) go too.
    """
    objects = scene_objects(scene)
    copies = [c for c in copies_of() if c.lightfade.aged_object in objects
              or c.lightfade.aged_object is None]
    for copy in copies:
        remove_aged(copy)
    clear_view(scene)                            # dose views show what Reset removes
    if exposure:
        meshes = [o for o in objects if o.type == "MESH"]
        remove_instance_data(meshes)             # each instancer's tile property too
        remove_exposure(scene, meshes)
        linked.restore(scene)                    # the library's collections back
    agingdata.purge_tables()
    purge(scene, set())
    props = scene.lightfade
    if props.lock_interface_before >= 0:
        scene.render.use_lock_interface = bool(props.lock_interface_before)
        props.lock_interface_before = -1
    return len(copies)
