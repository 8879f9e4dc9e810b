"""The aging table: one per recipe and set of light spectra, and its evaluator.

Two lookups, each smooth where it interpolates (the paper's Section 5: a grid over
colourant concentrations, looked up by interpolation):

1. the **unmixing** ``Φ`` (:mod:`..fading.unmix`, Eq. U2): the concentrations a colour
   needs, unbounded, tabulated over the colour cube (``A`` nodes per channel of
   ``u = clip(rgb, 0, 1) ** (1 / gamma)``). ``Φ`` is smooth across the recipe's gamut;
   its clip to [0, 1], which puts out-of-gamut colours on the gamut's faces, is
   applied after the interpolation, so the faces are exact;
2. the **change** ``log(XYZ_aged / XYZ_initial)`` over the concentrations (``N`` nodes
   per colourant, evenly spaced in ``k = c ** (1 / power)``: the paper's grid), the
   **dose** (an absolute axis in lux·h shared by every texel: node 0 at 0, node
   ``t >= 1`` at ``low · 10 ** ((t - 1) / per_decade)``, cut where the recipe has stopped
   changing: :func:`dose_position`) and the **light mix** (the slots of
   :func:`.table.simplex_slots` over the set's spectra).

Nothing in the table belongs to a texture: every material aged with the same recipe
under the same spectra shares it, and it is looked up from the artist's own colour at
each shading point, so procedural graphs, UDIMs and fine detail age at full detail.
Per texel only the dose rates remain (the exposure maps themselves).

The aged colour (linear sRGB ``rgb``, annual doses ``rate_s`` lux·h, ``years``)::

    y = lerp_b bilerp_rg unmix[b, g, r]           k = clip(y, 0, 1) ** (1 / power)
    d = years · Σ_s rate_s                        s = dose_position(d)          (lux·h)
    change = Σ_v w_v · lerp_k3 lerp_t bilerp_k1k2 table[slot_v, t, k3, k2, k1]
    rgb_aged = into_gamut(M⁻¹ · (M · rgb) · exp(change))

bilinear over two axes (a Linear image lookup in the node group), linear over the
third and the dose by hand, barycentric over the light mix (:func:`.table.simplex_slots`).
Recipes with fewer than three unmixed colourants leave the other axes at 0.
At zero years the colour itself comes back, unless the table carries a *history*
(a texture that is already old, :class:`.restore.Prior`): its change is then tabulated
over the seen colour's cube ``u`` itself (``unmix`` holds ``u ** power``, so ``k = u``)
and at dose 0 is the restoration ``log(XYZ_new / XYZ_seen)``.

:func:`evaluate` is the numpy evaluator; ``blender/aging/group.py`` builds the node
group that computes the same from :func:`atlas_pixels`, and the two are tested
against each other texel by texel.
"""

from __future__ import annotations

import functools
import math
import os
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ..colour.colorimetry import XYZ_to_linear_srgb, linear_srgb_to_XYZ
from ..colour.gamut import into_gamut_planes
from ..colour.srgb8 import srgb_code_floats
from .table import in_blocks, simplex_slots

__all__ = ["AtlasLayout", "ColourTable", "atlas_layout", "atlas_pixels", "coordinates",
           "cube_colours", "dose_position", "evaluate", "mix_resolution", "table_from_atlas"]

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
    """The unmixing over the colour cube; the change over concentrations × dose ×
    light-mix slot.

    Attributes
    ----------
    values : ndarray, shape (slots, T, N, N, N, 3), float16
        ``log(XYZ_aged / XYZ_initial)``, axes slot, dose node, k3, k2, k1 (with a
        history: b, g, r of the seen colour).
    doses : ndarray, shape (T,)
        lux·h of each dose node.
    gamma, per_decade, low_dose : float
        As :class:`TableSettings`.
    q, S : int
        Mix lattice resolution and number of spectra.
    history : bool
        Built over seen colours of an already aged texture (dose 0 is the restoration).
    key : str
    unmix : ndarray, shape (A, A, A, 3), float16
        ``Φ`` (Eq. U2) at the colour cube's nodes, axes b, g, r; unused colourants 0.
    power : float
        Concentration axis spacing: node ``i`` of ``N`` at ``c = (i / (N - 1)) ** power``.
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
    unmix: np.ndarray
    power: float
    lost: np.ndarray | None = None

    @property
    def side(self):
        return self.values.shape[2]

    @property
    def unmix_side(self):
        return self.unmix.shape[0]

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
                    history=int(self.history), key=self.key, max_dose=self.max_dose,
                    unmix_side=self.unmix_side, power=self.power)


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


@functools.cache
def _to_rgb():
    """XYZ -> linear sRGB (3, 3) float32, read-only (made once)."""
    m = XYZ_to_linear_srgb(np.eye(3)).T.astype(np.float32)
    m.flags.writeable = False
    return m


@functools.cache
def _to_XYZ():
    """Linear sRGB -> XYZ (3, 3) float32, read-only (made once)."""
    m = linear_srgb_to_XYZ(np.eye(3)).T.astype(np.float32)
    m.flags.writeable = False
    return m


def _bilinear(cells, N, tile, x, y):
    """Bilinear lookup of a tile of ``N × N`` nodes (rows of ``cells``, (tiles · N², K)):
    node coordinates ``x`` (fastest) and ``y``, (n,); ``tile`` (n,) int."""
    x0 = np.minimum(np.floor(x), N - 2).astype(np.int64)
    y0 = np.minimum(np.floor(y), N - 2).astype(np.int64)
    fx, fy = (x - x0)[:, None], (y - y0)[:, None]
    i = tile.astype(np.int64) * (N * N) + y0 * N + x0
    a = cells[i] + fx * (cells[i + 1] - cells[i])
    b = cells[i + N] + fx * (cells[i + N + 1] - cells[i + N])
    return a + fy * (b - a)


def coordinates(table, rgb, unmix=None):
    """The change table's node coordinates ``k · (N - 1)`` (n, 3) of colours ``rgb``
    (n, 3) linear: ``Φ`` interpolated over the colour cube (bilinear over r, g, linear
    over b), clipped to [0, 1], ``** (1 / power)``; ``unmix``: ``table.unmix`` as float32."""
    A = table.unmix_side
    cells = (table.unmix.astype(np.float32) if unmix is None else unmix).reshape(-1, 3)
    u = np.clip(rgb, 0.0, 1.0) ** np.float32(1.0 / table.gamma) * np.float32(A - 1)
    b0 = np.minimum(np.floor(u[:, 2]), A - 2).astype(np.int32)
    lo = _bilinear(cells, A, b0, u[:, 0], u[:, 1])
    hi = _bilinear(cells, A, b0 + 1, u[:, 0], u[:, 1])
    y = lo + (u[:, 2] - b0)[:, None] * (hi - lo)
    return np.clip(y, 0.0, 1.0) ** np.float32(1.0 / table.power) * np.float32(table.side - 1)


def mix_vertices(table, rates):
    """Light-mix slots and weights of texels lit by ``rates`` (S, n) lux·h:
    ``(slots (n, V) int32, weights (n, V) float32)``, weights None for one spectrum
    (:func:`.table.simplex_slots` of the spectra's shares; no light: spectrum 0)."""
    total = rates.sum(axis=0)
    if table.S == 1:
        return np.zeros((rates.shape[1], 1), np.int32), None
    with np.errstate(invalid="ignore", divide="ignore"):
        w = np.where(total > 0, rates / total, 0.0).T.astype(np.float32)
    w[total <= 0, 0] = 1.0
    return simplex_slots(w, table.q)


def change_nodes(table, values, u, slots, weights, t0):
    """The change at dose nodes ``t0`` and ``t0 + 1`` (two (n, 3) float32 arrays) of
    texels at node coordinates ``u`` (n, 3) (:func:`coordinates`), light-mix ``slots``,
    ``weights`` (:func:`mix_vertices`); ``t0`` (n,) int, at most ``T - 2``. ``values``
    is ``table.values`` as float32. Per vertex, bilinear over k1, k2 (a Linear image
    lookup), linear over k3; weighted over the vertices."""
    N, T = table.side, table.T
    b0 = np.minimum(np.floor(u[:, 2]), N - 2).astype(np.int32)
    fb = (u[:, 2] - b0)[:, None]
    cells = values.reshape(-1, 3)
    t0 = np.asarray(t0, dtype=np.int32)
    nodes = [np.zeros((len(u), 3), dtype=np.float32), np.zeros((len(u), 3), dtype=np.float32)]
    for v in range(slots.shape[1]):
        for dt, node in enumerate(nodes):
            row = (slots[:, v] * T + t0 + dt) * N + b0
            lo = _bilinear(cells, N, row, u[:, 0], u[:, 1])
            hi = _bilinear(cells, N, row + 1, u[:, 0], u[:, 1])
            step = lo + fb * (hi - lo)
            node += step if weights is None else step * weights[:, v:v + 1]
    return nodes


def dose_node(table, total, years):
    """``(t0, ft)``: the dose node below and the fraction past it of texels receiving
    ``total`` lux·h a year after ``years`` (:func:`dose_position`)."""
    s = dose_position(total * np.float32(years), table.low_dose, table.per_decade, table.T)
    t0 = np.minimum(np.floor(s), table.T - 2).astype(np.int32)
    return t0, (s - t0)[:, None]


def _change(table, values, u, rates, years):
    """``change`` (n, 3) float32 at node coordinates ``u`` (n, 3) (:func:`coordinates`),
    ``rates`` (S, n); ``values`` is ``table.values`` as float32."""
    slots, weights = mix_vertices(table, rates)
    t0, ft = dose_node(table, rates.sum(axis=0), years)
    lo, hi = change_nodes(table, values, u, slots, weights, t0)
    return lo + ft * (hi - lo)


def aged_colour(rgb, change, out, codes=False):
    """``into_gamut(M⁻¹ · (M · rgb) · exp(change))`` of (n, 3) linear colours into the
    first three channels of ``out`` (n, >= 3); with ``codes``, as the 8-bit sRGB codes
    over 255 that a byte sRGB image stores for it (:func:`..colour.srgb8.
    srgb_code_floats`)."""
    aged = rgb @ _to_XYZ().T
    aged *= np.exp(change)
    planes = np.ascontiguousarray((aged @ _to_rgb().T).T)   # (n, 3) @ (3, 3): no BLAS threads
    into_gamut_planes(planes)
    if codes:
        srgb_code_floats(planes, out=planes)
    out[:, :3] = planes.T
    return out


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
    values = table.values.astype(np.float32)
    unmix = table.unmix.astype(np.float32)

    def block(s0):
        s1 = min(s0 + _BLOCK, n)
        c = rgb[s0:s1]
        change = _change(table, values, coordinates(table, c, unmix), rates[:, s0:s1],
                         float(years))
        aged_colour(c, change, res[s0:s1])

    in_blocks(block, n, _BLOCK, _THREADS)
    return res


# ---------------------------------------------------------------------- the atlas image


class AtlasLayout(NamedTuple):
    """Where the two tables lie in the atlas image (texels).

    The change's tiles (``P = N + 2`` square) come first: tile (column ``k3``, row
    ``slot · T + t``), ``rows`` tile rows. The unmixing's tiles (``PA = A + 2``) follow
    above them, ``per_row`` to a row: tile ``b`` at column ``b mod per_row``, row
    ``b div per_row``, from texel row ``unmix_y``.
    """

    width: int
    height: int
    P: int
    PA: int
    per_row: int
    unmix_y: int


def atlas_layout(table):
    """The :class:`AtlasLayout` of ``table``: each tile holds a plane of nodes (the
    change: (k1, k2) of node k3, dose node t and light-mix slot; the unmixing: (r, g) of
    blue node b) with one texel of padding (edge copies), so a node group finds a tile
    with one multiply-add per axis. ``table`` may be a :meth:`ColourTable.info` dict."""
    info = table if isinstance(table, dict) else table.info()
    N, A = int(info["side"]), int(info["unmix_side"])
    slots, T = int(info["slots"]), int(info["T"])
    P, PA = N + 2, A + 2
    width = max(N * P, PA)
    per_row = width // PA
    unmix_y = slots * T * P
    height = unmix_y + -(-A // per_row) * PA
    if height > MAX_ATLAS_HEIGHT:
        raise ValueError(f"a colour table of {slots} light-mix slots x {T} dose "
                         f"nodes is {height} texels tall, more than {MAX_ATLAS_HEIGHT}")
    return AtlasLayout(width, height, P, PA, per_row, unmix_y)


def atlas_pixels(table):
    """The table as an (H, W, 4) float32 image (bottom row first, as Blender stores it):
    texel ``(k3 · P + 1 + i1, (slot · T + t) · P + 1 + i2)`` is change node (i1, i2, k3);
    texel ``((b mod per_row) · PA + 1 + i_r, unmix_y + (b div per_row) · PA + 1 + i_g)``
    is unmixing node (i_r, i_g, b). Unused texels are 0, alpha 1."""
    L = atlas_layout(table)
    N, A = table.side, table.unmix_side
    out = np.zeros((L.height, L.width, 4), dtype=np.float32)
    out[..., 3] = 1.0
    v = table.values.astype(np.float32)                             # (slot, t, k3, k2, k1, 3)
    padded = np.pad(v, ((0, 0), (0, 0), (0, 0), (1, 1), (1, 1), (0, 0)), mode="edge")
    out[:L.unmix_y, :N * L.P, :3] = padded.transpose(0, 1, 3, 2, 4, 5).reshape(
        L.unmix_y, N * L.P, 3)                                      # rows: slot, t, k2
    tiles = np.pad(table.unmix.astype(np.float32), ((0, 0), (1, 1), (1, 1), (0, 0)), mode="edge")
    for b in range(A):
        x, y = (b % L.per_row) * L.PA, L.unmix_y + (b // L.per_row) * L.PA
        out[y:y + L.PA, x:x + L.PA, :3] = tiles[b]
    return out


def table_from_atlas(pixels, info):
    """The :class:`ColourTable` an :func:`atlas_pixels` image holds (``info``: its
    :meth:`ColourTable.info`); values as the image stores them."""
    N, T, slots = int(info["side"]), int(info["T"]), int(info["slots"])
    A = int(info["unmix_side"])
    L = atlas_layout(info)
    img = pixels[:L.unmix_y, :N * L.P, :3].reshape(slots, T, L.P, N, L.P, 3)[:, :, 1:-1, :, 1:-1]
    values = np.ascontiguousarray(img.transpose(0, 1, 3, 2, 4, 5)).astype(np.float16)
    y0 = [L.unmix_y + (b // L.per_row) * L.PA + 1 for b in range(A)]
    x0 = [(b % L.per_row) * L.PA + 1 for b in range(A)]
    unmix = np.stack([pixels[y:y + A, x:x + A, :3] for x, y in zip(x0, y0)]).astype(np.float16)
    return ColourTable(values, dose_nodes(float(info["low_dose"]), float(info["per_decade"]), T),
                       float(info["gamma"]), float(info["per_decade"]), float(info["low_dose"]),
                       int(info["q"]), int(info["S"]), bool(info["history"]), str(info["key"]),
                       unmix, float(info["power"]))
