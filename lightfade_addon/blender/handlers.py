"""Application handlers: file load and save.

* ``load_post`` (persistent): cached evaluators belong to the file they came from.
* ``save_pre`` (persistent): LightFade's images (aging data, baked albedo, applied
  pixels) are packed, so that the .blend alone renders the same frames anywhere,
  with or without the extension; keys on the years are made linear.
* ``render_pre`` … ``save_post`` (persistent): aged copies render their frame images
  where LightFade is installed (:mod:`.aging.frames`).
* ``depsgraph_update_post`` (persistent): after a change to an action (a key inserted
  with *I*), the years' Bezier keys become linear (:func:`.years.linear_keys`); any
  other update returns at once.

The years themselves need no handler: keyframes and the slider change the scene's
custom property that the aged materials read themselves (:mod:`.aging.years`).

Handlers are added and removed exactly once each (:func:`register`/:func:`unregister`).
"""

import bpy
from bpy.app.handlers import persistent

from .aging import frames, runtime
from .aging.data import PREFIXES
from .albedo import ALBEDO_PREFIX
from .aging.apply import APPLIED_PREFIX
from .aging.parts import WEIGHTS_PREFIX
from .aging.years import linear_keys


@persistent
def on_load(_dummy=None, _more=None):
    runtime.clear()
    frames.forget()


@persistent
def on_save(_dummy=None, _more=None):
    # Pack only what changed: packing an unchanged, already packed image again
    # drops its data in Blender 5.0 (seen with float images).
    for image in bpy.data.images:
        if (image.name.startswith((*PREFIXES, ALBEDO_PREFIX, APPLIED_PREFIX, WEIGHTS_PREFIX))
                and image.has_data
                and (image.packed_file is None or image.is_dirty)):
            image.pack()
    for scene in bpy.data.scenes:
        linear_keys(scene)


@persistent
def on_depsgraph(scene, depsgraph=None):
    if depsgraph is not None and depsgraph.id_type_updated("ACTION"):
        linear_keys(scene)


HANDLERS = (
    (bpy.app.handlers.load_post, on_load),
    (bpy.app.handlers.save_pre, on_save),
    (bpy.app.handlers.depsgraph_update_post, on_depsgraph),
    *((getattr(bpy.app.handlers, name), fn) for name, fn in frames.HANDLERS),
)


def register():
    for handler_list, fn in HANDLERS:
        if fn not in handler_list:
            handler_list.append(fn)


def unregister():
    for handler_list, fn in reversed(HANDLERS):
        while fn in handler_list:
            handler_list.remove(fn)
    frames.on_render_end()          # the aging groups and switches as a saved file has them
    runtime.clear()
    frames.forget()
