"""Aging textures: from colours and exposure to the same texture after N years.

:class:`TextureAger` does everything that does not depend on the years once per
texture — lights to per-texel dose rates and spectral mixes, the grid, unmixing the
texel colours, the change curves along the dose axis for every distinct colour — so
that :meth:`TextureAger.age` only interpolates along the dose axis and multiplies:
a few gathers and elementwise operations per texel.

The aged texel is the original times the modelled change, in CIE XYZ::

    XYZ_aged = XYZ_texel * exp(change(c, dose, mix))

so texture detail survives, and at zero years the original comes back exactly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .colorimetry import linear_srgb_to_XYZ, srgb_decode, srgb_encode, XYZ_to_linear_srgb
from .grid import GridSettings, load_or_build, simplex_interpolation
from .recipes import Recipe, get_recipe
from .spectra import WAVELENGTHS, light_spectrum
from .unmix import get_unmixer

__all__ = ["Light", "TextureAger", "age_image", "age_image_exact", "HOURS_PER_YEAR_DEFAULT"]

#: Texels updated per block in :meth:`TextureAger.age` (bounds the temporaries).
_BLOCK = 1 << 18
#: Most distinct colours unmixed per texture; more are merged by dropping bits.
_MAX_KEYS = 1 << 16
HOURS_PER_YEAR_DEFAULT = 8.0 * 365.0


@dataclass(frozen=True)
class Light:
    """A light's spectrum and schedule.

    Attributes
    ----------
    spectrum : str
        A :data:`.spectra.LIGHTS` name, e.g. ``"daylight-glass"``.
    uv_filter : bool
        Behind a UV filter.
    lux : float
        Illuminance where the exposure map is 1 (with absolute maps in lux, 1).
    hours_per_day, days_per_year : float
        When the light is on.
    """

    spectrum: str = "daylight-glass"
    uv_filter: bool = False
    lux: float = 150.0
    hours_per_day: float = 8.0
    days_per_year: float = 365.0

    def __post_init__(self):
        for name in ("lux", "hours_per_day", "days_per_year"):
            v = getattr(self, name)
            if not np.isfinite(v) or v < 0:
                raise ValueError(f"light {name} must be a finite number >= 0, got {v!r}")
        if self.hours_per_day > 24 or self.days_per_year > 366:
            raise ValueError("a light cannot be on more than 24 h a day or 366 days a year")

    @property
    def annual_dose(self):
        """lux·h per year where the exposure is 1."""
        return self.lux * self.hours_per_day * self.days_per_year

    def spectrum_1lux(self, wavelengths=WAVELENGTHS):
        return light_spectrum(self.spectrum, wavelengths, self.uv_filter)


def _blockwise(a, fn, block=_BLOCK):
    """``fn`` applied to row blocks of ``a`` (n, 3), gathered as float32."""
    out = np.empty(a.shape, dtype=np.float32)
    for s0 in range(0, a.shape[0], block):
        out[s0:s0 + block] = fn(a[s0:s0 + block])
    return out


def _as_recipe(recipe):
    return get_recipe(recipe) if isinstance(recipe, str) else recipe


def _spectra_keys(lights):
    """Distinct (spectrum, uv_filter) pairs, in order of first appearance."""
    keys = []
    for light in lights:
        k = (light.spectrum, light.uv_filter)
        if k not in keys:
            keys.append(k)
    return keys


def _dose_rates(lights, exposure, n, keys):
    """Per-texel annual dose per distinct spectrum, (S, n) float32 lux·h a year."""
    rates = np.zeros((len(keys), n), dtype=np.float32)
    if exposure is not None:
        exposure = np.asarray(exposure)
        if exposure.size not in (n, n * len(lights)):
            raise ValueError(f"exposure must have one value per texel ({n}) or one map per "
                             f"light ({len(lights)} × {n}), got shape {exposure.shape}")
        exposure = exposure.reshape((1, n) if exposure.size == n else (len(lights), n))
    for k, light in enumerate(lights):
        row = rates[keys.index((light.spectrum, light.uv_filter))]
        if exposure is None:
            row += np.float32(light.annual_dose)
            continue
        e = exposure[0 if exposure.shape[0] == 1 else k]
        if not np.all(np.isfinite(e)) or np.any(e < 0):
            raise ValueError("exposure must be finite and >= 0")
        row += e.astype(np.float32) * np.float32(light.annual_dose)
    return rates


def _colour_keys(rgb_encoded):
    """Distinct colours (8 bits per channel, fewer if too many): (inverse, colours).

    ``rgb_encoded`` (n, 3) in [0, 1]; returns the index of each texel's colour and the
    (U, 3) colours (bin centres, encoded sRGB).
    """
    q = [np.clip(np.rint(rgb_encoded[:, ch] * 255.0), 0, 255).astype(np.int32)
         for ch in range(3)]
    for drop in range(0, 5):
        code = ((q[0] >> drop) << 16) | ((q[1] >> drop) << 8) | (q[2] >> drop)
        keys, inverse = np.unique(code, return_inverse=True)
        del code
        if keys.size <= _MAX_KEYS:
            break
    scale = 1 << drop
    colours = np.stack([(keys >> 16) & 255, (keys >> 8) & 255, keys & 255], -1)
    colours = (colours * scale + (scale - 1) / 2.0) / 255.0      # bin centres
    return inverse.astype(np.int32), np.clip(colours, 0.0, 1.0)


class TextureAger:
    """Per-texture precomputation for aging at any number of years.

    Parameters
    ----------
    rgb : array_like, shape (..., 3)
        Texel colours in [0, 1]: linear sRGB, or encoded sRGB with
        ``encoding="srgb"``. Any leading shape (an image is (H, W, 3)).
    recipe : Recipe or str
        The material's recipe (a name from :data:`.recipes.RECIPES`).
    lights : sequence of Light
        The lights; each contributes ``exposure × lux × hours × days`` lux·h a year.
    exposure : array_like, optional
        Relative exposure per texel: shape (...) shared by all lights, or
        (len(lights), ...) one map per light. Default: 1 everywhere.
    max_years : float
        Largest number of years :meth:`age` will be asked for (the grid's dose axis
        ends there).
    encoding : {"linear", "srgb"}
        Of ``rgb`` and of what :meth:`age` returns.
    settings : GridSettings
    cache : bool
        Use the on-disk grid cache.
    progress : callable(fraction, message), optional
    store : MutableMapping[str, bytes], optional
        Grid store consulted before the disk cache (see :func:`.grid.load_or_build`).
    """

    def __init__(self, rgb, recipe, lights, exposure=None, *, max_years=100.0,
                 encoding="linear", settings=GridSettings(), cache=True, progress=None,
                 store=None):
        self.recipe = _as_recipe(recipe)
        if not isinstance(self.recipe, Recipe):
            raise TypeError("recipe must be a Recipe or a recipe name")
        if encoding not in ("linear", "srgb"):
            raise ValueError(f"encoding must be 'linear' or 'srgb', got {encoding!r}")
        rgb = np.asarray(rgb, dtype=np.float32)
        if rgb.shape[-1] != 3:
            raise ValueError(f"rgb must have 3 channels on the last axis, got shape {rgb.shape}")
        if not np.all(np.isfinite(rgb)):
            raise ValueError("rgb contains NaN or infinite values")
        if not lights:
            raise ValueError("at least one light is needed")
        if not (np.isfinite(max_years) and max_years > 0):
            raise ValueError(f"max_years must be > 0, got {max_years!r}")
        self.shape = rgb.shape
        self.encoding = encoding
        self.max_years = float(max_years)
        self.original = rgb
        flat = rgb.reshape(-1, 3)
        n = flat.shape[0]
        say = progress or (lambda f, m: None)

        spectra_keys = _spectra_keys(lights)
        rates = _dose_rates(lights, exposure, n, spectra_keys)          # (S, n) float32
        self.rate = rates.sum(axis=0)                                   # lux·h per year
        self.spectra = np.stack([light_spectrum(s, WAVELENGTHS, uv) for s, uv in spectra_keys])

        max_dose = max(float(self.rate.max()) * self.max_years, 1.0)
        say(0.0, "building the fading grid")
        self.grid = load_or_build(self.recipe, self.spectra, max_dose, settings, cache=cache,
                                  progress=lambda f, m: say(0.6 * f, m), store=store)

        say(0.6, "unmixing colours")
        key, colours = _colour_keys(flat if encoding == "srgb" else
                                    _blockwise(flat, lambda b: srgb_encode(np.clip(b, 0, 1))))
        c = get_unmixer(self.recipe).unmix(colours, encoded=True, refine=2)
        say(0.85, f"change curves for {colours.shape[0]} colours")
        curves = self.grid.curves(c)                                  # (U, M, T, 3)
        U, M, T, _ = curves.shape
        # Planar table over (colour, mix node, dose interval): the change at the
        # interval's start and its increment, so a texel needs a + f * d.
        start = curves[:, :, :-1].reshape(-1, 3)
        step = (curves[:, :, 1:] - curves[:, :, :-1]).reshape(-1, 3)
        # one 24-byte row (start xyz, step xyz) per entry: a texel's six values share a
        # cache line, and a single gather of a 'void24' view fetches them together
        self._rows = np.ascontiguousarray(np.concatenate([start, step], axis=1),
                                          dtype=np.float32)                       # (K, 6)
        self._rows_void = self._rows.view(np.dtype((np.void, 24))).ravel()
        del curves, start, step
        self._T = T
        key *= M * (T - 1)
        if len(spectra_keys) == 1:
            self._offsets = key[None]
            self._weights = None
        else:
            self._offsets = np.empty((len(spectra_keys), n), dtype=np.int32)
            self._weights = np.empty((len(spectra_keys), n), dtype=np.float32)
            for s0 in range(0, n, _BLOCK):
                s1 = min(s0 + _BLOCK, n)
                total = self.rate[s0:s1]
                mix = np.where(total > 0, rates[:, s0:s1] / np.maximum(total, 1e-30), np.float32(0.0)).T
                mix[total <= 0, 0] = 1.0
                nodes, weights = simplex_interpolation(mix, self.grid.q)
                self._offsets[:, s0:s1] = key[s0:s1] + nodes.T * (T - 1)
                self._weights[:, s0:s1] = weights.T
        del rates, key
        # s = sigma * sqrt(years) is the texel's fractional position on the dose axis
        self._sigma = np.sqrt(self.rate / np.float32(self.grid.max_dose)) * np.float32(T - 1)
        self._XYZ = np.empty((3, n), dtype=np.float32)
        for s0 in range(0, n, _BLOCK):
            s1 = min(s0 + _BLOCK, n)
            lin = srgb_decode(flat[s0:s1]) if encoding == "srgb" else flat[s0:s1]
            self._XYZ[:, s0:s1] = linear_srgb_to_XYZ(lin).T
        self._to_rgb = (XYZ_to_linear_srgb(np.eye(3)).T).astype(np.float32)           # (3, 3)
        say(1.0, "ready")

    def dose(self, years):
        """Total dose per texel after ``years``, lux·h, shape of the texture."""
        return (self.rate * float(years)).reshape(self.shape[:-1])

    def _check_years(self, years):
        years = float(years)
        if not np.isfinite(years) or years < 0:
            raise ValueError(f"years must be a finite number >= 0, got {years!r}")
        if years > self.max_years * (1 + 1e-9):
            raise ValueError(f"years {years:g} is beyond this texture's max_years "
                             f"{self.max_years:g}; prepare it with a larger max_years")
        return years

    def _change(self, s0, s1, root_years):
        """``exp(change)`` for texels s0:s1 as (3, k) planes."""
        k = s1 - s0
        pos = self._sigma[s0:s1] * np.float32(root_years)
        i = pos.astype(np.int32)
        np.minimum(i, self._T - 2, out=i)
        f = pos
        f -= i                                        # fractional position, in place
        out = np.empty((3, k), dtype=np.float32)
        tmp = np.empty(k, dtype=np.float32)
        idx = np.empty(k, dtype=np.int32)
        acc = None if self._weights is None else np.zeros((3, k), dtype=np.float32)
        for v in range(self._offsets.shape[0]):
            np.add(self._offsets[v, s0:s1], i, out=idx)
            rows = np.take(self._rows_void, idx).view(np.float32).reshape(k, 6)
            for ch in range(3):
                np.multiply(rows[:, ch + 3], f, out=tmp)
                np.add(tmp, rows[:, ch], out=out[ch])
            if acc is not None:
                out *= self._weights[v, s0:s1]
                acc += out
        result = out if acc is None else acc
        np.exp(result, out=result)
        return result

    def age(self, years, out=None):
        """The texture after ``years`` (float32, same shape and encoding as the input).

        Zero years returns the original exactly. With ``out`` an (n, 4) float32
        array (Blender's RGBA pixel layout), the colour is written into its first
        three channels and the fourth is left alone.
        """
        years = self._check_years(years)
        n = self.original.size // 3
        rgba = out is not None and out.ndim == 2 and out.shape[1] == 4
        if years == 0:
            if out is None:
                return self.original.copy()
            (out[:, :3] if rgba else out.reshape(n, 3))[:] = self.original.reshape(n, 3)
            return out
        res = np.empty((n, 3), dtype=np.float32) if out is None else out
        root = np.sqrt(years)
        for s0 in range(0, n, _BLOCK):
            s1 = min(s0 + _BLOCK, n)
            XYZ = self._change(s0, s1, root)
            XYZ *= self._XYZ[:, s0:s1]
            target = res[s0:s1, :3] if rgba else res.reshape(n, 3)[s0:s1]
            if self.encoding == "srgb":
                rgb = self._to_rgb @ XYZ
                target[:] = srgb_encode(np.clip(rgb, 0.0, 1.0)).T
            else:
                np.matmul(XYZ.T, self._to_rgb.T, out=target)        # straight into RGBA
        return res if rgba else res.reshape(self.shape)


def age_image(rgb, years, recipe="printed-paper", lights=(Light(),), exposure=None,
              encoding="srgb", **kw):
    """Age one image for each of ``years``: a list of arrays like ``rgb``.

    A convenience over :class:`TextureAger` (see there for the parameters).
    """
    years = [float(y) for y in np.atleast_1d(years)]
    ager = TextureAger(rgb, recipe, list(lights), exposure, max_years=max(max(years), 1e-6),
                       encoding=encoding, **kw)
    return [ager.age(y) for y in years]


def age_image_exact(rgb, years, recipe="printed-paper", light=Light(), exposure=None,
                    encoding="srgb", levels=64, progress=None):
    """Age an image without the grid: one simulation per distinct colour (the reference).

    Distinct colours (as in :class:`TextureAger`) are unmixed the same way and each
    is simulated directly at the recipe's solver settings, recording every requested
    dose; the exposure map is quantised to ``levels`` levels (one batch each).
    Only one light spectrum (one :class:`Light`).

    Returns
    -------
    list of ndarray
        One image per entry of ``years``, like ``rgb``.
    """
    from .colorimetry import reflectance_to_XYZ
    from .fading import simulate

    recipe = _as_recipe(recipe)
    years = np.array([float(y) for y in np.atleast_1d(years)])
    if np.any(~np.isfinite(years)) or np.any(years < 0):
        raise ValueError("years must be finite numbers >= 0")
    rgb = np.asarray(rgb, dtype=np.float32)
    flat = rgb.reshape(-1, 3)
    n = flat.shape[0]
    say = progress or (lambda f, m: None)
    e = np.ones(n) if exposure is None else np.asarray(exposure, float).reshape(n)
    if not np.all(np.isfinite(e)) or np.any(e < 0):
        raise ValueError("exposure must be finite and >= 0")
    emax = float(e.max()) if e.size else 0.0
    level = np.zeros(n, dtype=np.int64) if emax == 0 else \
        np.rint(e / emax * (levels - 1)).astype(np.int64)
    enc = np.clip(flat if encoding == "srgb" else srgb_encode(np.clip(flat, 0, 1)), 0, 1)
    key, colours = _colour_keys(enc)
    c_unmixed = get_unmixer(recipe).unmix(colours, encoded=True, refine=2)
    A, S, ground = recipe.optics()
    base = recipe.base_concentrations()
    E0 = light.spectrum_1lux()
    lin = srgb_decode(flat) if encoding == "srgb" else flat
    XYZ = linear_srgb_to_XYZ(lin)
    ratio = np.ones((years.size, n, 3))
    groups = np.unique(level)
    for g_i, g in enumerate(groups):
        say(g_i / groups.size, f"simulating exposure level {g_i + 1}/{groups.size}")
        texels = np.nonzero(level == g)[0]
        dose_rate = light.annual_dose * (g / (levels - 1) * emax if emax else 0.0)
        doses = years * dose_rate
        if dose_rate == 0 or not np.any(doses > 0):
            continue
        used, inverse = np.unique(key[texels], return_inverse=True)
        conc = np.tile(base, (used.size, 1))
        for k, name in enumerate(recipe.unmixed):
            conc[:, recipe.index(name)] = c_unmixed[used, k]
        positive = np.unique(doses[doses > 0])
        r = simulate(A, S, conc, recipe.sensitivity(), E0, ground, WAVELENGTHS,
                     thickness=recipe.thickness, duration=positive[-1], record=positive,
                     yields=recipe.yield_matrix(), **recipe.solver())
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
        lin_aged = XYZ_to_linear_srgb(XYZ * ratio[y_i])
        res = srgb_encode(np.clip(lin_aged, 0, 1)) if encoding == "srgb" else lin_aged
        out.append(res.astype(np.float32).reshape(rgb.shape))
    return out
