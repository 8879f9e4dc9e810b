"""The fading problem the studies share: the bundled CMY dyes on paper in daylight.

Section 4.3 of the paper fades random mixtures of three primary colourants (cyan,
magenta, yellow). Its dye data (Yang 2002) is not public, so the studies use the
bundled parametric dyes (``docs/data.md``) and choose the sensitivities so that
one unit of time is a heavy fade, magenta fastest and cyan slowest, as in prints.
"""

from __future__ import annotations

import numpy as np

from lightfade_addon.core.colourants import load_colourant, load_substrate
from lightfade_addon.core.layered import trapezoid_weights
from lightfade_addon.core.spectra import WAVELENGTHS, light_spectrum

#: Relative fading speeds of cyan, magenta and yellow (magenta goes first).
SPEEDS = np.array([2.0, 5.0, 3.0])


def cmy_problem(wavelengths=WAVELENGTHS, light="daylight"):
    """Keyword arguments of :func:`lightfade_addon.core.simulate` except the
    concentrations: CMY dyes on paper under ``light``, ``duration = 1``.

    The irradiance is the light's spectrum at 1 lux; ``beta_j = SPEEDS_j /
    trapz(A_j E0)``, so a solid dye at the surface loses its first e-fold in
    about ``1 / (2 SPEEDS_j)`` time units (the fluence there is about twice the
    irradiance over white paper).
    """
    lam = np.asarray(wavelengths, dtype=float)
    dyes = [load_colourant(name, lam) for name in ("cyan", "magenta", "yellow")]
    A = np.stack([d.K for d in dyes])
    S = np.stack([d.S for d in dyes])
    E0 = light_spectrum(light, lam)
    beta = SPEEDS / (A * E0 * trapezoid_weights(lam)).sum(axis=1)
    return dict(absorption=A, scattering=S, sensitivity=beta, irradiance=E0,
                substrate=load_substrate("paper", lam).reflectance, wavelengths=lam,
                duration=1.0)


def random_mixtures(count=10, seed=2024):
    """``count`` seeded random CMY mixtures, concentrations uniform in [0, 1]."""
    return np.random.default_rng(seed).uniform(0.0, 1.0, (count, 3))


def synthetic_photo(height, width, seed=3):
    """A photograph-like sRGB image in [0, 1], (height, width, 3) float32.

    Sky gradient, sun disc, hills, saturated blossoms and fine texture noise: smooth
    regions, sharp edges and many distinct colours, with no download.
    """
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:height, 0:width].astype(float)
    y /= height
    x /= width
    img = np.empty((height, width, 3))
    img[...] = np.stack([0.35 + 0.4 * y, 0.55 + 0.3 * y, 0.95 - 0.2 * y], -1)      # sky
    sun = (x - 0.78) ** 2 + (y - 0.2) ** 2 < 0.006
    img[sun] = [1.0, 0.85, 0.35]
    hill = y > 0.55 + 0.08 * np.sin(7 * x) + 0.04 * np.sin(19 * x + 1)
    img[hill] = np.stack([0.2 + 0.2 * x, 0.45 + 0.25 * y, 0.15 + 0.1 * x], -1)[hill]
    for _ in range(40):
        cx, cy, r = rng.uniform(0, 1), rng.uniform(0.6, 1), rng.uniform(0.01, 0.04)
        blossom = (x - cx) ** 2 + ((y - cy) * height / width) ** 2 < r * r
        img[blossom] = rng.choice([[0.9, 0.1, 0.5], [0.95, 0.8, 0.1], [0.2, 0.3, 0.9],
                                   [0.9, 0.3, 0.1], [0.6, 0.1, 0.8]])
    img += rng.normal(0.0, 0.025, img.shape)
    return np.clip(img, 0.0, 1.0).astype(np.float32)
