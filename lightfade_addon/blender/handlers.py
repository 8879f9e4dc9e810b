"""Application handlers: keyframed years, file load and save, and the years slider.

* ``frame_change_post`` (persistent): a property's ``update`` callback does not fire
  when an F-curve or driver changes it, so keyframed years are applied here, from
  the evaluated value, before each frame is drawn or rendered.
* ``load_post`` (persistent): prepared agers belong to the file they came from.
* ``save_pre`` (persistent): the aged images are packed, so that a render node with
  the extension and the .blend alone renders the same frames.

Handlers are added and removed exactly once each (:func:`register`/:func:`unregister`).
"""

import bpy
from bpy.app.handlers import persistent

from . import aging

#: Texels above which a slider change waits for the slider to rest (debounce).
DEBOUNCE_TEXELS = 2048 * 2048
DEBOUNCE_SECONDS = 0.15
_pending = set()


def years_changed(scene):
    """Called by the ``years`` property's update callback (the slider)."""
    materials = aging.aged_materials(scene)
    if not materials:
        return
    big = sum(m.lightfade.aged_image.size[0] * m.lightfade.aged_image.size[1]
              for m in materials if m.lightfade.aged_image is not None) > DEBOUNCE_TEXELS
    if not big or bpy.app.background:
        _update(scene)
        return
    name = scene.name
    if name not in _pending:
        _pending.add(name)
        bpy.app.timers.register(lambda: _deferred(name), first_interval=DEBOUNCE_SECONDS)


def _deferred(scene_name):
    _pending.discard(scene_name)
    scene = bpy.data.scenes.get(scene_name)
    if scene is not None:
        _update(scene)
    return None


def _update(scene):
    try:
        aging.update_scene(scene)
    except aging.AgingError as err:
        print(f"LightFade: {err}")


@persistent
def on_frame_change(scene, depsgraph=None):
    if aging.aged_materials(scene):
        _update(scene)


@persistent
def on_load(_dummy=None, _more=None):
    aging.clear_runtime()
    _pending.clear()


@persistent
def on_save(_dummy=None, _more=None):
    # Pack only what changed: packing an unchanged, already packed image again
    # drops its data in Blender 5.0 (seen with float images).
    for image in bpy.data.images:
        if (image.name.startswith(aging.AGED_PREFIX) and image.has_data
                and (image.packed_file is None or image.is_dirty)):
            image.pack()


HANDLERS = (
    (bpy.app.handlers.frame_change_post, on_frame_change),
    (bpy.app.handlers.load_post, on_load),
    (bpy.app.handlers.save_pre, on_save),
)


def register():
    for handler_list, fn in HANDLERS:
        if fn not in handler_list:
            handler_list.append(fn)


def unregister():
    for handler_list, fn in reversed(HANDLERS):
        while fn in handler_list:
            handler_list.remove(fn)
    aging.clear_runtime()
