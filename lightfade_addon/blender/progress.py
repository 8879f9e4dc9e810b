"""The Blender adapter of the progress protocol (see :mod:`lightfade_addon.progress`)."""

import contextlib

import bpy

from ..progress import ProgressBar

#: Steps of Blender's progress indicator for a whole job.
_STEPS = 1000


class WindowProgress:
    """A ``progress(fraction, message)`` callable on Blender's window.

    In the UI it drives ``WindowManager.progress_begin/update/end`` and shows the message
    in the status bar (followed by ``hint``, e.g. "Esc to cancel"); with ``blender -b`` or the ``bpy`` module it prints one line per
    message (a :class:`..progress.ProgressBar`). Call :meth:`end` when the job is over,
    also on error or cancel (a modal operator does it in its finish and cancel paths;
    :func:`window_progress` does it for a job that runs in one call).
    """

    def __init__(self, context, label="LightFade", hint=""):
        self.label = label
        self.hint = f" ({hint})" if hint else ""
        self._ui = context.window is not None and not bpy.app.background
        self._wm = context.window_manager
        self._workspace = getattr(context, "workspace", None) if self._ui else None
        self._bar = None if self._ui else ProgressBar(f"{label}:", tty=False)
        self.prints = self._bar is not None          # lines of its own (background)
        if self._ui:
            self._wm.progress_begin(0, _STEPS)

    def __call__(self, fraction, message=""):
        if self._bar is not None:
            self._bar(fraction, message)
            return
        self._wm.progress_update(int(_STEPS * min(max(fraction, 0.0), 1.0)))
        if self._workspace is not None and message:
            self._workspace.status_text_set(f"{self.label}: {message}{self.hint}")

    def end(self):
        """Hide the indicator and clear the status bar (UI); end the lines (background)."""
        if self._bar is not None:
            self._bar.close()
            return
        self._wm.progress_end()
        if self._workspace is not None:
            self._workspace.status_text_set(None)


@contextlib.contextmanager
def window_progress(context, label="LightFade"):
    """Yield a :class:`WindowProgress` for the duration of a long job; ended also on error."""
    progress = WindowProgress(context, label)
    try:
        yield progress
    finally:
        progress.end()
