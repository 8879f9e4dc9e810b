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

import numpy as np

from .cache import load_or_build
from .colorimetry import linear_srgb_to_XYZ, srgb_decode, srgb_encode, XYZ_to_linear_srgb
from .gamut import encode_in_gamut, into_gamut_planes, out_of_gamut
from .grid import GridSettings
from .lattice import DOSE_POWER, dose_index, grid_max_dose, simplex_interpolation
from .lights import HOURS_PER_YEAR_DEFAULT, Light, dose_rates, spectra_keys
from .recipes import Recipe, get_recipe
from .restore import Prior, log_initial, restore
from .spectra import WAVELENGTHS, light_spectrum
from .texels import texel_concentrations
from .unmix import get_unmixer

__all__ = ["Light", "Prior", "TextureAger", "age_image", "age_image_exact",
           "HOURS_PER_YEAR_DEFAULT"]

#: Rows (a key's change at one mix node and dose node: three float16, 6 bytes) of a
#: texture's aging table: 101 MB, 258,111 keys of one light spectrum and 65 dose nodes.
#: (Half-precision logs are within 0.1 % of float32; a float32 table of as many keys
#: updated a 2048² texture no faster and took twice the memory.)
TABLE_ROWS = 1 << 24
#: Texels updated per block in :meth:`TextureAger.age` (bounds the temporaries).
_BLOCK = 1 << 18


def _blockwise(a, fn, block=_BLOCK):
    """``fn`` applied to row blocks of ``a`` (n, 3), gathered as float32."""
    out = np.empty(a.shape, dtype=np.float32)
    for s0 in range(0, a.shape[0], block):
        out[s0:s0 + block] = fn(a[s0:s0 + block])
    return out


def _in_range(rgb, encoding):
    """``rgb`` itself when inside [0, 1], else a copy mapped in by the gamut rule."""
    if not out_of_gamut(rgb).any():
        return rgb
    lin = rgb if encoding == "linear" else srgb_decode(np.clip(rgb, 0.0, None))
    return encode_in_gamut(np.array(lin, dtype=np.float32), encoding).astype(np.float32)


def _root(years):
    return float(years) ** (1.0 / DOSE_POWER)


def _as_recipe(recipe):
    return get_recipe(recipe) if isinstance(recipe, str) else recipe


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
        Grid store consulted before the disk cache (see :func:`.cache.load_or_build`).
    prior : Prior, optional
        The texture is already old (:class:`.restore.Prior`: years, lights,
        exposure): it is first restored to new (:func:`.restore.restore`), and
        :meth:`age` ages from new, so 0 years is the restored texture. The lost
        pixels are in :attr:`lost`.

    Attributes
    ----------
    lost : ndarray of bool or None
        With ``prior``: texels whose original colour the prior light destroyed.
    """

    def __init__(self, rgb, recipe, lights, exposure=None, *, max_years=100.0,
                 encoding="linear", settings=GridSettings(), cache=True, progress=None,
                 store=None, prior=None):
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
            raise ValueError(f"max_years must be a finite number > 0, got {max_years!r}")
        self.shape = rgb.shape
        self.encoding = encoding
        self.max_years = float(max_years)
        say = progress or (lambda f, m: None)
        self.lost = None
        if prior is not None:
            restored = restore(rgb, prior.years, self.recipe, prior.lights, prior.exposure,
                               encoding, settings, cache, store,
                               lambda f, m: say(0.3 * f, f"restoring: {m}"))
            rgb, self.lost = restored.image, restored.lost
            outer = say

            def say(f, m):
                outer(0.3 + 0.7 * f, m)
        self.original = _in_range(rgb, encoding)
        flat = self.original.reshape(-1, 3)
        n = flat.shape[0]

        keys = spectra_keys(lights)
        rates = dose_rates(lights, exposure, n, keys)          # (S, n) float32
        self.rate = rates.sum(axis=0)                                   # lux·h per year
        self.spectra = np.stack([light_spectrum(s, WAVELENGTHS, uv) for s, uv in keys])

        max_dose = grid_max_dose(float(self.rate.max()) * self.max_years)
        say(0.0, "building the fading grid")
        self.grid = load_or_build(self.recipe, self.spectra, max_dose, settings, cache=cache,
                                  progress=lambda f, m: say(0.6 * f, m), store=store)

        say(0.6, "unmixing colours")
        unmixer = get_unmixer(self.recipe)
        M, T = self.grid.change.shape[:2]
        key, c = texel_concentrations(
            flat if encoding == "srgb" else
            _blockwise(flat, lambda b: srgb_encode(np.clip(b, 0, 1))), unmixer,
            max_keys=max(TABLE_ROWS // (M * T), 1))
        say(0.85, f"change curves for {c.shape[0]} colour{'s' * (c.shape[0] != 1)}")
        curves = self.grid.curves(c, log_initial(self.grid, unmixer, c))     # (U, M, T, 3)
        U, M, T, _ = curves.shape
        # Planar table over (colour, mix node, dose node): a texel at fractional position
        # i + f needs the values at nodes i and i + 1, 12 adjacent bytes: two gathers of
        # a 'void6' view, the second from the cache line the first brought in.
        self._values = np.ascontiguousarray(curves.reshape(-1, 3), dtype=np.float16)
        self._nodes = self._values.view(np.dtype((np.void, 6))).ravel()
        del curves
        self._T = T
        key *= M * T
        if len(keys) == 1:
            self._offsets = key[None]
            self._weights = None
        else:
            self._offsets = np.empty((len(keys), n), dtype=np.int32)
            self._weights = np.empty((len(keys), n), dtype=np.float32)
            for s0 in range(0, n, _BLOCK):
                s1 = min(s0 + _BLOCK, n)
                total = self.rate[s0:s1]
                mix = np.where(total > 0, rates[:, s0:s1] / np.maximum(total, 1e-30), np.float32(0.0)).T
                mix[total <= 0, 0] = 1.0
                nodes, weights = simplex_interpolation(mix, self.grid.q)
                self._offsets[:, s0:s1] = key[s0:s1] + nodes.T * T
                self._weights[:, s0:s1] = weights.T
        del rates, key
        # s = sigma * years**(1/DOSE_POWER) is the texel's fractional position on the dose axis
        self._sigma = (dose_index(self.rate / np.float32(self.grid.max_dose), T)
                       .astype(np.float32))
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
        # root_years = years ** (1 / DOSE_POWER): a texel's position on the dose axis is
        # sigma * root_years, since the rate is constant per texel
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
            lo = np.take(self._nodes, idx).view(np.float16).reshape(k, 3).astype(np.float32)
            idx += 1
            hi = np.take(self._nodes, idx).view(np.float16).reshape(k, 3).astype(np.float32)
            for ch in range(3):                       # v_i + f (v_i+1 - v_i)
                np.subtract(hi[:, ch], lo[:, ch], out=tmp)
                tmp *= f
                np.add(tmp, lo[:, ch], out=out[ch])
            if acc is not None:
                out *= self._weights[v, s0:s1]
                acc += out
        result = out if acc is None else acc
        np.exp(result, out=result)
        return result

    def out_of_range(self, years):
        """Mask (texture shape) of texels the gamut rule maps back at ``years``.

        The modelled aged colour in linear sRGB has a channel outside [0, 1] there
        (:func:`.gamut.out_of_gamut`); :meth:`age` maps them in. For reports.
        """
        years = self._check_years(years)
        n = self.original.size // 3
        mask = np.zeros(n, dtype=bool)
        if years > 0:
            for s0 in range(0, n, _BLOCK):
                s1 = min(s0 + _BLOCK, n)
                XYZ = self._change(s0, s1, _root(years)) * self._XYZ[:, s0:s1]
                mask[s0:s1] = out_of_gamut((self._to_rgb @ XYZ).T)
        return mask.reshape(self.shape[:-1])

    def age(self, years, out=None):
        """The texture after ``years`` (float32, same shape and encoding as the input).

        Aged colours are mapped into [0, 1] keeping hue (:func:`.gamut.into_gamut`,
        the rule of every path). Zero years returns the original exactly (as
        mapped into [0, 1] on construction). With ``out`` an (n, 4) float32
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
        root = _root(years)
        for s0 in range(0, n, _BLOCK):
            s1 = min(s0 + _BLOCK, n)
            XYZ = self._change(s0, s1, root)
            XYZ *= self._XYZ[:, s0:s1]
            target = res[s0:s1, :3] if rgba else res.reshape(n, 3)[s0:s1]
            rgb = into_gamut_planes(self._to_rgb @ XYZ)            # (3, k), in [0, 1]
            target[:] = (srgb_encode(rgb) if self.encoding == "srgb" else rgb).T
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


def __getattr__(name):
    if name == "age_image_exact":          # the reference path lives in .exact
        from .exact import age_image_exact

        return age_image_exact
    raise AttributeError(name)
