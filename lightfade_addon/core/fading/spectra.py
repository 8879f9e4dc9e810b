"""Light sources on LightFade's wavelength grid.

Spectra are float arrays with wavelength (nm) on the last axis, next to one wavelength
vector. Source data are resampled once, at load time, by band averaging
(:func:`resample`), never inside time stepping.

Every preset in :data:`LIGHTS` is returned by :func:`light_spectrum` as the spectral
irradiance, in W m^-2 nm^-1, of that source at an illuminance of exactly 1 lux, so that
``E * lux`` is the irradiance of the source at ``lux`` and ``lux * hours`` is the dose.

Where the presets come from (colour-science 0.4.6, ``colour.SDS_ILLUMINANTS``):

========================  =================  =====================================
name                      CIE source         tabulated range in colour-science
========================  =================  =====================================
``daylight``              D65                300–780 nm, 5 nm (UV kept)
``daylight-glass``        ID65               300–780 nm, 5 nm (zero below 320 nm)
``incandescent``          A                  computed: Planck, 2856 K (colour)
``fluorescent``           FL2                380–780 nm, 5 nm
``led``                   LED-B3             380–780 nm, 5 nm
========================  =================  =====================================

Outside its tabulated range a light is zero. For A this never happens: CIE A is
defined as a Planckian radiator at 2856 K (CIE 15:2004 writes it with c2 = 1.435e-2 m K
and 2848 K), so it is computed at any wavelength, by
``colour.colorimetry.sd_CIE_standard_illuminant_A``. FL2 and LED-B3 are only tabulated from
380 nm: the real FL2 lamp's weak mercury lines at 313 and 365 nm are therefore missing
(fluorescent UV is underestimated); white LEDs emit essentially no UV.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

__all__ = [
    "WAVELENGTHS",
    "LIGHTS",
    "K_M",
    "resample",
    "light_spectrum",
    "illuminance",
    "uv_filter_transmittance",
    "luminous_efficiency",
]

#: The project's default wavelength grid, in nm: 300–780 nm, 12 nm step, 41 samples.
#: UV is included because UV drives much of the fading.
WAVELENGTHS = np.linspace(300.0, 780.0, 41)
WAVELENGTHS.flags.writeable = False

#: Maximum luminous efficacy of radiation for photopic vision, in lm/W.
K_M = 683.0

#: Light presets: name -> one-line description.
LIGHTS = {
    "daylight": "CIE D65 daylight, with its UV (300-380 nm) kept",
    "daylight-glass": "CIE ID65 indoor daylight through window glass (UV below ~320 nm cut)",
    "incandescent": "CIE A, tungsten incandescent lamp (Planckian radiator at 2856 K)",
    "fluorescent": "CIE FL2, cool-white halophosphate fluorescent tube (4230 K)",
    "led": "CIE LED-B3, phosphor-converted white LED (4100 K), no UV",
}

_COLOUR_KEYS = {
    "daylight": "D65",
    "daylight-glass": "ID65",
    "fluorescent": "FL2",
    "led": "LED-B3",
}

#: Fine grid step used to build and normalise spectra before resampling, in nm.
_FINE_STEP = 1.0

def _integral_to(x, y, b):
    """Integral of the linear interpolant of (x, y) from ``x[0]`` to each of ``b``.

    ``y`` is (..., n) over ``x`` (n,); ``b`` a 1-D array of end points within
    ``[x[0], x[-1]]``. The end points are added to the knots (the degree-1 spline
    through the samples, ``scipy.interpolate.make_interp_spline``, evaluated there)
    and the trapezoid rule accumulated over them (``scipy.integrate.cumulative_trapezoid``):
    exact for the piecewise-linear function, and exactly zero over zero stretches.
    """
    from scipy.integrate import cumulative_trapezoid
    from scipy.interpolate import make_interp_spline

    knots = np.union1d(x, b)
    values = make_interp_spline(x, y, k=1, axis=-1)(knots)
    C = cumulative_trapezoid(values, knots, axis=-1, initial=0.0)
    return C[..., np.searchsorted(knots, b)]


def _bin_edges(wavelengths):
    """Bin edges for band averaging: midpoints, with half-width end bins."""
    mid = 0.5 * (wavelengths[1:] + wavelengths[:-1])
    return np.concatenate([wavelengths[:1], mid, wavelengths[-1:]])


def _check_grid(wavelengths, what):
    w = np.asarray(wavelengths, dtype=float)
    if w.ndim != 1 or w.size < 2:
        raise ValueError(f"{what} must be a 1-D array of at least 2 wavelengths (nm)")
    if not np.all(np.diff(w) > 0):
        raise ValueError(f"{what} must be strictly increasing")
    return w


def resample(wavelengths_src, values_src, wavelengths=WAVELENGTHS, outside="zero"):
    """Band-average a spectrum onto a new wavelength grid.

    Each target sample is the mean, over its bin, of the linear interpolant of the
    source. Bin edges lie at the midpoints between target samples; the two end bins are
    half-width (``[w0, (w0 + w1) / 2]`` and its mirror at the top). The integrals are
    computed exactly for the piecewise-linear source, so narrow emission lines (the
    mercury lines of fluorescent lamps) keep their energy on any target grid: the
    trapezoid integral of the result over the target range equals the integral of the
    source over that range.

    Parameters
    ----------
    wavelengths_src : array_like, shape (Ws,)
        Source wavelengths in nm, strictly increasing, ``Ws >= 2``.
    values_src : array_like, shape (..., Ws)
        Source values (any unit); leading axes are a batch.
    wavelengths : array_like, shape (W,)
        Target wavelengths in nm, strictly increasing, ``W >= 2``.
    outside : {"zero", "edge"}
        Value of the source outside its range: ``"zero"`` (light: no emission where
        nothing was measured) or ``"edge"`` (coefficients: hold the end values).

    Returns
    -------
    ndarray, shape (..., W)
        The band-averaged values, in the unit of ``values_src``.

    Examples
    --------
    >>> resample([400.0, 500.0], [1.0, 1.0], [420.0, 450.0, 480.0]).tolist()
    [1.0, 1.0, 1.0]
    """
    x = _check_grid(wavelengths_src, "wavelengths_src")
    w = _check_grid(wavelengths, "wavelengths")
    y = np.asarray(values_src, dtype=float)
    if y.shape[-1:] != x.shape:
        raise ValueError(
            f"values_src has {y.shape[-1] if y.ndim else 0} samples on its last axis, "
            f"wavelengths_src has {x.size}"
        )
    if outside not in ("zero", "edge"):
        raise ValueError(f"outside must be 'zero' or 'edge', not {outside!r}")

    edges = _bin_edges(w)
    F = _integral_to(x, y, np.clip(edges, x[0], x[-1]))
    inside = np.diff(F, axis=-1)
    if outside == "edge":
        below = np.clip(np.minimum(edges[1:], x[0]) - edges[:-1], 0.0, None)
        above = np.clip(edges[1:] - np.maximum(edges[:-1], x[-1]), 0.0, None)
        inside = inside + y[..., :1] * below + y[..., -1:] * above
    return inside / np.diff(edges)


@lru_cache(maxsize=None)
def _photopic_table():
    """CIE 1924 photopic V(lambda), 360–830 nm at 1 nm, as read-only arrays."""
    import colour

    sd = colour.colorimetry.SDS_LEFS_PHOTOPIC["CIE 1924 Photopic Standard Observer"]
    lam = np.array(sd.wavelengths, dtype=float)
    V = np.array(sd.values, dtype=float)
    lam.flags.writeable = False
    V.flags.writeable = False
    return lam, V


def luminous_efficiency(wavelengths):
    """CIE 1924 photopic luminous efficiency V(lambda), zero outside 360–830 nm.

    Parameters
    ----------
    wavelengths : array_like
        Wavelengths in nm.

    Returns
    -------
    ndarray
        V(lambda) in [0, 1], linearly interpolated from the 1 nm CIE table.
    """
    lam, V = _photopic_table()
    return np.interp(np.asarray(wavelengths, dtype=float), lam, V, left=0.0, right=0.0)


def illuminance(E, wavelengths=WAVELENGTHS):
    """Illuminance of a spectral irradiance, by the trapezoid rule.

    Parameters
    ----------
    E : array_like, shape (..., W)
        Spectral irradiance in W m^-2 nm^-1.
    wavelengths : array_like, shape (W,)
        Wavelengths in nm.

    Returns
    -------
    ndarray, shape (...)
        Illuminance in lux: ``683 lm/W * integral E V dlambda``.
    """
    from scipy.integrate import trapezoid

    w = np.asarray(wavelengths, dtype=float)
    return K_M * trapezoid(np.asarray(E, dtype=float) * luminous_efficiency(w), w, axis=-1)


def uv_filter_transmittance(wavelengths, cutoff=400.0, width=8.0):
    """Transmittance of a UV-blocking film, a smooth (logistic) step.

    Parameters
    ----------
    wavelengths : array_like
        Wavelengths in nm.
    cutoff : float
        Wavelength of 50 % transmittance, in nm (museum UV films: about 390–410 nm).
    width : float
        Width of the 10 %–90 % transition, in nm (> 0). With the defaults the film
        transmits < 0.5 % below 390 nm and > 99.5 % above 410 nm.

    Returns
    -------
    ndarray
        Transmittance in [0, 1].
    """
    if width <= 0:
        raise ValueError(f"width must be > 0 nm, not {width}")
    s = width / (2.0 * np.log(9.0))
    z = (np.asarray(wavelengths, dtype=float) - cutoff) / s
    return 0.5 * (1.0 + np.tanh(0.5 * z))


@lru_cache(maxsize=None)
def _fine_source(name, lo, hi):
    """Relative source spectrum on a fine grid: (wavelengths, values), read-only."""
    import colour

    if name == "incandescent":
        shape = colour.SpectralShape(min(lo, 300.0), max(hi, 830.0), _FINE_STEP)
        sd = colour.colorimetry.sd_CIE_standard_illuminant_A(shape)
        lam = np.array(sd.wavelengths, dtype=float)
        values = np.array(sd.values, dtype=float)
    else:
        sd = colour.SDS_ILLUMINANTS[_COLOUR_KEYS[name]]
        src_lam = np.array(sd.wavelengths, dtype=float)
        src = np.array(sd.values, dtype=float)
        lam = np.arange(src_lam[0], src_lam[-1] + _FINE_STEP / 2, _FINE_STEP)
        values = np.interp(lam, src_lam, src)
    lam.flags.writeable = False
    values.flags.writeable = False
    return lam, values


def _check_name(name):
    if name not in LIGHTS:
        raise ValueError(f"unknown light {name!r}; valid names are: {', '.join(LIGHTS)}")


def light_spectrum(name, wavelengths=WAVELENGTHS, uv_filter=False):
    """Spectral irradiance of a preset light at an illuminance of 1 lux.

    Parameters
    ----------
    name : str
        One of :data:`LIGHTS`.
    wavelengths : array_like, shape (W,)
        Target wavelengths in nm, strictly increasing.
    uv_filter : bool
        Put the light behind :func:`uv_filter_transmittance` (default film).

    Returns
    -------
    ndarray, shape (W,)
        Spectral irradiance in W m^-2 nm^-1 for 1 lux, band-averaged onto
        ``wavelengths`` (zero where the source has no data).

    Notes
    -----
    The normalisation ``683 * integral E V dlambda = 1 lux`` is computed on a 1 nm grid
    from the source data (after the UV filter, if any) before resampling, so that
    ``lux`` is always the illuminance measured at the object, filter or not. The
    trapezoid :func:`illuminance` of the resampled spectrum is therefore 1 lux up to
    the resampling error (< 1 % on the default grid).

    Examples
    --------
    >>> E = light_spectrum("daylight", np.arange(300.0, 831.0))
    >>> round(float(illuminance(E, np.arange(300.0, 831.0))), 4)
    1.0
    """
    _check_name(name)
    w = _check_grid(wavelengths, "wavelengths")
    return _light_cached(name, tuple(w.tolist()), bool(uv_filter)).copy()


@lru_cache(maxsize=64)
def _light_cached(name, wavelengths, uv_filter):
    """:func:`light_spectrum` for a grid given as a tuple; read-only, cached."""
    w = np.array(wavelengths)
    lam, values = _fine_source(name, float(w[0]), float(w[-1]))
    if uv_filter:
        values = values * uv_filter_transmittance(lam)
    scale = 1.0 / illuminance(values, lam)
    E = resample(lam, values * scale, w, outside="zero")
    E.flags.writeable = False
    return E
