"""LightFade's Blender shell: properties, operators, panels (and, later, handlers).

:func:`register` registers :data:`classes` in order and then attaches the property
groups; :func:`unregister` undoes both in reverse.  Neither touches scene data.
"""

import bpy

from . import panels, properties
from .operators import CLASSES as _OPERATOR_CLASSES

classes = (
    *properties.CLASSES,
    *_OPERATOR_CLASSES,
    *panels.CLASSES,
)


def register():
    """Register the classes in order, then attach ``Scene.lightfade`` & co."""
    for cls in classes:
        bpy.utils.register_class(cls)
    properties.register_pointers()


def unregister():
    """Exactly undo :func:`register`, in reverse order."""
    properties.unregister_pointers()
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
