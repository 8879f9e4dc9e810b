"""LightFade's Blender shell: properties, operators, panels and handlers.

:func:`register` registers :data:`classes` in order and then attaches the property
groups and handlers; :func:`unregister` undoes them in reverse.  Neither touches scene data.
"""

import bpy

from . import cache, cli_command, handlers, panels, properties
from .aging import panel as aging_panel
from .aging import properties as aging_properties
from .bake import records as bake_records
from .daylight import operators as daylight_operators
from .daylight import panel as daylight_panel
from .daylight import settings as daylight_settings
from .operators import CLASSES as _OPERATOR_CLASSES
from .parts import operators as parts_operators
from .parts import panel as parts_panel
from .parts import properties as parts_properties

classes = (
    *parts_properties.CLASSES,
    *aging_properties.CLASSES,
    *properties.CLASSES,
    *bake_records.CLASSES,
    *daylight_settings.CLASSES,
    *_OPERATOR_CLASSES,
    *parts_operators.CLASSES,
    *daylight_operators.CLASSES,
    *aging_panel.CLASSES,
    *panels.CLASSES,
    *parts_panel.CLASSES,
    *daylight_panel.CLASSES,
)

#: Every ``(ID type, attribute, property group)`` LightFade attaches, in order.
pointers = (*properties.POINTERS, *aging_properties.POINTERS, *bake_records.POINTERS,
            *daylight_settings.POINTERS)


def register():
    """Register the classes in order, then attach ``Scene.lightfade`` & co."""
    for cls in classes:
        bpy.utils.register_class(cls)
    properties.register_pointers(pointers)
    handlers.register()
    cache.register()
    cli_command.register()


def unregister():
    """Exactly undo :func:`register`, in reverse order."""
    cli_command.unregister()
    cache.unregister()
    handlers.unregister()
    properties.unregister_pointers(pointers)
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
