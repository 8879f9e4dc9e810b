"""LightFade operators, one per module.  ``CLASSES`` is registered in order."""

from .age import LIGHTFADE_OT_age
from .apply_aging import LIGHTFADE_OT_apply_aging, LIGHTFADE_OT_live_aging
from .bake_exposure import LIGHTFADE_OT_bake_calibrate, LIGHTFADE_OT_bake_exposure
from .key_years import LIGHTFADE_OT_key_years
from .linked import LIGHTFADE_OT_localize_linked
from .reset import LIGHTFADE_OT_reset

CLASSES = (
    LIGHTFADE_OT_bake_exposure,
    LIGHTFADE_OT_bake_calibrate,
    LIGHTFADE_OT_localize_linked,
    LIGHTFADE_OT_age,
    LIGHTFADE_OT_apply_aging,
    LIGHTFADE_OT_live_aging,
    LIGHTFADE_OT_reset,
    LIGHTFADE_OT_key_years,
)
