"""Application handlers: keyframed years, file load and save, and the years slider.

* ``frame_change_post`` (persistent): a property's ``update`` callback does not fire
  when an F-curve or driver changes it, so keyframed years are applied here, from
  the evaluated value, before each frame is drawn or rendered.
* ``load_post`` (persistent): prepared agers belong to the file they came from.
* ``save_pre`` (persistent): the aged and baked-albedo images are packed, so that a
  render node with the extension and the .blend alone renders the same frames.
* the years slider: :func:`years_changed` joins :data:`.properties.YEARS_LISTENERS`.

Handlers are added and removed exactly once each (:func:`register`/:func:`unregister`).
"""

import bpy
from bpy.app.handlers import persistent

from . import runtime
from .albedo import ALBEDO_PREFIX
from .apply import aged_copies, update_scene
from .copies import AGED_PREFIX
from .properties import YEARS_LISTENERS, valid_years

#: Texels above which a slider change waits for the slider to rest (debounce).
DEBOUNCE_TEXELS = 2048 * 2048
DEBOUNCE_SECONDS = 0.15
_pending = set()


def _interactive():
    return not bpy.app.background


def years_changed(scene):
    """The years slider moved: update now, or when it rests if the textures are big."""
    copies = aged_copies(scene)
    if not copies:
        return
    texels = sum(c.lightfade.aged_image.size[0] * c.lightfade.aged_image.size[1]
                 for c in copies if c.lightfade.aged_image is not None)
    if texels <= DEBOUNCE_TEXELS or not _interactive():
        update_scene(scene)
        return
    name = scene.name
    if name not in _pending:
        _pending.add(name)
        bpy.app.timers.register(lambda: _deferred(name), first_interval=DEBOUNCE_SECONDS)


def _deferred(scene_name):
    _pending.discard(scene_name)
    scene = bpy.data.scenes.get(scene_name)
    if scene is not None:
        update_scene(scene)
    return None


@persistent
def on_frame_change(scene, depsgraph=None):
    if valid_years(scene.lightfade.years) and aged_copies(scene):
        update_scene(scene)


@persistent
def on_load(_dummy=None, _more=None):
    runtime.clear()
    _pending.clear()


@persistent
def on_save(_dummy=None, _more=None):
    # Pack only what changed: packing an unchanged, already packed image again
    # drops its data in Blender 5.0 (seen with float images).
    for image in bpy.data.images:
        if (image.name.startswith((AGED_PREFIX, ALBEDO_PREFIX)) and image.has_data
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
    if years_changed not in YEARS_LISTENERS:
        YEARS_LISTENERS.append(years_changed)


def unregister():
    while years_changed in YEARS_LISTENERS:
        YEARS_LISTENERS.remove(years_changed)
    for handler_list, fn in reversed(HANDLERS):
        while fn in handler_list:
            handler_list.remove(fn)
    runtime.clear()
