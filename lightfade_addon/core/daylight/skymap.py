"""The annual sky map assembled from a year's samples: sun path, sky, ground.

:func:`.daylight.annual_sky_map` is the entry point; this module puts each sample's
light into the pixels of Blender's equirectangular frame (:mod:`.skygrid`).
"""

from __future__ import annotations

import numpy as np

from .allweather import diffuse_sky_Perez1993
from .perez import COS_85
from .skygrid import direction_to_pixel, grid, sun_direction_scene
from .skysamples import SkySamples

__all__ = ["SKY_MODELS", "PEREZ1993_GRID", "PEREZ1993_SUBSTEPS", "substeps_for", "accumulate"]

#: The sky luminance distributions :func:`.daylight.annual_sky_map` offers (the first is
#: the default).
SKY_MODELS = ("Perez1993", "Perez1990")

#: The Perez 1993 distribution's resolution: grid width (pixels) and samples per hour.
PEREZ1993_GRID = 64
PEREZ1993_SUBSTEPS = 2


def substeps_for(width):
    """Sub-intervals per hour so that the sun moves at most about half a pixel (the
    sun crosses at most 15°/h; a pixel is 360/width degrees)."""
    return max(6, int(np.ceil(width / 12.0)))


def _coarse_factor(width, finest=128):
    """Integer f such that width / f <= ``finest`` is a valid map width (1 if none)."""
    for f in range(int(np.ceil(width / finest)), width // 16 + 1):
        if width % f == 0 and (width // f) % 4 == 0:
            return f
    return 1


def _upsample(part, f):
    """Bilinear interpolation of a (h, w) half-map between its pixel centres onto
    (h f, w f) pixels; columns wrap round (azimuth), rows are clamped at the ends."""
    if f == 1:
        return part
    h, w = part.shape

    def axis(n, size):
        x = (np.arange(n * f) + 0.5) / f - 0.5
        i0 = np.floor(x).astype(int)
        return i0, x - i0

    r0, tr = axis(h, h)
    r0c = np.clip(r0, 0, h - 1)
    r1c = np.clip(r0 + 1, 0, h - 1)
    rows = part[r0c] * (1.0 - tr)[:, None] + part[r1c] * tr[:, None]
    c0, tc = axis(w, w)
    return rows[:, c0 % w] * (1.0 - tc) + rows[:, (c0 + 1) % w] * tc


def _diffuse_Perez1990(s, K_d, width, north, sky):
    """Isotropic dome, circumsolar point source and horizon band (Perez et al. 1990)."""
    d, omega = grid(width)
    H = d.shape[0]
    h = H // 2
    cos_z = np.cos(np.radians(s.zenith))
    # circumsolar: a point source at the sun, F1·DHI / max(cos Z, cos 85°) at normal incidence
    cs = K_d * s.F1 * s.dhi / np.maximum(cos_z, COS_85) * s.hours
    idx = direction_to_pixel(sun_direction_scene(s.zenith, s.azimuth, north), width)
    sky += np.bincount(idx, weights=cs, minlength=sky.size).reshape(sky.shape) / omega
    # horizon band: a line source along the horizon giving F2·DHI·sin(tilt) on a plane,
    # i.e. F2·DHI/2 per radian of azimuth, in the first row above the horizon
    band_L = float(np.sum(K_d * s.F2 * s.dhi * s.hours)) / 2.0 / np.sin(np.pi / H)
    sky[h] += band_L
    band_horizontal = band_L * float(np.sum(omega[h] * d[h, :, 2]))
    # isotropic dome: (1 - F1)·DHI on the horizontal, less what the band row already gives
    iso = float(np.sum(K_d * (1.0 - s.F1) * s.dhi * s.hours)) - band_horizontal
    sky[h:] += iso / float(np.sum(omega[h:] * d[h:, :, 2]))


def _diffuse_Perez1993(s, coarse, photometric, width, north, sky):
    """All-weather luminance distribution (Perez et al. 1993), gendaymtx's normalisation,
    evaluated for the ``coarse`` samples on a grid at most :data:`PEREZ1993_GRID` pixels
    wide, interpolated onto the map's pixels and scaled to the diffuse horizontal dose of
    the samples ``s``."""
    f = _coarse_factor(width, PEREZ1993_GRID)
    K_d = coarse.K_diffuse if photometric else 1.0
    part = diffuse_sky_Perez1993(coarse, K_d * coarse.dhi * coarse.hours, width // f, north)
    part = _upsample(part, f)
    d, omega = grid(width)
    h = d.shape[0] // 2
    total = float(np.sum(part * omega[h:] * d[h:, :, 2]))
    K_d = s.K_diffuse if photometric else 1.0
    if total > 0:
        sky[h:] += part * (float(np.sum(K_d * s.dhi * s.hours)) / total)


def accumulate(s: SkySamples, width, north, albedo, ground, photometric, sky_model="Perez1993",
               coarse: SkySamples | None = None):
    """The annual sky map from a year's samples (:func:`.daylight.annual_sky_map` says
    what goes where).

    Parameters
    ----------
    s : SkySamples
        The year's samples (sun path and totals).
    width : int
        Map width.
    north : float
        Scene north angle, degrees.
    albedo : float
        Ground reflectance.
    ground : bool
        Fill the lower half.
    photometric : bool
        lux·h (True) or W·h (False).
    sky_model : str
        One of :data:`SKY_MODELS`.
    coarse : SkySamples, optional
        The samples the Perez 1993 distribution is evaluated for (default ``s``).

    Returns
    -------
    numpy.ndarray
        (W // 2, W) float32.
    """
    d, omega = grid(width)
    H, W = d.shape[:2]
    h = H // 2
    K_b = s.K_direct if photometric else 1.0
    K_d = s.K_diffuse if photometric else 1.0
    # the sun: direct normal dose into the pixel of each sample's position
    idx = direction_to_pixel(sun_direction_scene(s.zenith, s.azimuth, north), width)
    sky = np.bincount(idx, weights=K_b * s.dni * s.hours, minlength=H * W).reshape(H, W) / omega
    if sky_model == "Perez1990":
        _diffuse_Perez1990(s, K_d, width, north, sky)
    else:
        _diffuse_Perez1993(s, coarse if coarse is not None else s, photometric, width, north, sky)
    if ground:
        k_g = s.K_global if photometric else 1.0
        glob = float(np.sum(k_g * s.ghi * s.hours))
        sky[:h] += albedo * glob / float(np.sum(omega[:h] * -d[:h, :, 2]))
    return np.maximum(sky, 0.0).astype(np.float32)
