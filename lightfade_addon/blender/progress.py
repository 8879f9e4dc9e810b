"""Progress for long operators: the window's progress indicator, or lines in background mode."""

import contextlib

import bpy


@contextlib.contextmanager
def window_progress(context, label="LightFade"):
    """Yield ``progress(fraction, message)`` for the duration of a long job.

    In the UI it drives ``WindowManager.progress_begin/update/end`` (ended also on
    error); with ``blender -b`` or the ``bpy`` module it prints one line per message.
    """
    wm = context.window_manager
    ui = context.window is not None and not bpy.app.background
    last = [None]

    def progress(fraction, message=""):
        if ui:
            wm.progress_update(int(1000 * min(max(fraction, 0.0), 1.0)))
        elif message and message != last[0]:
            print(f"{label}: {100 * fraction:5.1f}% {message}", flush=True)
            last[0] = message

    if ui:
        wm.progress_begin(0, 1000)
    try:
        yield progress
    finally:
        if ui:
            wm.progress_end()
