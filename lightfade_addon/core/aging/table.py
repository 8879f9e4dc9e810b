"""The aging table: one per aged texture, and its numpy evaluator.

Everything about a texture's aging that does not depend on the years is two things:

* the **table** — for every colour *key* (a bin of unmixed concentrations), every
  light-mix *slot* and every dose node, the modelled change
  ``log(XYZ_aged / XYZ_initial)`` (three numbers);
* per texel, its **key** and its annual **dose rate** from each light spectrum
  (lux·h per year).

The years select a position on the dose axis. With the rate ``r`` of a texel and
the table's largest dose ``D`` (lux·h), its fractional dose node is

    s = (T - 1) · (r · years / D) ** (1/3)                      (cubic dose axis, :mod:`.lattice`)

and the change is interpolated linearly between nodes ``i = min(floor s, T - 2)`` and
``i + 1``, and barycentrically over the light-mix lattice (:func:`simplex_slots`).
The aged texel is the original times that change in CIE XYZ (the paper's
grid lookup, Section 5)::

    XYZ_aged = XYZ_texel · exp(change)

then back to linear sRGB and into the gamut (:func:`.gamut.into_gamut`).

The same table has two evaluators that are tested against each other texel by texel:
:func:`evaluate` here (real aged images: export, other engines, painting) and a
node group in Blender (``blender/nodes``), which reads the table, the keys and the
rates from images laid out by :func:`table_pixels`, :func:`key_pixels`.

Light-mix slots
---------------
The grid's light-mix axis is the simplex lattice of :func:`.lattice.mix_lattice`
(compositions ``n / q`` of ``S`` spectra). A texel's mixture is interpolated on
Freudenthal's triangulation in cumulative coordinates ``y_j = q · (w_1 + … + w_j)``,
``j < S``: the ``S`` vertices are integer points ``0 <= v_1 <= … <= v_{S-1} <= q``.
The table indexes a vertex by its *slot* ``Σ v_j (q + 1)**(j - 1)`` — a number a node
tree computes with a few multiply-adds, where a lattice row would need a lookup —
so it has ``(q + 1)**(S - 1)`` slots, the non-monotone ones unused.
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from ..colour.colorimetry import XYZ_to_linear_srgb, linear_srgb_to_XYZ
from ..colour.gamut import into_gamut_planes
from ..fading.lattice import DOSE_POWER, mix_lattice

__all__ = ["AgingTable", "Texels", "TABLE_TEXELS", "TABLE_NODES_PER_ROW", "evaluate",
           "evaluate_change", "max_keys",
           "key_pixels", "mix_slots", "simplex_slots", "table_layout", "table_pixels",
           "texel_positions"]

#: Most table entries (key × slot × dose node) by default (the command line): 258,111
#: keys of one spectrum and 65 dose nodes, 192 MB as half-precision node pairs (half as
#: many measured max ΔE00 1.89 instead of 0.48 on a 2048² landscape against the exact
#: path: docs/grid_photos.md). Blender sizes a copy's table by its texture.
TABLE_TEXELS = 1 << 24
#: Dose-node runs per row of the table image (a run of T nodes never straddles rows).
TABLE_NODES_PER_ROW = 63
#: Texels evaluated per block (bounds the temporaries) and threads (numpy releases the GIL).
_BLOCK = 1 << 17
_THREADS = max(1, min(4, os.cpu_count() or 1))


def mix_slots(S, q):
    """Lattice row of every slot, (``(q+1)**(S-1)``,) int, -1 for unused slots."""
    if S == 1:
        return np.zeros(1, dtype=np.int64)
    rows = {tuple(np.rint(r * q).astype(int)): i for i, r in enumerate(mix_lattice(S, q))}
    out = np.full((q + 1) ** (S - 1), -1, dtype=np.int64)
    for slot in range(out.size):
        v = [(slot // (q + 1) ** j) % (q + 1) for j in range(S - 1)]
        if all(a <= b for a, b in zip(v, v[1:])):
            parts = tuple(np.diff([0, *v, q]))
            out[slot] = rows[parts]
    return out


def simplex_slots(w, q):
    """Slots and barycentric weights of mixtures ``w`` (N, S) on the mix lattice.

    Freudenthal's triangulation in cumulative coordinates (see the module docstring):
    ``y = clip(q · cumsum(w)[:S-1], 0, q)``, ``base = min(floor y, q - 1)``,
    ``f = y - base``. Coordinate ``j``'s *rank* counts the fractions that go before
    it — larger ones, and equal ones of a later coordinate. Vertex ``k`` is ``base``
    plus one on every coordinate of rank below ``k``; its weight is
    ``f_(k-1) - f_(k)`` with ``f_(-1) = 1`` and ``f_(S-1) = 0`` (``f_(k)`` the fraction
    of rank ``k``). The node group computes exactly this.

    Returns
    -------
    slots : ndarray of int32, shape (N, S)
    weights : ndarray of float32, shape (N, S), non-negative, summing to 1
    """
    w = np.asarray(w, dtype=np.float32)
    N, S = w.shape
    if S == 1:
        return np.zeros((N, 1), dtype=np.int32), np.ones((N, 1), dtype=np.float32)
    if S == 2:                      # one coordinate: rank 0, vertices base and base + 1
        y = np.clip(np.float32(q) * w[:, 0], 0, q)
        base = np.minimum(np.floor(y), q - 1)
        f = (y - base).astype(np.float32)
        slots = np.empty((N, 2), dtype=np.int32)
        slots[:, 0] = base
        slots[:, 1] = slots[:, 0] + 1
        weights = np.empty((N, 2), dtype=np.float32)
        np.subtract(np.float32(1.0), f, out=weights[:, 0])
        weights[:, 1] = f
        return slots, weights
    y = np.clip(np.float32(q) * np.cumsum(w, axis=1, dtype=np.float32)[:, :-1], 0, q)
    base = np.minimum(np.floor(y), q - 1)
    f = (y - base).astype(np.float32)
    J = S - 1
    rank = np.zeros((N, J), dtype=np.int32)
    for j in range(J):
        for i in range(J):
            if i < j:
                rank[:, j] += f[:, i] > f[:, j]
            elif i > j:
                rank[:, j] += f[:, i] >= f[:, j]
    radix = (q + 1) ** np.arange(J)
    base_slot = base.astype(np.int64) @ radix
    slots = np.empty((N, S), dtype=np.int32)
    weights = np.empty((N, S), dtype=np.float32)
    ordered = np.zeros((N, J), dtype=np.float32)       # f_(k): the fraction of rank k
    for j in range(J):
        np.put_along_axis(ordered, rank[:, j:j + 1], f[:, j:j + 1], axis=1)
    for k in range(S):
        slots[:, k] = base_slot + ((rank < k) * radix).sum(axis=1)
        upper = np.float32(1.0) if k == 0 else ordered[:, k - 1]
        lower = np.float32(0.0) if k == J else ordered[:, k]
        weights[:, k] = upper - lower
    return slots, weights


@dataclass(frozen=True)
class AgingTable:
    """The change of every key along the dose axis, per light-mix slot.

    Stored as :attr:`pairs`: each entry (key, slot, dose node ``t``) beside the entry of
    node ``t + 1``, in half precision (as a GPU may hold the table image, so both
    evaluators read the same numbers, within 0.05 % of the float32 logs): what the
    numpy evaluator gathers, one 12-byte copy a texel and light-mix vertex.

    Attributes
    ----------
    pairs : ndarray, shape (K · slots · T, 6), float16
        ``log(XYZ_aged / XYZ_initial)`` at dose node ``t`` (columns 0–2) and ``t + 1``
        (columns 3–5; the last entry repeats itself); node ``t``'s dose is
        ``max_dose · (t / (T - 1))**3`` lux·h. Unused slots hold zeros.
    shape : (K, slots, T)
    max_dose : float
        lux·h of the last dose node.
    q : int
        Mix lattice resolution; ``slots == (q + 1)**(S - 1)``.
    S : int
        Number of light spectra.
    """

    pairs: np.ndarray
    shape: tuple
    max_dose: float
    q: int
    S: int

    @classmethod
    def from_values(cls, values, max_dose, S, q):
        """A table from its values (K, slots, T, 3) (rounded to half precision)."""
        flat = np.asarray(values).reshape(-1, 3)
        pairs = np.empty((flat.shape[0], 6), dtype=np.float16)
        pairs[:, :3] = flat
        pairs[:-1, 3:] = pairs[1:, :3]
        pairs[-1:, 3:] = pairs[-1:, :3]
        return cls(pairs, tuple(np.shape(values)[:3]), float(max_dose), int(q), int(S))

    @classmethod
    def from_curves(cls, curves, max_dose, S, q):
        """A table from the grid's change curves (keys, lattice rows, T, 3)."""
        rows = mix_slots(S, q)
        K, M, T, _ = curves.shape
        values = np.zeros((K, rows.size, T, 3), dtype=np.float16)
        used = rows >= 0
        values[:, used] = curves[:, rows[used]]
        return cls.from_values(values, max_dose, S, q)

    @property
    def values(self):
        """(K, slots, T, 3) float16 view of the entries."""
        return self.pairs[:, :3].reshape(*self.shape, 3)

    @property
    def keys(self):
        return self.shape[0]

    @property
    def slots(self):
        return self.shape[1]

    @property
    def T(self):
        return self.shape[2]

    def max_years(self, rate):
        """Years until a texel of annual dose ``rate`` lux·h reaches the last node."""
        return self.max_dose / rate if rate > 0 else np.inf


def max_keys(S, q, T, entries=None):
    """Most keys a table of ``S`` spectra, mix resolution ``q`` and ``T`` dose nodes holds
    within ``entries`` (default :data:`TABLE_TEXELS`)."""
    entries = TABLE_TEXELS if entries is None else int(entries)
    return max(entries // ((q + 1) ** (S - 1) * T), 1)


@dataclass
class Texels:
    """Per texel: its key, its annual dose per spectrum and its colour.

    Attributes
    ----------
    key : ndarray of int32, shape (n,)
    rate : ndarray of float32, shape (S, n)
        lux·h per year from each light spectrum.
    XYZ : ndarray of float32, shape (3, n)
        The original colour in CIE XYZ (D65), as planes.
    """

    key: np.ndarray
    rate: np.ndarray
    XYZ: np.ndarray

    @classmethod
    def from_linear(cls, key, rate, linear_rgb):
        rgb = np.asarray(linear_rgb, dtype=np.float32).reshape(-1, 3)
        return cls(np.asarray(key, dtype=np.int32).reshape(-1),
                   np.asarray(rate, dtype=np.float32).reshape(len(rate), -1),
                   linear_srgb_to_XYZ(rgb).T.astype(np.float32))


def texel_positions(table, texels):
    """Years-independent lookups of :func:`evaluate`: dose scale, table rows, weights.

    Returns
    -------
    sigma : (n,) float32
        ``(T - 1) · (rate / max_dose)**(1/3)``; the dose node is ``sigma · years**(1/3)``.
    rows : (S, n) int32
        Row of each mix vertex's dose node 0 in ``values.reshape(-1, 3)``.
    weights : (S, n) float32 or None (one spectrum)
    """
    rate = texels.rate
    total = rate.sum(axis=0)
    sigma = ((total / np.float32(table.max_dose)) ** np.float32(1.0 / DOSE_POWER)
             * np.float32(table.T - 1)).astype(np.float32)
    base = texels.key.astype(np.int32) * np.int32(table.slots * table.T)
    if table.S == 1:
        return sigma, base[None], None
    with np.errstate(invalid="ignore", divide="ignore"):
        w = np.where(total > 0, rate / total, 0.0).T.astype(np.float32)
    w[total <= 0, 0] = 1.0
    slots, weights = simplex_slots(w, table.q)
    return sigma, (base[:, None] + slots * np.int32(table.T)).T.copy(), weights.T.copy()


def evaluate_change(table, positions, years):
    """``change`` (3, n) float32 of every texel after ``years``: the dose and mix
    interpolation of :func:`evaluate`, before ``exp`` (for reports and tests)."""
    sigma, rows, weights = positions
    nodes = table.values.reshape(-1, 3).astype(np.float32)
    pos = np.minimum(sigma * np.float32(float(years) ** (1.0 / DOSE_POWER)),
                     np.float32(table.T - 1))
    i = np.minimum(pos.astype(np.int32), table.T - 2)
    f = (pos - i)[:, None]
    change = np.zeros((sigma.shape[0], 3), dtype=np.float32)
    for v in range(rows.shape[0]):
        lo = nodes[rows[v] + i]
        step = lo + f * (nodes[rows[v] + i + 1] - lo)
        change += step if weights is None else step * weights[v][:, None]
    return change.T


def _to_rgb():
    return XYZ_to_linear_srgb(np.eye(3)).T.astype(np.float32)


def evaluate(table, texels, years, positions=None, out=None):
    """Aged linear sRGB of every texel after ``years`` (the numpy evaluator).

    Parameters
    ----------
    table : AgingTable
    texels : Texels
    years : float
        ``>= 0``; dose positions past the last node are held there (the caller
        prepares a table long enough, see :meth:`AgingTable.max_years`).
    positions : tuple, optional
        :func:`texel_positions` of ``table`` and ``texels`` (computed when not given).
    out : ndarray, shape (n, 3) or (n, 4), float32, optional
        Where to write (the first three channels of Blender's RGBA layout).

    Returns
    -------
    ndarray, shape (n, 3) or ``out``
        In [0, 1] (:func:`.gamut.into_gamut`).
    """
    sigma, rows, weights = positions or texel_positions(table, texels)
    n = sigma.shape[0]
    res = np.empty((n, 3), dtype=np.float32) if out is None else out
    root = np.float32(float(years) ** (1.0 / DOSE_POWER))
    # a key's values at dose nodes i and i + 1 in half precision are one 12-byte item
    items = table.pairs.view(np.dtype((np.void, 12))).ravel()
    last = np.float32(table.T - 1)
    to_rgb = _to_rgb()

    def block(s0):
        s1 = min(s0 + _BLOCK, n)
        k = s1 - s0
        pos = sigma[s0:s1] * root
        np.minimum(pos, last, out=pos)
        i = pos.astype(np.int32)
        np.minimum(i, table.T - 2, out=i)
        f = pos
        f -= i                                          # fractional node position
        change = np.zeros((3, k), dtype=np.float32)     # planes: long inner loops
        tmp = np.empty(k, dtype=np.float32)
        for v in range(rows.shape[0]):
            both = np.take(items, rows[v, s0:s1] + i).view(np.float16).reshape(k, 6)
            both = np.ascontiguousarray(both.T, dtype=np.float32)     # (6, k) planes
            for ch in range(3):                         # v_i + f (v_i+1 - v_i)
                np.subtract(both[3 + ch], both[ch], out=tmp)
                tmp *= f
                tmp += both[ch]
                if weights is not None:
                    tmp *= weights[v, s0:s1]
                change[ch] += tmp
        np.exp(change, out=change)
        change *= texels.XYZ[:, s0:s1]                  # aged XYZ
        rgb = np.empty_like(change)
        for ch in range(3):                             # 9 multiply-adds beat a 3 x k matmul
            np.multiply(change[0], to_rgb[ch, 0], out=rgb[ch])
            np.multiply(change[1], to_rgb[ch, 1], out=tmp)
            rgb[ch] += tmp
            np.multiply(change[2], to_rgb[ch, 2], out=tmp)
            rgb[ch] += tmp
        into_gamut_planes(rgb)
        for ch in range(3):
            res[s0:s1, ch] = rgb[ch]

    in_blocks(block, n, _BLOCK)
    return res


def in_blocks(block, n, size, threads=_THREADS):
    """Call ``block(s0)`` for every start ``s0`` of ``size``-row blocks of ``n`` rows, on
    ``threads`` threads when there is more than one block (numpy releases the GIL in
    the gathers)."""
    starts = range(0, n, size)
    if n > size and threads > 1:
        with ThreadPoolExecutor(threads) as pool:
            list(pool.map(block, starts))
    else:
        for s0 in starts:
            block(s0)


# ------------------------------------------------------------------ image layouts
# The node group reads the table and the keys from images (bottom row first, as
# Blender stores pixels); these functions are the one definition of that layout.


def table_layout(table):
    """(width, height) of the table image: rows of :data:`TABLE_NODES_PER_ROW` runs of T."""
    runs = table.keys * table.slots
    per_row = min(TABLE_NODES_PER_ROW, runs)
    return per_row * table.T, -(-runs // per_row)


def table_pixels(table):
    """The table as an (H, W, 4) float32 image: run ``k · slots + slot`` (a key's dose
    nodes at one slot) at row ``run // per_row``, columns ``(run % per_row) · T + t``."""
    W, H = table_layout(table)
    flat = np.zeros((H * W, 4), dtype=np.float32)
    flat[:table.pairs.shape[0], :3] = table.pairs[:, :3]
    flat[:, 3] = 1.0
    return flat.reshape(H, W, 4)


def key_pixels(key, shape):
    """Keys (n,) as an (H, W, 4) uint8 image: ``key = 65536 R + 256 G + B`` (0–255)."""
    key = np.asarray(key, dtype=np.int64).reshape(shape)
    if key.max(initial=0) >= 1 << 24:
        raise ValueError("at most 2**24 keys fit an 8-bit RGB key image")
    out = np.empty((*shape, 4), dtype=np.uint8)
    out[..., 0] = key >> 16
    out[..., 1] = (key >> 8) & 255
    out[..., 2] = key & 255
    out[..., 3] = 255
    return out
