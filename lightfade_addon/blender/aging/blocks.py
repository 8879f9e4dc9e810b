"""A frame image at a coarser level: its texture's blocks, each aged as a whole or as
its two parts.

A frame image written at level ``L`` (:mod:`.detail`) holds one texel for each block of
``2^L × 2^L`` texels of its texture. Aging a block's mean colour is not the mean of its
aged texels where the block mixes very different colours: at the edge of a white dot on
a dyed ground the mean unmixes to another dye (measured on the ten-material room's floor
at 25 years: up to 21 ΔE00 on one 2 × 2 block). So each block is split at its mean
luminance into a darker and a brighter part; where the two differ enough
(:data:`MIXED`) both parts are aged and mixed by their texels (exact for a block of two
colours), elsewhere the block's mean is aged (:class:`Pyramid`). The samples aged are
the level's blocks (row by row), then the brighter parts of the mixed ones
(:class:`Layout`), so that the colours, the annual doses and the aged codes line up.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...core.colour.gamut import LUMA
from ...core.colour.srgb8 import encode_srgb_f32, srgb_code_floats
from ..pixels import decode_srgb_bytes

__all__ = ["Layout", "Pyramid", "block_mean"]


def block_mean(rgba, L):
    """(H / 2^L, W / 2^L, C) float32 means of ``2^L × 2^L`` blocks of ``rgba`` (H, W, C)
    (linear colour: what a pixel's samples average to), as a mipmap's level ``L``."""
    if L == 0:
        return rgba
    f = 1 << L
    H, W, C = rgba.shape
    return rgba.reshape(H // f, f, W // f, f, C).mean(axis=(1, 3), dtype=np.float32)


#: A block's two parts are aged apart where ``w (1 − w) Δ`` exceeds this: ``Δ`` the
#: largest difference of their sRGB-encoded means, ``w`` the brighter part's share of
#: the texels (:meth:`Pyramid.split`; the bias of aging the mean of two colours grows
#: with the variance of the mix, ``w (1 − w) Δ²``, and with ``Δ`` here once more, so
#: that a single dot of a very different colour counts). Measured, ten-material room
#: at 25 years, a texel a pixel, ΔE00 of 8 × 8-pixel means against the live render at
#: 128 spp (two seeds), p99 / max: none split 0.89–0.91 / 1.36–1.46; 0.01 gives
#: 0.50–0.54 / 0.75–0.83; 0.005 gives 0.45–0.46 / 0.57–0.59 at half as much again of
#: the render handler's CPU; two seeds of the live render differ by 0.48 / 0.79.
MIXED = 0.01


@dataclass(frozen=True, eq=False)
class Layout:
    """The colours a frame image at a level ages: one sample per block, row by row — the
    block's mean, or where the block mixes two colours (:meth:`Pyramid.split`) its
    darker part's mean — and, after them, the brighter part's mean of each mixed block.

    Attributes
    ----------
    shape : tuple
        (h, w) of the level.
    mixed : ndarray, shape (m,), int
        The blocks (of the first ``n = h · w`` samples) that are mixed.
    weight : ndarray, shape (m,), float32
        The brighter part's share of each mixed block.
    """

    shape: tuple
    mixed: np.ndarray
    weight: np.ndarray

    def extend(self, values):
        """(n + m, C) of per-block ``values`` (n, C): each mixed block's brighter part
        takes its block's value (an annual dose)."""
        return np.concatenate([values, values[self.mixed]])

    def image(self, codes):
        """The frame image ((h, w, 4)) of the samples' aged 8-bit sRGB codes over 255
        ``codes`` (n + m, 4; written over): each mixed block the mean of its two parts'
        aged linear colours, weighted by their texels, encoded again (within a code of
        the mean of the unrounded colours), and the mean of their alphas."""
        n = len(codes) - len(self.mixed)
        out = codes[:n]                                  # in place: the caller's buffer
        if len(self.mixed):
            w = self.weight[:, None]
            first = decode_srgb_bytes(out[self.mixed, :3])
            first += w * (decode_srgb_bytes(codes[n:, :3]) - first)
            alpha = out[self.mixed, 3:]                  # alpha is linear: mixed as it is
            alpha += w * (codes[n:, 3:] - alpha)
            out[self.mixed] = np.concatenate([srgb_code_floats(first), alpha], axis=1)
        return out.reshape(*self.shape, -1)


class Pyramid:
    """One colour's block means (:func:`block_mean`) at the levels asked (level 0 the
    colour itself, each level from the one below it), their splits (:meth:`split`) and
    the samples a frame image ages at the last level asked (:meth:`samples`): held per
    frame image while its colour is the same, so that a years value or a camera move
    reads no texture again."""

    def __init__(self, colour, key):
        self.key = key                        # the colour's twin key (:func:`.runtime.twin_key`)
        self._levels = {0: colour}
        self._splits = {}
        self._level = self._held = None

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
            luma = blocks[..., :3] @ LUMA
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

    def samples(self, L):
        """``(layout, samples (n + m, 1, 4), their twin key)``: what a frame image at
        level ``L`` >= 1 ages (:class:`Layout`); the key names the level (the annual
        doses are sampled at the level and extended the same way: :func:`.runtime.
        aged_rgb`)."""
        if self._level != L:
            *inputs, _shape, digest = self.key
            first, second, weight, mixed = self.split(L)
            at = np.flatnonzero(mixed)
            samples = np.concatenate([first.reshape(-1, 4), second.reshape(-1, 4)[at]])[:, None, :]
            samples.flags.writeable = False
            layout = Layout(mixed.shape, at, weight.reshape(-1)[at])
            key = (*inputs, ("level", L, mixed.shape), (digest, L))
            self._level, self._held = L, (layout, samples, key)
        return self._held
