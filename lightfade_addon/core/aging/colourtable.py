"""The colour-cube aging table: one per recipe and set of light spectra, and its evaluator.

The modelled change of a colour, ``log(XYZ_aged / XYZ_initial)``, is tabulated over

* the **colour cube**: ``N`` nodes per channel of the encoded colour
  ``u = clip(rgb_linear, 0, 1) ** (1 / gamma)``;
* the **dose**, an absolute axis in lux·h shared by every texel: node 0 at 0, node
  ``t >= 1`` at ``low · 10 ** ((t - 1) / per_decade)``, up to the dose where the
  recipe has stopped changing (the table is cut there, so huge doses saturate
  cleanly: :func:`dose_position`);
* the **light mix**: the slots of :func:`.table.simplex_slots` over the set's spectra.

Nothing in the table belongs to a texture: every material aged with the same recipe
under the same spectra shares it, and it is looked up from the artist's own colour at
each shading point, so procedural graphs, UDIMs and fine detail age at full detail.
Per texel only the dose rates remain (the exposure maps themselves).

The aged colour (linear sRGB ``rgb``, annual doses ``rate_s`` lux·h, ``years``)::

    d = years · Σ_s rate_s                     s = dose_position(d)          (lux·h)
    change = Σ_v w_v · lerp_b lerp_t bilerp_rg table[slot_v, t, b, g, r]
    rgb_aged = into_gamut(M⁻¹ · (M · rgb) · exp(change))

bilinear over (r, g) (a Linear image lookup in the node group), linear over ``b``
and the dose by hand, barycentric over the light mix (:func:`.table.simplex_slots`).
At zero years the colour itself comes back, unless the table carries a *history*
(a texture that is already old, :class:`.restore.Prior`): its change at dose 0 is
then the restoration ``log(XYZ_new / XYZ_seen)``, built over the seen colour.

:func:`evaluate` is the numpy evaluator; ``blender/aging/group.py`` builds the node
group that computes the same from :func:`atlas_pixels`, and the two are tested
against each other texel by texel.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

import numpy as np

from ..colour.colorimetry import XYZ_to_linear_srgb, linear_srgb_to_XYZ
from ..colour.gamut import into_gamut_planes
from .table import in_blocks, simplex_slots

__all__ = ["ColourTable", "atlas_layout", "atlas_pixels", "cube_colours", "dose_position",
           "evaluate", "mix_resolution", "table_from_atlas"]

#: Texels evaluated per block (bounds the temporaries) and threads.
_BLOCK = 1 << 16
_THREADS = max(1, min(4, os.cpu_count() or 1))
#: Tallest atlas image (a GPU's texture limit).
MAX_ATLAS_HEIGHT = 16384


def mix_resolution(S):
    """Light-mix lattice resolution ``q`` for ``S`` spectra: 3 slots for two spectra,
    9 (6 used) for three, 8 (4 used) for four: the table grows with the slots."""
    return {1: 1, 2: 2, 3: 2}.get(S, 1)


@dataclass(frozen=True)
class ColourTable:
    """The change over colour cube × dose × light-mix slot.

    Attributes
    ----------
    values : ndarray, shape (slots, T, N, N, N, 3), float16
        ``log(XYZ_aged / XYZ_initial)``, axes slot, dose node, b, g, r.
    doses : ndarray, shape (T,)
        lux·h of each dose node.
    gamma, per_decade, low_dose : float
        As :class:`TableSettings`.
    q, S : int
        Mix lattice resolution and number of spectra.
    history : bool
        Built over seen colours of an already aged texture (dose 0 is the restoration).
    key : str
    lost : ndarray of bool, shape (N, N, N) or None
        With a history: cube nodes whose original the prior light erased.
    """

    values: np.ndarray
    doses: np.ndarray
    gamma: float
    per_decade: float
    low_dose: float
    q: int
    S: int
    history: bool
    key: str
    lost: np.ndarray | None = None

    @property
    def side(self):
        return self.values.shape[2]

    @property
    def T(self):
        return self.values.shape[1]

    @property
    def slots(self):
        return self.values.shape[0]

    @property
    def max_dose(self):
        return float(self.doses[-1])

    def info(self):
        """Everything but the values, as plain numbers (an image's custom property)."""
        return dict(side=self.side, T=self.T, slots=self.slots, gamma=self.gamma,
                    per_decade=self.per_decade, low_dose=self.low_dose, q=self.q, S=self.S,
                    history=int(self.history), key=self.key, max_dose=self.max_dose)


def dose_position(dose, low_dose, per_decade, T):
    """Fractional dose node of ``dose`` lux·h (clipped to the last node).

    ``s = min(d / low, 1) + per_decade · log10(max(d, low) / low)``: linear from 0 to
    node 1, logarithmic after it (equal steps per decade), so ordinary years keep their
    resolution and a dose past the axis sits on its last, saturated node.
    """
    d = np.asarray(dose, dtype=np.float32)
    low = np.float32(low_dose)
    s = np.minimum(d / low, np.float32(1.0)) + np.float32(per_decade / math.log(10.0)) \
        * np.log(np.maximum(d, low) / low)
    return np.minimum(s, np.float32(T - 1))


# ---------------------------------------------------------------------- evaluation


def cube_colours(side, gamma):
    """Linear sRGB of the cube nodes, (N³, 3), r fastest (index ``(b · N + g) · N + r``)."""
    u = np.linspace(0.0, 1.0, side)
    b, g, r = np.meshgrid(u, u, u, indexing="ij")
    return np.stack([r, g, b], -1).reshape(-1, 3) ** gamma


def dose_nodes(low_dose, per_decade, T):
    """lux·h of the ``T`` dose nodes: 0, then ``low · 10**((t - 1) / per_decade)``."""
    return np.concatenate([[0.0], low_dose * 10.0 ** (np.arange(T - 1) / per_decade)])


def _to_rgb():
    return XYZ_to_linear_srgb(np.eye(3)).T.astype(np.float32)


def _to_XYZ():
    return linear_srgb_to_XYZ(np.eye(3)).T.astype(np.float32)


def _change(table, values, rgb, rates, years):
    """``change`` (n, 3) float32 of colours ``rgb`` (n, 3) linear, ``rates`` (S, n);
    ``values`` is ``table.values`` as float32."""
    N, T = table.side, table.T
    u = np.clip(rgb, 0.0, 1.0) ** np.float32(1.0 / table.gamma) * np.float32(N - 1)
    b0 = np.minimum(np.floor(u[:, 2]), N - 2).astype(np.int32)
    fb = (u[:, 2] - b0)[:, None]
    total = rates.sum(axis=0)
    s = dose_position(total * np.float32(years), table.low_dose, table.per_decade, T)
    t0 = np.minimum(np.floor(s), T - 2).astype(np.int32)
    ft = (s - t0)[:, None]
    if table.S == 1:
        slots, weights = np.zeros((len(rgb), 1), np.int32), None
    else:
        with np.errstate(invalid="ignore", divide="ignore"):
            w = np.where(total > 0, rates / total, 0.0).T.astype(np.float32)
        w[total <= 0, 0] = 1.0
        slots, weights = simplex_slots(w, table.q)
    change = np.zeros((len(rgb), 3), dtype=np.float32)
    cells = values.reshape(-1, 3)
    x0 = np.minimum(np.floor(u[:, 0]), N - 2).astype(np.int64)   # bilinear over (r, g):
    y0 = np.minimum(np.floor(u[:, 1]), N - 2).astype(np.int64)   # a Linear image lookup
    fx = (u[:, 0] - x0)[:, None]
    fy = (u[:, 1] - y0)[:, None]
    inside = y0 * N + x0

    def bilinear(tile):
        i = tile.astype(np.int64) * (N * N) + inside
        a = cells[i] + fx * (cells[i + 1] - cells[i])
        b = cells[i + N] + fx * (cells[i + N + 1] - cells[i + N])
        return a + fy * (b - a)

    for v in range(slots.shape[1]):
        corner = [bilinear((slots[:, v] * T + t0 + dt) * N + b0 + db)
                  for dt in (0, 1) for db in (0, 1)]
        lo_t = corner[0] + fb * (corner[1] - corner[0])
        hi_t = corner[2] + fb * (corner[3] - corner[2])
        step = lo_t + ft * (hi_t - lo_t)
        change += step if weights is None else step * weights[:, v:v + 1]
    return change


def evaluate(table, rgb, rates, years, out=None):
    """Aged linear sRGB of colours ``rgb`` lit by ``rates`` after ``years`` (numpy).

    Parameters
    ----------
    table : ColourTable
    rgb : ndarray, shape (n, 3)
        Linear sRGB (the artist's colour at each point).
    rates : ndarray, shape (S, n)
        Annual dose from each of the table's spectra, lux·h.
    years : float
        >= 0; any size (past the axis the last, saturated node holds).
    out : ndarray, shape (n, 3) or (n, 4), optional
        Written in its first three channels.

    Returns
    -------
    ndarray, shape (n, 3) or ``out``, in [0, 1] (:func:`.gamut.into_gamut`), except at
    zero years without history, where the colour itself comes back.
    """
    rgb = np.asarray(rgb, dtype=np.float32).reshape(-1, 3)
    rates = np.asarray(rates, dtype=np.float32).reshape(table.S, -1)
    n = rgb.shape[0]
    res = np.empty((n, 3), dtype=np.float32) if out is None else out
    if years == 0 and not table.history:
        res[:, :3] = rgb
        return res
    to_XYZ, to_rgb = _to_XYZ(), _to_rgb()
    values = table.values.astype(np.float32)

    def block(s0):
        s1 = min(s0 + _BLOCK, n)
        c = rgb[s0:s1]
        change = _change(table, values, c, rates[:, s0:s1], float(years))
        aged = (c @ to_XYZ.T) * np.exp(change)
        planes = np.ascontiguousarray((aged @ to_rgb.T).T)
        into_gamut_planes(planes)
        res[s0:s1, :3] = planes.T

    in_blocks(block, n, _BLOCK, _THREADS)
    return res


# ---------------------------------------------------------------------- the atlas image


def atlas_layout(table):
    """``(width, height, tile side P)`` of the atlas: tile (column ``b``, row
    ``slot · T + t``) holds the (r, g) plane of blue node ``b``, dose node ``t`` and
    light-mix slot ``slot``, one texel of padding (edge copies) around its N × N nodes,
    so a node group finds a tile with one multiply-add per axis."""
    P = table.side + 2
    height = table.slots * table.T * P
    if height > MAX_ATLAS_HEIGHT:
        raise ValueError(f"a colour table of {table.slots} light-mix slots x {table.T} dose "
                         f"nodes is {height} texels tall, more than {MAX_ATLAS_HEIGHT}")
    return table.side * P, height, P


def atlas_pixels(table):
    """The table as an (H, W, 4) float32 image (bottom row first, as Blender stores it):
    texel ``(b · P + 1 + i_r, (slot · T + t) · P + 1 + i_g)`` is node (r = i_r, g = i_g)."""
    W, H, P = atlas_layout(table)
    N = table.side
    v = table.values.astype(np.float32)                             # (slot, t, b, g, r, 3)
    padded = np.pad(v, ((0, 0), (0, 0), (0, 0), (1, 1), (1, 1), (0, 0)), mode="edge")
    img = padded.transpose(0, 1, 3, 2, 4, 5).reshape(H, N * P, 3)   # rows: slot, t, g
    out = np.ones((H, W, 4), dtype=np.float32)
    out[..., :3] = img
    return out


def table_from_atlas(pixels, info):
    """The :class:`ColourTable` an :func:`atlas_pixels` image holds (``info``: its
    :meth:`ColourTable.info`); values as the image stores them."""
    N, T, slots = int(info["side"]), int(info["T"]), int(info["slots"])
    P = N + 2
    img = pixels[..., :3].reshape(slots, T, P, N, P, 3)[:, :, 1:-1, :, 1:-1]   # (slot, t, g, b, r)
    values = np.ascontiguousarray(img.transpose(0, 1, 3, 2, 4, 5)).astype(np.float16)
    return ColourTable(values, dose_nodes(float(info["low_dose"]), float(info["per_decade"]), T),
                       float(info["gamma"]), float(info["per_decade"]), float(info["low_dose"]),
                       int(info["q"]), int(info["S"]), bool(info["history"]), str(info["key"]))
