"""The fading problem the studies share: the bundled CMY dyes on paper in daylight.

Section 4.3 of the paper fades random mixtures of three primary colourants (cyan,
magenta, yellow). Its dye data (Yang 2002) is not public, so the studies use the
bundled parametric dyes (``docs/data.md``) and choose the sensitivities so that
one unit of time is a heavy fade, magenta fastest and cyan slowest, as in prints.
"""

from __future__ import annotations

import numpy as np

from lightfade_addon.core.fading.colourants import load_colourant, load_substrate
from lightfade_addon.core.fading.layered import trapezoid_weights
from lightfade_addon.core.fading.spectra import WAVELENGTHS, light_spectrum

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
    regions, sharp edges and many distinct colours, with no download. Built with
    broadcasting in float32, so a 4096² image costs little more than its own 200 MB.
    """
    rng = np.random.default_rng(seed)
    y = (np.arange(height, dtype=np.float32) / height)[:, None]
    x = (np.arange(width, dtype=np.float32) / width)[None, :]
    img = np.empty((height, width, 3), dtype=np.float32)
    for ch, (a, b) in enumerate(((0.35, 0.4), (0.55, 0.3), (0.95, -0.2))):
        img[..., ch] = a + b * y                                           # sky
    img[((x - 0.78) ** 2 + (y - 0.2) ** 2) < 0.006] = (1.0, 0.85, 0.35)    # sun
    hill = y > 0.55 + 0.08 * np.sin(7 * x) + 0.04 * np.sin(19 * x + 1)
    for ch, value in enumerate((0.2 + 0.2 * x + 0 * y, 0.45 + 0.25 * y + 0 * x,
                                0.15 + 0.1 * x + 0 * y)):
        img[..., ch][hill] = value[hill]
    for _ in range(40):
        cx, cy, r = rng.uniform(0, 1), rng.uniform(0.6, 1), rng.uniform(0.01, 0.04)
        blossom = (x - cx) ** 2 + ((y - cy) * height / width) ** 2 < r * r
        img[blossom] = rng.choice([[0.9, 0.1, 0.5], [0.95, 0.8, 0.1], [0.2, 0.3, 0.9],
                                   [0.9, 0.3, 0.1], [0.6, 0.1, 0.8]])
    for ch in range(3):
        img[..., ch] += rng.standard_normal((height, width), dtype=np.float32) * 0.025
    np.clip(img, 0.0, 1.0, out=img)
    return img
