"""A frame image as tiles, each at the level of detail the camera resolves there.

One level per object (the nearest point it shows) keeps a floor running from under the
camera to the far wall, and every object partly in view, whole everywhere. So the frame
image is cut into tiles (:data:`.detail.TILE` texels a side) and each tile gets its own
level (:func:`.detail.object_levels`): the coarsest at which every render pixel that
sees its part of the surface spans at least two frame texels, or the hidden level where
the camera does not see it. Only the tiles' own texels are aged — a tile at level ``L``
holds ``(tile / 2^L)²`` texels, block means of the texture (:func:`block_mean`), a
block of two colours as its two parts (:class:`Pyramid`) — and the image is written at
the finest level of its tiles, each coarser tile's texels repeated ``2^(L − base)``
times each way (:meth:`Mosaic.expand`). A pixel spans at least two of a tile's texels,
so it averages whole repeated blocks as it would a coarser image's bilinear lookups.

The samples are the tiles' texels in a fixed order (by level, then tile), so the
colours, the annual doses and the aged codes of one image line up
(:meth:`Mosaic.gather`).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from ...core.colour.colorimetry import srgb_decode
from ...core.colour.srgb8 import encode_srgb_f32, srgb_code_floats

__all__ = ["Layout", "Mosaic", "Pyramid", "block_mean"]


def block_mean(rgba, L):
    """(H / 2^L, W / 2^L, C) float32 means of ``2^L × 2^L`` blocks of ``rgba`` (H, W, C)
    (linear colour: what a pixel's samples average to), as a mipmap's level ``L``."""
    if L == 0:
        return rgba
    f = 1 << L
    H, W, C = rgba.shape
    return rgba.reshape(H // f, f, W // f, f, C).mean(axis=(1, 3), dtype=np.float32)


@dataclass(frozen=True, eq=False)
class Mosaic:
    """The level of each tile of a texture.

    Attributes
    ----------
    levels : ndarray, shape (ny, nx), int8
        Level of each tile (row 0 at the texture's first row).
    tile : int
        Tile side at full resolution, texels (a power of two, at least ``2^max(levels)``).
    """

    levels: np.ndarray
    tile: int

    @property
    def size(self):
        """(W, H) of the texture at full resolution."""
        ny, nx = self.levels.shape
        return nx * self.tile, ny * self.tile

    @property
    def base(self):
        """The finest level of the tiles: the image is written at it."""
        return int(self.levels.min())

    @functools.cached_property
    def key(self):
        """Hashable: the tiles and their levels."""
        return ("tiles", self.tile, self.levels.shape, self.levels.tobytes())

    @functools.cached_property
    def order(self):
        """``[(level, tile indices (k,))]``: the samples' order."""
        flat = self.levels.reshape(-1)
        return [(int(L), np.flatnonzero(flat == L)) for L in np.unique(flat)]

    @property
    def n(self):
        """Texels aged: ``Σ (tile / 2^L)²`` over the tiles."""
        return sum(len(at) * (self.tile >> L) ** 2 for L, at in self.order)

    def gather(self, at_level):
        """(n, C) samples: the texels of every tile at its level, from ``at_level(L)``
        ((H / 2^L, W / 2^L, C): the texture's values at level ``L``), in :attr:`order`."""
        ny, nx = self.levels.shape
        out = []
        for L, at in self.order:
            values = at_level(L)
            t = self.tile >> L
            C = values.shape[-1]
            tiles = values.reshape(ny, t, nx, t, C).transpose(0, 2, 1, 3, 4).reshape(-1, t, t, C)
            out.append(tiles[at].reshape(-1, C))
        return np.concatenate(out) if len(out) > 1 else out[0]

    def expand(self, samples):
        """(H / 2^base, W / 2^base, C) image of ``samples`` (n, C) (:meth:`gather`'s
        order): each tile's texels repeated ``2^(L − base)`` times each way."""
        ny, nx = self.levels.shape
        base, C = self.base, samples.shape[-1]
        tb = self.tile >> base
        out = np.empty((ny, tb, nx, tb, C), dtype=samples.dtype)
        start = 0
        for L, at in self.order:
            t, f = self.tile >> L, 1 << (L - base)
            chunk = samples[start:start + len(at) * t * t].reshape(-1, t, 1, t, 1, C)
            start += len(at) * t * t
            rows, cols = np.divmod(at, nx)
            out[rows, :, cols] = np.broadcast_to(chunk, (len(at), t, f, t, f, C)).reshape(
                -1, tb, tb, C)
        return out.reshape(ny * tb, nx * tb, C)


#: A block's two parts are aged apart where ``w (1 − w) Δ`` exceeds this: ``Δ`` the
#: largest difference of their sRGB-encoded means, ``w`` the brighter part's share of
#: the texels (:meth:`Pyramid.split`; the bias of aging the mean of two colours grows
#: with the variance of the mix, ``w (1 − w) Δ²``, and with ``Δ`` here once more, so
#: that a single dot of a very different colour counts). Measured, ten-material room
#: at 25 years, ΔE00 of 8 × 8-pixel means against the live render at 128 spp, p99 /
#: max: 0.01 gives 0.41–0.43 / 0.71–0.76 (22 % of the samples split), 0.005 gives
#: 0.43–0.44 / 0.61–0.62 (39 %), none 0.69 / 1.45; two seeds of the live render differ
#: by 0.48 / 0.79.
MIXED = 0.01
#: Linear luminance of sRGB's primaries (ITU-R BT.709).
_LUMA = np.array([0.2126, 0.7152, 0.0722], dtype=np.float32)


@dataclass(frozen=True, eq=False)
class Layout:
    """The colours a frame image ages under a :class:`Mosaic`: one sample per texel of
    each tile at its level — the block's mean, or where the block mixes two colours
    (:meth:`Pyramid.split`) its darker part's mean — and, after them, the brighter part's
    mean of each mixed block.

    Attributes
    ----------
    mosaic : Mosaic
    mixed : ndarray, shape (m,), int
        The samples (of the first ``n``) whose block is mixed.
    weight : ndarray, shape (m,), float32
        The brighter part's share of each mixed block.
    """

    mosaic: Mosaic
    mixed: np.ndarray
    weight: np.ndarray

    def extend(self, values):
        """(n + m, C) of per-sample ``values`` (n, C) (:meth:`Mosaic.gather`): each mixed
        block's brighter part takes its block's value (an annual dose)."""
        return np.concatenate([values, values[self.mixed]])

    def image(self, codes):
        """The frame image ((H / 2^base, W / 2^base, 4), :meth:`Mosaic.expand`) of the
        samples' aged 8-bit sRGB codes over 255 ``codes`` (n + m, 4; written over): each
        mixed block the mean of its two parts' aged linear colours, weighted by their
        texels, encoded again (within a code of the mean of the unrounded colours)."""
        n = len(codes) - len(self.mixed)
        out = codes[:n]                                  # in place: the caller's buffer
        if len(self.mixed):
            first = _linear(out[self.mixed, :3])
            first += self.weight[:, None] * (_linear(codes[n:, :3]) - first)
            out[self.mixed, :3] = srgb_code_floats(first)
        return self.mosaic.expand(out)


def _linear(codes):
    """Linear values of 8-bit sRGB codes over 255 (IEC 61966-2-1, :func:`..core.colour.
    colorimetry.srgb_decode` of each of the 256 codes)."""
    if not _DECODED:
        _DECODED.append(srgb_decode(np.arange(256) / 255.0).astype(np.float32))
    return np.take(_DECODED[0], np.rint(codes * np.float32(255.0)).astype(np.int32))


_DECODED = []


class Pyramid:
    """One colour's block means (:func:`block_mean`) at the levels asked (level
    0 the colour itself, each level from the one below it), and the samples a frame
    image ages under the last :class:`Mosaic` asked (:class:`Layout`): held per frame
    image while its colour is the same, so that a years value or a camera move reads no
    texture again.

    Aging a block's mean colour is not the mean of its aged texels where the block
    mixes very different colours (the edge of a white dot on a dyed ground: measured,
    up to 21 ΔE00 on a block of four texels of the ten-material room's floor at 25
    years): so such a block is split in two at its mean luminance and each part aged
    apart (:meth:`split`), exact for a block of two colours."""

    def __init__(self, colour, key):
        self.key = key                        # the colour's twin key (:func:`.runtime.twin_key`)
        self._levels = {0: colour}
        self._splits = {}
        self._layout = self._held = None

    def at(self, L):
        """(H / 2^L, W / 2^L, 4) block means, read-only."""
        if L not in self._levels:
            means = block_mean(self.at(L - 1), 1)
            means.flags.writeable = False
            self._levels[L] = means
        return self._levels[L]

    def split(self, L):
        """``(first (h, w, 4), second (h, w, 4), weight (h, w), mixed (h, w))`` of the
        ``2^L × 2^L`` blocks: each block's texels split at the block's mean luminance
        into a darker and a brighter part; where they differ enough (:data:`MIXED`)
        the block is ``mixed``, ``first`` the darker part's mean, ``second`` the
        brighter's and ``weight`` its share of the texels; elsewhere ``first`` is the
        block's mean."""
        if L not in self._splits:
            f, colour = 1 << L, self._levels[0]
            H, W, C = colour.shape
            blocks = colour.reshape(H // f, f, W // f, f, C)
            luma = blocks[..., :3] @ _LUMA
            bright = luma > luma.mean(axis=(1, 3), keepdims=True)
            count = bright.sum(axis=(1, 3), dtype=np.float32)
            high = np.einsum("ijkl,ijklc->ikc", bright.astype(np.float32), blocks)
            mean = self.at(L)
            low = (mean * np.float32(f * f) - high) / np.maximum(f * f - count, 1)[..., None]
            high /= np.maximum(count, 1)[..., None]
            apart = np.abs(encode_srgb_f32(high[..., :3]) - encode_srgb_f32(low[..., :3]))
            share = count / np.float32(f * f)
            mixed = share * (1 - share) * apart.max(axis=-1) > MIXED
            first = np.where(mixed[..., None], low, mean)
            self._splits[L] = (first, high, share, mixed)
        return self._splits[L]

    def samples(self, mosaic):
        """``(layout, samples (n + m, 1, 4), their twin key)``: what a frame image ages
        under ``mosaic`` (:class:`Layout`), whose key names the mosaic (the annual doses
        are gathered the same way: :func:`.runtime.aged_rgb`)."""
        if self._layout != mosaic.key:
            *inputs, _shape, digest = self.key
            level = lambda L: self.at(0) if L == 0 else self.split(L)[0]   # noqa: E731
            first = mosaic.gather(level)
            mixed = np.flatnonzero(mosaic.gather(
                lambda L: np.zeros(self.at(L).shape[:2] + (1,), bool) if L == 0
                else self.split(L)[3][..., None])[:, 0])
            second = mosaic.gather(lambda L: self.at(L) if L == 0 else self.split(L)[1])
            weight = mosaic.gather(lambda L: np.zeros(self.at(L).shape[:2] + (1,), np.float32)
                                   if L == 0 else self.split(L)[2][..., None])[mixed, 0]
            samples = np.concatenate([first, second[mixed]])[:, None, :]
            samples.flags.writeable = False
            layout = Layout(mosaic, mixed, weight)
            key = (*inputs, mosaic.key, (digest, mosaic.key))
            self._layout, self._held = mosaic.key, (layout, samples, key)
        return self._held
