"""LightFade: light fading and yellowing of scene materials.

The package imports without Blender: the physics lives in :mod:`lightfade_addon.core`
(numpy and colour-science only) and the Blender shell in :mod:`lightfade_addon.blender`,
which is imported only inside :func:`register`.
"""

__version__ = "0.1.0"


def register():
    """Register the Blender classes, properties and handlers (called by Blender)."""
    from . import blender

    blender.register()


def unregister():
    """Undo :func:`register` exactly, in reverse order."""
    from . import blender

    blender.unregister()
