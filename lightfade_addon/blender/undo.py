"""Changes to the file that must be put back: an undo stack run on leaving a scope.

The exposure bake (:class:`.bake.state.BakeState`) and the albedo bake
(:func:`.albedo.bake_albedos`) change render settings, node trees, slots and selection
for their Cycles calls; each change is recorded here as it is made and undone in reverse
on exit, whether the scope ends normally, with an error or cancelled.
"""

from __future__ import annotations

import contextlib


class Undo(contextlib.AbstractContextManager):
    """Undo steps run in reverse on exit (normal or error); every step is attempted."""

    def __init__(self):
        self._undo = []

    def push(self, fn):
        """Run ``fn()`` on exit (in reverse order of pushing)."""
        self._undo.append(fn)

    def set(self, struct, name, value):
        """``setattr(struct, name, value)``, remembering the old value."""
        old = getattr(struct, name)
        if old != value:
            setattr(struct, name, value)
            self.push(lambda: setattr(struct, name, old))

    def unwind(self):
        """Run every step, newest first; the errors they raised (the rest still ran)."""
        errors = []
        for fn in reversed(self._undo):
            try:
                fn()
            except Exception as err:  # noqa: BLE001 (keep restoring the rest)
                errors.append(err)
        self._undo.clear()
        return errors

    def __exit__(self, exc_type, exc, tb):
        errors = self.unwind()
        if errors and exc_type is None:
            raise errors[0]
        return False
