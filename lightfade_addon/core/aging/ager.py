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

from ..fading.cache import load_or_build
from ..colour.colorimetry import checked_rgb, srgb_decode, srgb_encode, XYZ_to_linear_srgb
from ..colour.gamut import encode_in_gamut, out_of_gamut
from ..fading.grid import GridSettings
from ..fading.lattice import grid_max_dose
from ..fading.lights import HOURS_PER_YEAR_DEFAULT, Light, dose_rates, spectra_keys
from ..fading.recipes import Recipe, get_recipe
from .restore import Prior, log_initial, restore
from ..fading.spectra import WAVELENGTHS, light_spectrum
from .table import AgingTable, Texels, evaluate, evaluate_change, max_keys, texel_positions
from .texels import texel_concentrations
from ..fading.unmix import get_unmixer

__all__ = ["Light", "Prior", "TextureAger", "age_image", "age_image_exact",
           "HOURS_PER_YEAR_DEFAULT"]

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

    max_rate : float, optional
        Largest annual dose (lux·h) the table must cover besides the texels' own (the
        same exposure seen at another resolution, e.g. by a node group).
    table_entries : int, optional
        Most entries (key × light-mix slot × dose node) of the aging table; default
        :data:`.table.TABLE_TEXELS`. Fewer entries, fewer keys: coarser colour bins.

    Attributes
    ----------
    lost : ndarray of bool or None
        With ``prior``: texels whose original colour the prior light destroyed.
    """

    def __init__(self, rgb, recipe, lights, exposure=None, *, max_years=100.0,
                 encoding="linear", settings=GridSettings(), cache=True, progress=None,
                 store=None, prior=None, max_rate=None, table_entries=None):
        self.recipe = _as_recipe(recipe)
        if not isinstance(self.recipe, Recipe):
            raise TypeError("recipe must be a Recipe or a recipe name")
        if encoding not in ("linear", "srgb"):
            raise ValueError(f"encoding must be 'linear' or 'srgb', got {encoding!r}")
        rgb = checked_rgb(rgb)
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

        top = max(float(self.rate.max()), float(max_rate or 0.0))
        max_dose = grid_max_dose(top * self.max_years)
        say(0.0, "building the fading grid")
        self.grid = load_or_build(self.recipe, self.spectra, max_dose, settings, cache=cache,
                                  progress=lambda f, m: say(0.6 * f, m), store=store)

        say(0.6, "unmixing colours")
        unmixer = get_unmixer(self.recipe)
        M, T = self.grid.change.shape[:2]
        S = len(keys)
        key, c = texel_concentrations(
            flat if encoding == "srgb" else
            _blockwise(flat, lambda b: srgb_encode(np.clip(b, 0, 1))), unmixer,
            max_keys=max_keys(S, self.grid.q, T, table_entries))
        say(0.85, f"change curves for {c.shape[0]} colour{'s' * (c.shape[0] != 1)}")
        curves = self.grid.curves(c, log_initial(self.grid, unmixer, c))     # (U, M, T, 3)
        self.table = AgingTable.from_curves(curves, self.grid.max_dose, S, self.grid.q)
        del curves
        lin = _blockwise(flat, srgb_decode) if encoding == "srgb" else flat
        self.texels = Texels.from_linear(key, rates, lin)
        del rates, key
        self._positions = texel_positions(self.table, self.texels)
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

    def out_of_range(self, years):
        """Mask (texture shape) of texels the gamut rule maps back at ``years``.

        The modelled aged colour in linear sRGB has a channel outside [0, 1] there
        (:func:`.gamut.out_of_gamut`); :meth:`age` maps them in. For reports.
        """
        years = self._check_years(years)
        n = self.original.size // 3
        if years == 0:
            return np.zeros(self.shape[:-1], dtype=bool)
        change = evaluate_change(self.table, self._positions, years)
        XYZ = np.exp(change) * self.texels.XYZ
        mask = out_of_gamut((XYZ_to_linear_srgb(np.eye(3)).T @ XYZ).T)
        return mask.reshape(n).reshape(self.shape[:-1])

    def age(self, years, out=None):
        """The texture after ``years`` (float32, same shape and encoding as the input).

        Aged colours are mapped into [0, 1] keeping hue (:func:`.gamut.into_gamut`,
        the rule of every path): :func:`.table.evaluate` of this texture's aging
        table. Zero years returns the original exactly (as mapped into [0, 1] on
        construction). With ``out`` an (n, 4) float32 array (Blender's RGBA pixel
        layout), the colour is written into its first three channels and the fourth
        is left alone.
        """
        years = self._check_years(years)
        n = self.original.size // 3
        rgba = out is not None and out.ndim == 2 and out.shape[1] == 4
        if years == 0:
            if out is None:
                return self.original.copy()
            (out[:, :3] if rgba else out.reshape(n, 3))[:] = self.original.reshape(n, 3)
            return out
        target = out if rgba else (np.empty((n, 3), dtype=np.float32) if out is None
                                   else out.reshape(n, 3))
        evaluate(self.table, self.texels, years, self._positions, out=target)
        if self.encoding == "srgb":
            target[:, :3] = srgb_encode(target[:, :3])
        if rgba:
            return out
        return target.reshape(self.shape)


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
        from ..fading.exact import age_image_exact

        return age_image_exact
    raise AttributeError(name)
