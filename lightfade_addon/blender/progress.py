"""The Blender adapter of the progress protocol (see :mod:`lightfade_addon.progress`)."""

import contextlib

import bpy

from ..progress import ProgressBar

#: Steps of Blender's progress indicator for a whole job.
_STEPS = 1000


@contextlib.contextmanager
def window_progress(context, label="LightFade"):
    """Yield a ``progress(fraction, message)`` callable for the duration of a long job.

    In the UI it drives ``WindowManager.progress_begin/update/end`` (ended also on
    error); with ``blender -b`` or the ``bpy`` module it prints one line per message.
    """
    if context.window is None or bpy.app.background:
        with ProgressBar(f"{label}:", stream=None, tty=False) as bar:
            yield bar
        return
    wm = context.window_manager
    wm.progress_begin(0, _STEPS)
    try:
        yield lambda fraction, message="": wm.progress_update(
            int(_STEPS * min(max(fraction, 0.0), 1.0)))
    finally:
        wm.progress_end()
