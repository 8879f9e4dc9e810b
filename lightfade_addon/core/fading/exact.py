"""The reference path: aging an image without the grid, one simulation per colour.

The paper's "without selective interpolation": every distinct colour of the image
is unmixed (exactly, no binning) and simulated directly at the recipe's solver
settings. Slow, and the yardstick of the grid's accuracy (``benchmarks/photos.py``).
"""

from __future__ import annotations

import numpy as np

from ..colour.colorimetry import (
    checked_rgb,
    XYZ_to_linear_srgb,
    linear_srgb_to_XYZ,
    reflectance_to_XYZ,
    srgb_decode,
    srgb_encode,
)
from ..colour.gamut import encode_in_gamut
from .lights import Light
from .recipes import get_recipe
from .spectra import WAVELENGTHS
from .unmix import get_unmixer

__all__ = ["age_image_exact"]


def age_image_exact(rgb, years, recipe="printed-paper", light=Light(), exposure=None,
                    encoding="srgb", levels=64, progress=None):
    """Age an image without the grid: one simulation per distinct colour (the reference).

    Every distinct colour (exact values, no binning) is unmixed as in
    :class:`.aging.TextureAger` and simulated directly at the recipe's solver
    settings (:meth:`.recipes.Recipe.simulate`: stepping at least at the grid's dose
    nodes), recording every requested dose; one batch per distinct exposure value,
    or per one of ``levels`` levels when there are more. Only one light spectrum (one :class:`Light`).
    Aged colours are mapped into [0, 1] by :func:`.gamut.encode_in_gamut`.

    Returns
    -------
    list of ndarray
        One image per entry of ``years``, like ``rgb``.
    """
    recipe = get_recipe(recipe) if isinstance(recipe, str) else recipe
    years = np.array([float(y) for y in np.atleast_1d(years)])
    if np.any(~np.isfinite(years)) or np.any(years < 0):
        raise ValueError("years must be finite numbers >= 0")
    rgb = checked_rgb(rgb)
    flat = rgb.reshape(-1, 3)
    n = flat.shape[0]
    say = progress or (lambda f, m: None)
    e = np.ones(n) if exposure is None else np.asarray(exposure, float).reshape(n)
    if not np.all(np.isfinite(e)) or np.any(e < 0):
        raise ValueError("exposure must be finite and >= 0")
    emax = float(e.max()) if e.size else 0.0
    values, level = np.unique(e, return_inverse=True)      # exact when there are few
    level = level.reshape(-1)
    if values.size > levels:
        level = np.rint(e / emax * (levels - 1)).astype(np.int64)
        values = np.arange(levels) / (levels - 1) * emax
    enc = np.clip(flat if encoding == "srgb" else srgb_encode(np.clip(flat, 0, 1)), 0, 1)
    colours, key = np.unique(enc, axis=0, return_inverse=True)
    key = key.reshape(-1)
    c_unmixed = get_unmixer(recipe).unmix(colours, encoded=True)   # converged
    E0 = light.spectrum_1lux()
    lin = srgb_decode(flat) if encoding == "srgb" else flat
    XYZ = linear_srgb_to_XYZ(lin)
    ratio = np.ones((years.size, n, 3))
    groups = np.unique(level)
    for g_i, g in enumerate(groups):
        say(g_i / groups.size, f"simulating exposure level {g_i + 1}/{groups.size}")
        texels = np.nonzero(level == g)[0]
        dose_rate = light.annual_dose * values[g]
        doses = years * dose_rate
        if dose_rate == 0 or not np.any(doses > 0):
            continue
        used, inverse = np.unique(key[texels], return_inverse=True)
        positive = np.unique(doses[doses > 0])
        r = recipe.simulate(recipe.concentrations(c_unmixed[used]), E0, positive[-1],
                            record=positive)
        X0 = np.maximum(reflectance_to_XYZ(r.initial, WAVELENGTHS), 1e-6)
        for y_i, d in enumerate(doses):
            if d > 0:
                Xd = np.maximum(reflectance_to_XYZ(r.history[np.searchsorted(positive, d)],
                                                   WAVELENGTHS), 1e-6)
                ratio[y_i, texels] = (Xd / X0)[inverse]
    say(1.0, "done")
    out = []
    for y_i, y in enumerate(years):
        if y == 0:
            out.append(rgb.copy())
            continue
        res = encode_in_gamut(XYZ_to_linear_srgb(XYZ * ratio[y_i]), encoding)
        out.append(res.astype(np.float32).reshape(rgb.shape))
    return out
