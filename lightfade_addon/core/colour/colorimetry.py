"""Colorimetry: reflectance spectra to XYZ, CIELAB, linear sRGB, and colour differences.

Conventions (DESIGN.md, "Units and conventions"): CIE 1931 2° standard observer,
illuminant D65 unless told otherwise, XYZ scaled so that a perfect white reflector has
Y = 1, CIELAB relative to the illuminant's own white. Arrays broadcast: reflectance is
(..., W) with wavelength on the last axis, colours are (..., 3).

Everything that depends only on the wavelength grid (the (W, 3) weight matrix, the
white point, the sRGB matrices) is computed once and cached, so that per-texel work is
one matrix product and a few element-wise operations.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

__all__ = [
    "checked_rgb",
    "xyz_weights",
    "white_XYZ",
    "reflectance_to_XYZ",
    "XYZ_to_Lab",
    "reflectance_to_Lab",
    "XYZ_to_linear_srgb",
    "linear_srgb_to_XYZ",
    "reflectance_to_linear_srgb",
    "srgb_encode",
    "srgb_decode",
    "delta_E_ab",
    "delta_E_2000",
    "rms_delta_R",
]

_OBSERVER = "CIE 1931 2 Degree Standard Observer"
#: The 1 nm integration grid of the CIE 1931 colour-matching functions, in nm.
_CMF_RANGE = (360.0, 830.0)


@lru_cache(maxsize=None)
def _cmfs_times_illuminant(illuminant):
    """(471, 3) array: CMF x illuminant on the 1 nm grid 360–830 nm, and that grid."""
    import colour

    if illuminant not in colour.SDS_ILLUMINANTS:
        raise ValueError(
            f"unknown illuminant {illuminant!r}; use a key of colour.SDS_ILLUMINANTS "
            "such as 'D65', 'D50' or 'A'"
        )
    cmfs = colour.MSDS_CMFS[_OBSERVER]
    shape = colour.SpectralShape(_CMF_RANGE[0], _CMF_RANGE[1], 1.0)
    cmfs = cmfs.copy().align(shape)
    sd = colour.SDS_ILLUMINANTS[illuminant].copy().align(shape)
    lam = np.array(cmfs.wavelengths, dtype=float)
    weighted = np.array(cmfs.values, dtype=float) * np.clip(sd.values, 0.0, None)[:, None]
    return lam, weighted


def _hat_basis(lam, wavelengths):
    """(len(lam), W) matrix of the linear-interpolation hat functions at ``lam``.

    Row ``j`` holds the weights with which the samples of a piecewise-linear spectrum
    combine to its value at ``lam[j]``: the degree-1 B-spline through the identity
    (``scipy.interpolate.make_interp_spline``), so that column ``k`` is the hat of
    sample ``k``. Outside the sample range the end values are held.
    """
    from scipy.interpolate import make_interp_spline

    w = np.asarray(wavelengths, dtype=float)
    if w.size == 1:
        return np.ones((lam.size, 1))
    hats = make_interp_spline(w, np.eye(w.size), k=1)
    return hats(np.clip(lam, w[0], w[-1]))


@lru_cache(maxsize=64)
def _weights_cached(wavelengths, illuminant):
    lam, weighted = _cmfs_times_illuminant(illuminant)
    M = _hat_basis(lam, np.array(wavelengths)).T @ weighted
    M /= weighted[:, 1].sum()
    M.flags.writeable = False
    return M


def xyz_weights(wavelengths, illuminant="D65"):
    """Weight matrix M with ``XYZ = R @ M`` for reflectance R sampled at ``wavelengths``.

    Parameters
    ----------
    wavelengths : array_like, shape (W,)
        Sample wavelengths in nm, strictly increasing.
    illuminant : str
        A key of ``colour.SDS_ILLUMINANTS`` ("D65", "D50", "A", ...).

    Returns
    -------
    ndarray, shape (W, 3), read-only
        Tristimulus weights. A reflectance ``R = 1`` gives ``Y = 1``.

    Notes
    -----
    The reflectance is taken to be the linear interpolant of its samples, held constant
    beyond the first and last sample. The CIE 1931 2° colour-matching functions times the
    illuminant (colour-science's data aligned to 1 nm) are summed against each
    interpolation hat function over 360–830 nm, so that the result is exact, at 1 nm
    resolution, for piecewise-linear R (ASTM E308's idea of weighting tables, built for
    any grid). Samples whose hat lies outside 360–830 nm get zero weight. The matrix is
    cached per (grid, illuminant).
    """
    w = np.asarray(wavelengths, dtype=float)
    if w.ndim != 1 or w.size < 1 or np.any(np.diff(w) <= 0):
        raise ValueError("wavelengths must be a strictly increasing 1-D array (nm)")
    return _weights_cached(tuple(w.tolist()), illuminant)


@lru_cache(maxsize=None)
def _white_cached(illuminant):
    lam, weighted = _cmfs_times_illuminant(illuminant)
    W = weighted.sum(axis=0) / weighted[:, 1].sum()
    W.flags.writeable = False
    return W


def white_XYZ(illuminant="D65"):
    """XYZ of the perfect white reflector under ``illuminant``, Y = 1; shape (3,)."""
    return _white_cached(illuminant)


def reflectance_to_XYZ(R, wavelengths, illuminant="D65"):
    """CIE XYZ (Y of white = 1) of reflectance spectra.

    Parameters
    ----------
    R : array_like, shape (..., W)
        Reflectance in [0, 1] at ``wavelengths``.
    wavelengths : array_like, shape (W,)
        Wavelengths in nm.
    illuminant : str
        Illuminant key, see :func:`xyz_weights`.

    Returns
    -------
    ndarray, shape (..., 3)
    """
    return np.asarray(R, dtype=float) @ xyz_weights(wavelengths, illuminant)


#: CIE 15:2004 Eq. 8.5: the cube root's threshold, ``(24/116)³``, and the linear part's
#: slope, ``841/108``, below it (colour-science's constants, the same floats)
_LAB_EPSILON = (24.0 / 116.0) ** 3
_LAB_SLOPE = 841.0 / 108.0


def XYZ_to_Lab(XYZ, illuminant="D65"):
    """CIE 1976 L*a*b* of XYZ, relative to the white of ``illuminant``.

    Parameters
    ----------
    XYZ : array_like, shape (..., 3)
        Tristimulus values with Y of white = 1.
    illuminant : str
        Illuminant key; the white is :func:`white_XYZ` of it (the same integration as
        the reflectance, so that R = 1 gives (100, 0, 0)).

    Returns
    -------
    ndarray, shape (..., 3)
        L* in [0, 100] for reflective colours, a* and b*.

    Notes
    -----
    CIE 15:2004, equations 8.3–8.7, as ``colour.XYZ_to_Lab`` computes them (within
    1e-12; ``tests/core/test_colorimetry.py``) but written out here: the colour
    unmixing calls it thousands of times on small blocks (a table build: 1,800 calls),
    where colour-science's domain-range and validation layers cost 0.9 s of the
    unmixing's 2.3 s (cProfile, the ten-material room's Age).
    """
    t = np.asarray(XYZ, dtype=float) / white_XYZ(illuminant)
    f = np.where(t > _LAB_EPSILON, np.cbrt(t), _LAB_SLOPE * t + 16.0 / 116.0)
    fx, fy, fz = f[..., 0], f[..., 1], f[..., 2]
    return np.stack([116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)], axis=-1)


def reflectance_to_Lab(R, wavelengths, illuminant="D65"):
    """CIELAB of reflectance spectra (..., W) -> (..., 3); see :func:`XYZ_to_Lab`."""
    return XYZ_to_Lab(reflectance_to_XYZ(R, wavelengths, illuminant), illuminant)


@lru_cache(maxsize=None)
def _srgb_matrices():
    """(RGB_to_XYZ, XYZ_to_RGB) for sRGB primaries with the integrated D65 white."""
    import colour

    W = white_XYZ("D65")
    xy = W[:2] / W.sum()
    primaries = colour.RGB_COLOURSPACES["sRGB"].primaries
    M = np.array(colour.normalised_primary_matrix(primaries, xy), dtype=float)
    Minv = np.linalg.inv(M)
    M.flags.writeable = False
    Minv.flags.writeable = False
    return M, Minv


def XYZ_to_linear_srgb(XYZ):
    """Linear sRGB (Rec. 709 primaries, D65) of D65 XYZ; (..., 3) -> (..., 3).

    The matrix is built from the sRGB primaries and the D65 white integrated by this
    module (xy differs from the nominal (0.3127, 0.3290) by ~1e-4), so that the perfect
    white reflector maps to exactly (1, 1, 1). No clipping.
    """
    return np.asarray(XYZ, dtype=float) @ _srgb_matrices()[1].T


def linear_srgb_to_XYZ(RGB):
    """D65 XYZ of linear sRGB; the inverse of :func:`XYZ_to_linear_srgb`."""
    return np.asarray(RGB, dtype=float) @ _srgb_matrices()[0].T


@lru_cache(maxsize=64)
def _rgb_weights_cached(wavelengths):
    M = xyz_weights(np.array(wavelengths), "D65") @ _srgb_matrices()[1].T
    M.flags.writeable = False
    return M


def reflectance_to_linear_srgb(R, wavelengths):
    """Linear sRGB albedo of reflectance spectra under D65; (..., W) -> (..., 3).

    One matrix product with the cached (W, 3) matrix ``xyz_weights @ XYZ_to_RGB.T``.
    """
    w = np.asarray(wavelengths, dtype=float)
    return np.asarray(R, dtype=float) @ _rgb_weights_cached(tuple(w.tolist()))


def srgb_encode(linear):
    """The sRGB transfer function (IEC 61966-2-1): linear [0, 1] -> encoded [0, 1].

    ``colour.models.eotf_inverse_sRGB``; values below 0 follow the linear segment, no
    clipping.
    """
    from colour.models import eotf_inverse_sRGB

    return eotf_inverse_sRGB(np.asarray(linear, dtype=float))


def srgb_decode(encoded):
    """The inverse sRGB transfer function: encoded [0, 1] -> linear [0, 1].

    ``colour.models.eotf_sRGB`` (IEC 61966-2-1).
    """
    from colour.models import eotf_sRGB

    return eotf_sRGB(np.asarray(encoded, dtype=float))


def delta_E_ab(Lab1, Lab2):
    """CIE 1976 colour difference ΔE*ab (the paper's metric); (..., 3) -> (...).

    ``colour.delta_E(..., method="CIE 1976")``, the Euclidean distance in CIELAB.
    """
    import colour

    Lab1, Lab2 = np.broadcast_arrays(np.asarray(Lab1, float), np.asarray(Lab2, float))
    return np.asarray(colour.delta_E(Lab1, Lab2, method="CIE 1976"), dtype=float)


def delta_E_2000(Lab1, Lab2):
    """CIEDE2000 colour difference (kL = kC = kH = 1); (..., 3) -> (...).

    Uses ``colour.delta_E(..., method="CIE 2000")`` (Sharma, Wu and Dalal 2005).
    """
    import colour

    Lab1, Lab2 = np.broadcast_arrays(np.asarray(Lab1, float), np.asarray(Lab2, float))
    return np.asarray(colour.delta_E(Lab1, Lab2, method="CIE 2000"), dtype=float)


def rms_delta_R(R1, R2):
    """RMS spectral difference over wavelength (the paper's Table 1 metric).

    Parameters
    ----------
    R1, R2 : array_like, shape (..., W)
        Reflectances on the same wavelength grid.

    Returns
    -------
    ndarray, shape (...)
        ``sqrt(mean((R1 - R2)**2))`` over the last axis.
    """
    d = np.asarray(R1, dtype=float) - np.asarray(R2, dtype=float)
    return np.sqrt(np.mean(d * d, axis=-1))


def checked_rgb(rgb):
    """``rgb`` as float32 colours on the last axis (…, 3), or one clear ``ValueError``
    (the shared input check of the agers, restore and the exact path)."""
    rgb = np.asarray(rgb, dtype=np.float32)
    if rgb.shape[-1:] != (3,):
        raise ValueError(f"rgb must have 3 channels on the last axis, got shape {rgb.shape}")
    if not np.all(np.isfinite(rgb)):
        raise ValueError("rgb contains NaN or infinite values")
    return rgb
