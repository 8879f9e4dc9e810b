"""Names, units and the error type shared by the exposure-bake modules.

Calibration (Cycles CPU, pinned by ``tests/blender/test_bake.py``)
-----------------------------------------------------------------
Cycles' DIFFUSE bake without colour of a white Lambertian surface returns ``B = E / pi``,
where ``E`` is the irradiance in Blender's nominal radiometric units (W/m²); the baked
texels are shown to Cycles as exactly that surface, whatever their material
(:mod:`.surface`).  The maps store::

    lux = 683 lm/W * pi * Y(B)          (LUX_PER_BAKE_UNIT = 683 pi = 2145.7)

with ``Y`` the luminance of the baked RGB irradiance (Rec. 709 weights, Blender's default
scene-linear space).  For white light ``Y(B) = B``:

============================  ==============================  =======================
emitter                        measured B                     illuminance (lux)
============================  ==============================  =======================
sun, strength S, angle θ       S cosθ / pi  (0.31830 for S=1)  683 S cosθ
point, power P, distance r     P / (4 pi² r²) (±0.02 %)        683 P / (4 pi r²)
spot, power P (on axis)        P / (4 pi² r²)  as a point      683 P / (4 pi r²)
area, power P (small, axis)    P / (pi² r²)                    683 P / (pi r²)
world, background strength W   W (open hemisphere)             683 pi W
annual sky, radiance L lx·h/sr  L / (683 × 8760) (a pixel)      pi L / 8760 (mean lux)
emission strength L (plane)    L (infinite emitting plane)     683 pi L
============================  ==============================  =======================
"""

from __future__ import annotations

import math

import numpy as np

#: Luminous efficacy assumed for Blender's nominal radiometric watts (lm/W).
LUX_PER_WATT = 683.0
#: Lux per unit of Cycles' DIFFUSE (no colour) bake value: ``683 * pi``.
LUX_PER_BAKE_UNIT = LUX_PER_WATT * math.pi
#: Rec. 709 / sRGB luminance weights of linear R, G, B (CIE Y of Blender's default
#: scene-linear space).
LUMINANCE_WEIGHTS = np.array([0.2126, 0.7152, 0.0722])

WORLD_EMITTER = "World"
#: The daylight group's one emitter when the scene has a place (:mod:`.daylight`).
DAYLIGHT_EMITTER = "Daylight"
TEMP_PREFIX = "LF_TMP_"
EXPOSURE_PREFIX = "LF_Exposure_"
#: Name of the UV map LightFade makes when a mesh's own UVs overlap or leave 0-1.
UV_MAP_NAME = "LightFadeUV"


class LightFadeBakeError(RuntimeError):
    """A bake that cannot start; the message names the object and what to fix.

    Several problems are reported at once, one per line.
    """


class BakeCancelled(LightFadeBakeError):
    """The user cancelled the bake (Esc); settings were restored, no map was stored."""


def exposure_image_name(obj_name, group_name):
    """Name of the image holding ``obj_name``'s exposure to light group ``group_name``."""
    return f"{EXPOSURE_PREFIX}{obj_name}_{group_name}"


def luminance(rgb):
    """Luminance ``Y`` of linear Rec. 709 RGB, shape ``(..., 3) -> (...)``."""
    return np.asarray(rgb)[..., :3] @ LUMINANCE_WEIGHTS
