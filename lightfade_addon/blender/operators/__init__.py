"""LightFade operators, one per module.  ``CLASSES`` is registered in order."""

from .bake_exposure import LIGHTFADE_OT_bake_exposure

CLASSES = (
    LIGHTFADE_OT_bake_exposure,
)
