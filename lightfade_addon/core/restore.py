"""Textures that are already old: the colourants before ``years`` of light, by inversion.

A photograph of a faded poster or rug already shows years of light. :func:`restore`
inverts :class:`.aging.TextureAger`'s model, ``XYZ_seen = XYZ_new · exp(change(c0,
dose))`` with ``c0`` the unmixed concentrations of the new colour, per pixel: ``c0``
is the fixed point

    c0 = unmix(XYZ_seen / exp(change(c0, dose)))

found by bounded least squares on ``Lab(c0) - Lab(XYZ_seen / exp(change(c0,
dose)))`` (:func:`.unmix.bounded_gauss_newton`, ``c0`` in [0, 1]) started at the seen
colour's own concentrations, then polished by two fixed-point steps with the same
unmixing the aging uses (:meth:`.unmix.Unmixer.unmix`). The restored pixel is ``XYZ_seen / exp(change(c0,
dose))``, so texture detail survives and aging it again by the same light and years
gives the seen image back.

Where a colourant has (nearly) gone, very different originals fade to the same
colour and the information is destroyed: the restoration would amplify a small
uncertainty in the seen colour into a large one in the original. Such pixels are
reported in ``lost``: the norm of ``d Lab_original / d Lab_seen`` exceeds
:data:`AMPLIFICATION_LIMIT` (an error in the seen colour would triple).
So are pixels no original explains: where the fixed point is not reached (the
mismatch stays above :data:`RESIDUAL_LIMIT`, ΔE*ab), no new colour of the recipe
fades to the seen one under that light. So are pixels whose seen colour has a channel at the edge of [0, 1] (it may have
been clipped there, by the camera or by the gamut mapping of :mod:`.gamut`). Lost
pixels keep the least-squares estimate.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .cache import load_or_build
from .colorimetry import (
    XYZ_to_Lab, XYZ_to_linear_srgb, linear_srgb_to_XYZ, srgb_decode, srgb_encode)
from .gridbuild import XYZ_FLOOR
from .gamut import encode_in_gamut, into_gamut
from .grid import GridSettings
from .lattice import grid_max_dose
from .lights import Light, dose_rates, spectra_keys
from .recipes import get_recipe
from .spectra import WAVELENGTHS, light_spectrum
from .texels import UNMIX_REFINE, texel_concentrations
from .unmix import bounded_gauss_newton, get_unmixer, jacobian, pseudo_inverse

__all__ = ["AMPLIFICATION_LIMIT", "RESIDUAL_LIMIT", "Prior", "Restored", "restore"]

#: Largest gain from an error in the seen colour to one in the restored colour
#: (ΔE*ab per ΔE*ab) for a pixel's information to count as surviving.
AMPLIFICATION_LIMIT = 3.0
#: Largest remaining mismatch (ΔE*ab) between a restored colour and the fixed point
#: for the pixel to count as explained by the model.
RESIDUAL_LIMIT = 2.0
#: Linear channel values this close to 0 or 1 count as clipped at the range's edge.
_EDGE = 1e-4
#: Gauss–Newton iterations of the inversion.
_ITERATIONS = 12


@dataclass(frozen=True)
class Prior:
    """A texture's own history: it is already ``years`` old under ``lights``.

    Attributes
    ----------
    years : float
        Age of the texture as photographed, >= 0.
    lights : tuple of Light
        The light it aged under (each with its schedule).
    exposure : array_like, optional
        Relative exposure per texel (as for :class:`.aging.TextureAger`); uniform
        by default.
    """

    years: float
    lights: tuple = (Light(),)
    exposure: object = None


@dataclass
class Restored:
    """What :func:`restore` returns.

    Attributes
    ----------
    image : ndarray, shape like the input
        The estimated new texture, in [0, 1] in the input's encoding.
    lost : ndarray of bool, shape of the input without the channel axis
        Pixels whose original colour the light destroyed (see the module docstring).
    gain : ndarray, shape of ``lost``
        Per pixel, how much an error in the seen colour grows in the restored one
        (ΔE*ab per ΔE*ab; 0 where no light fell).
    """

    image: np.ndarray
    lost: np.ndarray
    gain: np.ndarray

    @property
    def lost_count(self):
        return int(np.count_nonzero(self.lost))


def log_initial(grid, unmixer, c):
    """``log XYZ_initial`` of unmixed concentrations ``c`` when ``grid`` wants it."""
    if grid.initial is None:
        return None
    return np.log(np.maximum(unmixer.XYZ(c), XYZ_FLOOR))


def _encoded(flat, encoding):
    return flat if encoding == "srgb" else srgb_encode(np.clip(flat, 0.0, 1.0))


def restore(rgb, years, recipe="printed-paper", lights=(Light(),), exposure=None,
            encoding="srgb", settings=GridSettings(), cache=True, store=None, progress=None,
            levels=64):
    """Undo ``years`` of ``lights`` on a texture: its estimated colours when new.

    Parameters
    ----------
    rgb : array_like, shape (..., 3)
        The texture as it is now, in [0, 1] (linear or encoded sRGB, ``encoding``).
    years : float
        How old it is, >= 0.
    recipe : Recipe or str
    lights : sequence of Light
        The light it aged under.
    exposure : array_like, optional
        Relative exposure per texel (default: 1 everywhere).
    encoding : {"linear", "srgb"}
    settings, cache, store, progress
        As for :class:`.aging.TextureAger`.
    levels : int
        The dose per texel is quantised to this many levels (one solve per
        distinct colour and level).

    Returns
    -------
    Restored
        ``image`` and the ``lost`` mask.

    Raises
    ------
    ValueError
        Non-finite colours or years, negative years, no lights, bad exposure.
    """
    recipe = get_recipe(recipe) if isinstance(recipe, str) else recipe
    years = float(years)
    if not np.isfinite(years) or years < 0:
        raise ValueError(f"years must be a finite number >= 0, got {years!r}")
    if encoding not in ("linear", "srgb"):
        raise ValueError(f"encoding must be 'linear' or 'srgb', got {encoding!r}")
    rgb = np.asarray(rgb, dtype=np.float32)
    if rgb.shape[-1] != 3:
        raise ValueError(f"rgb must have 3 channels on the last axis, got shape {rgb.shape}")
    if not np.all(np.isfinite(rgb)):
        raise ValueError("rgb contains NaN or infinite values")
    if not lights:
        raise ValueError("at least one light is needed")
    say = progress or (lambda f, m: None)
    flat = np.clip(rgb.reshape(-1, 3), 0.0, 1.0)
    n = flat.shape[0]
    keys = spectra_keys(lights)
    rates = dose_rates(lights, exposure, n, keys).astype(float)          # (S, n)
    total = rates.sum(axis=0)
    doses = total * years
    dmax = float(doses.max()) if n else 0.0
    lost = np.zeros(rgb.shape[:-1], dtype=bool)
    gain = np.zeros(rgb.shape[:-1])
    if dmax <= 0:
        return Restored(rgb.copy(), lost, gain)

    spectra = np.stack([light_spectrum(s, WAVELENGTHS, uv) for s, uv in keys])
    say(0.0, "building the fading grid")
    grid = load_or_build(recipe, spectra, grid_max_dose(dmax), settings, cache=cache, store=store,
                         progress=lambda f, m: say(0.5 * f, m))
    unmixer = get_unmixer(recipe)
    say(0.5, "unmixing colours")
    key, c_seen = texel_concentrations(_encoded(flat, encoding), unmixer)

    # one solve per distinct (colour, dose level, light mix level)
    level = np.rint(doses / dmax * (levels - 1)).astype(np.int64)
    mix = rates / np.where(total > 0, total, 1.0)
    mix_level = np.rint(mix[1:] * (levels - 1)).astype(np.int64) if len(keys) > 1 else \
        np.zeros((0, n), dtype=np.int64)
    code = key.astype(np.int64) * levels + level
    for row in mix_level:
        code = code * levels + row
    _, first, group = np.unique(code, return_index=True, return_inverse=True)
    group = group.reshape(-1)
    G = first.size
    dose_g = level[first] / (levels - 1) * dmax
    mix_g = None
    if len(keys) > 1:
        counts = np.bincount(group, minlength=G)
        mix_g = np.stack([np.bincount(group, mix[s], G) for s in range(len(keys))], 1)
        mix_g /= counts[:, None]
    c0 = c_seen[key[first]].copy()
    lin = srgb_decode(flat) if encoding == "srgb" else flat
    XYZ_seen = linear_srgb_to_XYZ(lin.astype(float))
    counts = np.bincount(group, minlength=G)[:, None]
    XYZ_g = np.stack([np.bincount(group, v, G) for v in XYZ_seen.T], 1) / counts

    def ratio_of(c, rows=slice(None)):
        m = None if mix_g is None else mix_g[rows]
        return np.exp(grid.log_change(c, dose_g[rows], m, log_initial(grid, unmixer, c)))

    say(0.7, f"inverting the fade of {G} colours")
    if unmixer.Cu:
        # the fixed point c0 = unmix(XYZ_seen / ratio(c0)): what TextureAger sees in
        # the restored pixel is what it was restored with. Gauss-Newton on the
        # mismatch Lab(c0) - Lab(XYZ_seen / ratio(c0)) (zero at the fixed point
        # inside the gamut), then two fixed-point steps with the aging's unmixing.
        def mismatch(c, rows=slice(None)):
            return unmixer.Lab(c) - XYZ_to_Lab(XYZ_g[rows] / ratio_of(c, rows))

        c0 = bounded_gauss_newton(mismatch, c0, np.zeros((G, 3)), _ITERATIONS)
        for _ in range(2):      # polish with the aging's own unmixing, for a round trip
            new = into_gamut(XYZ_to_linear_srgb(XYZ_g / ratio_of(c0)))
            c0 = unmixer.unmix(new, refine=UNMIX_REFINE)

        def aged_Lab(c, rows=slice(None)):
            return XYZ_to_Lab(unmixer.XYZ(c) * ratio_of(c, rows))

        gain_g = np.linalg.norm(np.einsum("nik,nkj->nij", jacobian(unmixer.Lab, c0),
                                          pseudo_inverse(jacobian(aged_Lab, c0))),
                                ord=2, axis=(1, 2))
        gain_g[dose_g <= 0] = 0.0
        unexplained = np.linalg.norm(mismatch(c0), axis=-1) > RESIDUAL_LIMIT
        gain_g[unexplained & (dose_g > 0)] = np.inf
        gain = gain_g[group].reshape(gain.shape)
    # a seen colour on the edge of the range may have been clipped there: its
    # original is not known either
    clipped = np.any((lin <= _EDGE) | (lin >= 1.0 - _EDGE), axis=-1).reshape(lost.shape)
    lost = (gain > AMPLIFICATION_LIMIT) | (clipped & (doses.reshape(lost.shape) > 0))
    ratio = ratio_of(c0)                                                  # (G, 3)
    XYZ = XYZ_seen / ratio[group]
    image = encode_in_gamut(XYZ_to_linear_srgb(XYZ), encoding).astype(np.float32)
    say(1.0, f"restored; {np.count_nonzero(lost)} pixels lost")
    return Restored(image.reshape(rgb.shape), lost, gain)
