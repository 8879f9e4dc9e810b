"""The exposure bake: per-texel illuminance (lux) from each light group, with Cycles.

Modules, one job each:

``common``   units (the lux calibration), names, the error type
``records``  what is stored in the .blend (exposure-map records, bake settings)
``presets``  quality presets with their measured time and noise
``state``    the context manager that restores every setting a bake changes
``emitters`` finding emitters, grouping them by spectrum and schedule, isolating a group
``raster``   UV triangles on the texel grid (numpy): overlap counts, island labels
``uvmaps``   the UV map each object is baked on: overlap checks, LightFadeUV
``uvpack``   islands folded onto themselves found all at once; overlap tests that stop early
``geometry`` geometry refused before any Cycles work (instances only, no faces, no UV map)
``batch``    small objects baked together: one temporary mesh and atlas per batch
``sizing``   map sizes from a texel density; time estimates from a calibration bake
``targets``  which objects are baked; the target image nodes in their real materials
``surface``  the baked texels read as a Lambertian probe, the real material for every other ray
``denoise``  OIDN through Blender's compositor, guided by UV islands
``settings`` the settings of one bake (preset, density, seed, portals)
``portals``  temporary light portals over windows while the sky is baked
``panes``    refracting window glass shown as a clear pane while the sky is baked
``adaptive`` passes until each map reaches its noise target: seeds, error, samples wanted
``passes``   each map's passes, denoised and 3D-filtered as the map; their mean in lux
``exposure`` the bake loop (Cycles calls per group and pass): :class:`ExposureBake`
``run``      :func:`bake_exposure`, a whole bake in one call
``calibration`` tiny bakes that give the estimate its rate
``instances`` collection and geometry-nodes instances: placements, tiles of one atlas per source
``stand_in`` the temporary mesh an instanced source is baked as (every placement, UVs in tiles)
``instance_tiles`` the geometry-nodes modifier that gives each instance its tile
``instance_frames`` instances that change with the frame, said once
``linked``   collections linked from a library: local copies of their aging objects, on request
``maps``     storing maps; reading them back for aging; signature; removal
``panel``    the Exposure Bake panel's contents
"""

from .common import (
    LUX_PER_BAKE_UNIT,
    LUX_PER_WATT,
    UV_MAP_NAME,
    BakeCancelled,
    LightFadeBakeError,
    exposure_image_name,
)
from .emitters import Emitter, LightGroup, find_emitters, find_groups, group_emitters
from .calibration import calibrate
from . import instances
from .exposure import ExposureBake
from .run import bake_exposure
from .settings import BakeSettings
from .maps import (
    StaleExposureError,
    exposure_signature,
    lights_and_exposure,
    maps_lit_by,
    remove_exposure,
)
from .records import LIGHTFADE_PG_exposure_map, LIGHTFADE_PG_object
from .state import BakeState
from .targets import find_targets

__all__ = [
    "LUX_PER_WATT", "LUX_PER_BAKE_UNIT", "UV_MAP_NAME",
    "BakeCancelled", "BakeSettings", "BakeState", "Emitter", "ExposureBake", "LightGroup",
    "LightFadeBakeError", "StaleExposureError",
    "LIGHTFADE_PG_exposure_map", "LIGHTFADE_PG_object",
    "bake_exposure", "calibrate", "exposure_image_name", "exposure_signature",
    "find_emitters", "find_groups", "find_targets", "group_emitters",
    "lights_and_exposure", "maps_lit_by", "remove_exposure",
]
