"""Map sizes from a texel density, and bake-time estimates from a calibration bake.

An object of world-space surface ``A`` (m²) whose UV islands cover a share ``a`` of the
0-1 square gets an ``N × N`` map with ``N = d √(A / a)`` for a density of ``d`` texels
per metre, rounded up to a multiple of 8 and capped.  A ``LightFadeUV`` map (made, or to
be made) is sized with ``a =`` :data:`PACK_FILL` whatever its layout, so the estimate
before the map exists, the bake that makes it and every re-bake give the same size.  Cycles' bake time grows with
texels × samples (per-call overhead is small); a tiny calibration bake on the scene
measures the rate.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from .common import UV_MAP_NAME
from .uvmaps import evaluated_mesh, plan_uv, triangle_uvs, world_triangles

MIN_SIZE = 16
#: Share of the 0-1 square a ``LightFadeUV`` map is sized for: the packing of
#: :func:`.uvmaps.make_unique_uv` fills 0.56-0.60 on real meshes (a sofa, a curtain).
PACK_FILL = 0.55
#: Denoising cost, seconds per million texels on 2 cores: OIDN (4.3 s of CPU per 1024² map)
#: and the 3D filter (2.6 s of CPU, its neighbour search on both cores); docs/bake.md.
DENOISE_SECONDS_PER_MTEXEL = 3.5


def _areas(tri3, tri_uv):
    world = 0.5 * np.linalg.norm(np.cross(tri3[:, 1] - tri3[:, 0], tri3[:, 2] - tri3[:, 0]), axis=1)
    e1, e2 = tri_uv[:, 1] - tri_uv[:, 0], tri_uv[:, 2] - tri_uv[:, 0]
    uv = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    return float(world.sum()), float(uv.sum())


def surface_and_uv_area(obj, depsgraph, uv_name):
    """World-space area (m²) of ``obj`` as rendered, and its UV area in ``uv_name`` (0-1 units).

    Without ``uv_name`` the UV area is :data:`PACK_FILL`.
    """
    with evaluated_mesh(obj, depsgraph) as mesh:
        mesh.calc_loop_triangles()
        tri3 = world_triangles(obj, mesh)
        if uv_name and uv_name in mesh.uv_layers:
            world, uv = _areas(tri3, triangle_uvs(mesh, uv_name)[0])
        else:
            world, uv = _areas(tri3, np.zeros((len(tri3), 3, 2)))[0], PACK_FILL
    return world, uv


def density_size(world_area, uv_area, texels_per_metre, max_size):
    """Map width (= height) for ``texels_per_metre``: a multiple of 8 in [16, max_size]."""
    if world_area <= 0 or uv_area <= 0:
        return MIN_SIZE
    n = texels_per_metre * math.sqrt(world_area / min(uv_area, 1.0))
    n = int(math.ceil(n / 8.0) * 8)
    cap = max(MIN_SIZE, int(max_size) // 8 * 8)
    return int(min(max(n, MIN_SIZE), cap))


def planned_map(obj, depsgraph, settings, diagnose=True):
    """The size and UV map ``obj`` will be baked with: ``(width, UvPlan)``, or
    ``(width, problem line)``.

    The bake, its estimate and the panel all call this.  A ``LightFadeUV`` map, made or
    to be made, is sized from the object's area alone (:data:`PACK_FILL`): a
    re-bake keeps the map and its size, and the estimate gives the size the bake makes.
    ``diagnose``: as :func:`.uvmaps.plan_uv` (False in a panel's draw).
    """
    layers = obj.data.uv_layers
    made = obj.lightfade.uv_created and UV_MAP_NAME in layers
    own = UV_MAP_NAME if made else (layers.active.name if layers.active else None)
    size = _size(obj, depsgraph, settings, None if own == UV_MAP_NAME else own)
    plan = plan_uv(obj, depsgraph, size, diagnose)
    if isinstance(plan, str) or plan.uv_name == own:
        return size, plan
    return _size(obj, depsgraph, settings, None), plan


def _size(obj, depsgraph, settings, uv_name):
    """Map width of ``obj`` baked on ``uv_name`` (None: a ``LightFadeUV`` map)."""
    if settings.resolution:
        return int(settings.resolution)
    world, uv = surface_and_uv_area(obj, depsgraph, uv_name)
    return density_size(world, uv, settings.texels_per_metre, settings.max_size)


@dataclass
class Estimate:
    """What a bake will cost: texel-samples, Cycles calls, and seconds when calibrated.

    An adaptive bake (:mod:`.adaptive`) costs between its first passes everywhere
    (``texel_samples``, ``seconds``) and the cap everywhere (``texel_samples_max``,
    ``seconds_max``; None for a fixed bake).
    """

    texel_samples: float
    texels: float
    calls: int
    seconds: float | None
    texel_samples_max: float | None = None
    seconds_max: float | None = None

    def text(self):
        work = f"{self.texel_samples / 1e6:,.1f} M texel·samples"
        if self.texel_samples_max is not None:
            work = (f"{self.texel_samples / 1e6:,.1f}–{self.texel_samples_max / 1e6:,.1f} M "
                    "texel·samples")
        if self.seconds is None:
            return work + " (press Calibrate for a time)"
        if self.seconds_max is not None:
            return work + (f", ~{format_seconds(self.seconds)} where clean, up to "
                           f"{format_seconds(self.seconds_max)}")
        return work + f", ~{format_seconds(self.seconds)}"


def format_seconds(s):
    return f"{s:.0f} s" if s < 90 else f"{s / 60:.1f} min"


#: scene session_uid -> (texel-samples per second, seconds per call), from :func:`calibrate`.
CALIBRATION = {}


def estimate(scene, sizes_by_group, samples, denoise, passes=1):
    """Estimate the bake of ``sizes_by_group`` (a list, per group, of map widths) at
    ``samples`` per texel in ``passes`` Cycles calls per group (each map denoised once
    per pass)."""
    texels = float(sum(n * n for sizes in sizes_by_group for n in sizes))
    work = texels * samples
    calls = sum(1 for sizes in sizes_by_group if sizes) * passes
    seconds = None
    rate = CALIBRATION.get(scene.session_uid)
    if rate is not None:
        per_texel_sample, per_call = rate
        seconds = work / per_texel_sample + calls * per_call
        if denoise:
            seconds += texels / 1e6 * DENOISE_SECONDS_PER_MTEXEL * passes
    return Estimate(work, texels, calls, seconds)


def estimate_for(scene, sizes_by_group, settings):
    """:func:`estimate` of a bake with :class:`.settings.BakeSettings` ``settings``: an
    adaptive one from its first passes everywhere to its cap everywhere."""
    per_pass = settings.samples_per_pass()
    low = estimate(scene, sizes_by_group, per_pass * settings.first_passes, settings.denoise,
                   settings.first_passes)
    if not settings.adaptive:
        return low
    high = estimate(scene, sizes_by_group, settings.cap_samples, settings.denoise,
                    settings.most_passes)
    low.texel_samples_max = high.texel_samples
    low.seconds_max = high.seconds
    if high.seconds is not None and settings.max_seconds > 0:
        low.seconds_max = min(high.seconds, max(settings.max_seconds, low.seconds))
    return low


#: The untimed bake :func:`calibrate` starts with, and the two it times: (size, samples).
WARM_UP = (32, 1)
TIMED = ((32, 1), (128, 16))


def calibrate(run_bake, clock=time.perf_counter):
    """Measure the bake rate with tiny bakes: ``run_bake(size, samples)`` bakes once.

    Returns ``(texel-samples per second, seconds per call)``: the slope and intercept of
    the time of a 32², 1-sample bake and a 128², 16-sample bake, after an untimed 32²,
    1-sample bake.  A fresh scene's first bake also prepares what every later bake
    reuses (the annual sky map, Cycles' kernels); timed, that read as the small bake's
    cost, and the rate came out 8× too fast on the furnished room (4.2 M against 0.53 M
    texel·samples per second: 8 s estimated for a 34 s bake).  ``clock`` is the timer
    (seconds).
    """
    run_bake(*WARM_UP)
    times = []
    work = []
    for size, samples in TIMED:
        t0 = clock()
        run_bake(size, samples)
        times.append(clock() - t0)
        work.append(size * size * samples)
    slope = max((times[1] - times[0]) / (work[1] - work[0]), 1e-9)
    overhead = max(times[0] - slope * work[0], 0.0)
    return 1.0 / slope, overhead
