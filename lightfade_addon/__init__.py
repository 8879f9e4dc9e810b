"""LightFade: light fading and yellowing of scene materials.

The package imports without Blender: the physics lives in :mod:`lightfade_addon.core`
(numpy and colour-science only) and the Blender shell in :mod:`lightfade_addon.blender`,
which is imported only inside :func:`register`.
"""

import os as _os

__version__ = "0.1.0"

#: When this file was loaded, as Blender's ``addon_utils`` records it on the modules it
#: imports: it takes a module already imported without it (``python -m lightfade_addon``,
#: a script or a test that imported the package first) for one changed on disk, prints
#: "module changed on disk: '.../__init__.py' reloading..." and reloads it.  A file that
#: did change since still is reloaded.
__time__ = _os.path.getmtime(__file__)


def register():
    """Register the Blender classes, properties and handlers (called by Blender)."""
    from . import blender

    blender.register()


def unregister():
    """Undo :func:`register` exactly, in reverse order."""
    from . import blender

    blender.unregister()
