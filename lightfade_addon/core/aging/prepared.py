"""The numpy evaluator with what does not depend on the years done once per texel.

:func:`.colourtable.evaluate` does everything per texel at every call: the unmixing
``Φ`` over the colour cube (8 gathers), the light-mix vertices, and per vertex the
change at two dose nodes × two k3 planes, each bilinear (16 gathers): about 40 gathers
of three floats a texel, 0.5-3 s per Mtexel. Of that, only the dose position depends on
the years. :class:`PreparedTexels` keeps per texel

* ``total`` — the annual dose, lux·h (the dose axis position is ``years · total``);
* ``slots``, ``weights`` — the light-mix vertices (two or more spectra);
* the **band**: the dose node ``t0`` it was last evaluated at and the change there,
  ``lo = change(t0)``, and to the next node, ``step = change(t0 + 1) - lo``
  (vertex-mixed and interpolated over the concentration cube, exactly as
  :func:`.colourtable.change_nodes`);
* ``u`` — the colour's coordinates on the concentration cube (its unmixing), from the
  first band on.

A years value then costs, per texel, the dose position ``s`` (:func:`.colourtable.
dose_position`), ``change = lo + (s - t0) · step`` and the colour stage; only texels
whose node ``t0 = min(floor s, T - 2)`` moved (a new years range: every texel at the
first call; a step of 0.1 year at 10 years moves about 4 % of them) have their band
evaluated again: a move of one node (a time-lapse, a nearby years value) keeps the
band's other end and evaluates one node (one gather of 24 floats per light-mix
vertex), a longer move two, the first one the unmixing as well.
All in float32: 42 bytes a texel for one spectrum, 58 for two.

The result equals :func:`.colourtable.evaluate`'s (the same nodes, the same lerp) to
float32 rounding; zero years without a history gives the colour itself, as there.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..colour.srgb8 import srgb_code_floats
from .colourtable import _BLOCK, _THREADS, aged_colour, dose_node, mix_vertices
from .table import in_blocks

__all__ = ["PreparedTexels", "TableCells", "table_cells", "prepare_texels",
           "evaluate_prepared"]


@dataclass(frozen=True)
class TableCells:
    """A table's two grids as cells: each row the 8 corners × 3 channels of one cube
    cell (corner ``(d3, d2, d1)`` at ``4 d3 + 2 d2 + d1``), so that a texel's trilinear
    lookup is one gather of 24 floats instead of eight of three.

    ``change``: rows ``((slot · T + t) · (N - 1) + k3) · (N - 1)² + k2 · (N - 1) + k1``;
    ``unmix``: rows ``(b · (A - 1) + g) · (A - 1) + r``.
    """

    change: np.ndarray
    unmix: np.ndarray

    @property
    def nbytes(self):
        return self.change.nbytes + self.unmix.nbytes


def _cells(grid):
    """(..., M, M, M, 3) nodes -> (prod(...) · (M-1)³, 24) float32 cells."""
    M = grid.shape[-2]
    corners = [grid[..., d3:d3 + M - 1, d2:d2 + M - 1, d1:d1 + M - 1, :]
               for d3 in (0, 1) for d2 in (0, 1) for d1 in (0, 1)]
    return np.stack(corners, axis=-2).astype(np.float32).reshape(-1, 24)


def table_cells(table):
    """The :class:`TableCells` of a :class:`.colourtable.ColourTable` (float32: a
    two-spectrum table of 17 nodes and 50 dose nodes takes 59 MB)."""
    return TableCells(_cells(table.values), _cells(table.unmix))


def _trilinear(cells, row, f):
    """Trilinear lookup: ``cells`` rows ``row`` (m,), fractions ``f`` (m, 3) along the
    fastest axis first (k1, k2, k3), as the node group (bilinear over the first two,
    a Linear image lookup, then linear over the third): the 8 corner weights
    ``Π (1 - f) or f`` times the corners, one small matrix product per texel."""
    return (_corner_weights(f)[:, None, :] @ np.take(cells, row, axis=0).reshape(-1, 8, 3))[:, 0]


def _corner_weights(f):
    """(m, 8) float32 weights of the cell corners (corner ``(d3, d2, d1)`` at
    ``4 d3 + 2 d2 + d1``) for fractions ``f`` (m, 3): ``(f3 or 1 - f3) · (f2 or 1 - f2)
    · (f1 or 1 - f1)``, computed on (2, m) planes (contiguous, no per-column loop)."""
    m = f.shape[0]
    planes = np.empty((3, 2, m), dtype=np.float32)     # axis, (1 - f, f), texel
    planes[:, 1] = f.T
    np.subtract(np.float32(1.0), planes[:, 1], out=planes[:, 0])
    w = (planes[2][:, None, None, :] * planes[1][None, :, None, :]) * planes[0][None, None]
    return w.reshape(8, m).T


def _cell(x, M):
    """Cell index below node coordinates ``x`` (m, 3) on ``M`` nodes and the fractions
    (``min(floor x, M - 2)``, as the evaluator)."""
    i = np.minimum(np.floor(x), M - 2).astype(np.int32)
    return (i[:, 2] * (M - 1) + i[:, 1]) * (M - 1) + i[:, 0], x - i


def _coordinates(table, cells, rgb):
    """:func:`.colourtable.coordinates` through the unmixing's cells."""
    A = table.unmix_side
    u = np.clip(rgb, 0.0, 1.0) ** np.float32(1.0 / table.gamma) * np.float32(A - 1)
    row, f = _cell(u, A)
    y = _trilinear(cells.unmix, row, f)
    return np.clip(y, 0.0, 1.0) ** np.float32(1.0 / table.power) * np.float32(table.side - 1)


def _cube(table, u):
    """``(row, corner weights)`` of texels at node coordinates ``u`` (m, 3) on the change
    table's cube: the cell (:func:`_cell`) and its 8 corners' weights, the same at
    every dose node and light-mix vertex."""
    row, f = _cell(u, table.side)
    return row, _corner_weights(f)


def _node(table, cells, cube, slots, weights, t):
    """The change (m, 3) at dose nodes ``t`` (m,) of texels in cube cells ``cube``
    (:func:`_cube`), light-mix ``slots``, ``weights``: one node of
    :func:`.colourtable.change_nodes`, through the change's cells. The light-mix
    vertices share the cube cell and its corner weights, so their corners are mixed
    first (``Σ_v w_v · corners_v``) and interpolated once."""
    N, T = table.side, table.T
    row, w = cube
    mixed = None
    for v in range(slots.shape[1]):
        corners = np.take(cells.change, ((slots[:, v] * T + t) * (N - 1) ** 3) + row, axis=0)
        if weights is not None:
            corners *= weights[:, v:v + 1]
        if mixed is None:
            mixed = corners
        else:
            mixed += corners
    return (w[:, None, :] @ mixed.reshape(-1, 8, 3))[:, 0]


@dataclass
class PreparedTexels:
    """Per-texel state of the numpy evaluator (see the module docstring).

    Attributes
    ----------
    total : ndarray, shape (n,), float32
        Annual dose, lux·h.
    slots, weights : ndarray, shape (n, V), int32 and float32; or None
        Light-mix vertices (None for one spectrum).
    t0 : ndarray, shape (n,), int16
        Dose node of the band; -1 where none was evaluated yet.
    lo : ndarray, shape (n, 3), float32
        The change at node ``t0``.
    step : ndarray, shape (n, 3), float32
        The change at node ``t0 + 1`` minus ``lo``.
    u : ndarray, shape (n, 3), float32
        Node coordinates of the colour on the concentration cube
        (:func:`.colourtable.coordinates`), where ``t0 >= 0``.
    """

    total: np.ndarray
    slots: np.ndarray | None
    weights: np.ndarray | None
    t0: np.ndarray
    lo: np.ndarray
    step: np.ndarray
    u: np.ndarray

    @property
    def n(self):
        return self.total.shape[0]

    @property
    def nbytes(self):
        arrays = (self.total, self.slots, self.weights, self.t0, self.lo, self.step, self.u)
        return sum(a.nbytes for a in arrays if a is not None)


def prepare_texels(table, rates):
    """:class:`PreparedTexels` of texels lit by ``rates`` (S, n) lux·h a year, no band yet."""
    rates = np.asarray(rates, dtype=np.float32).reshape(table.S, -1)
    n = rates.shape[1]
    slots, weights = (None, None) if table.S == 1 else mix_vertices(table, rates)
    return PreparedTexels(rates.sum(axis=0), slots, weights, np.full(n, -1, np.int16),
                          np.zeros((n, 3), np.float32), np.zeros((n, 3), np.float32),
                          np.zeros((n, 3), np.float32))


def _get(a, at):
    """Rows ``at`` (a slice, or indices) of ``a``: a slice's view, else ``np.take`` (a
    quarter of the cost of ``a[indices]`` on rows of a few floats)."""
    return a[at] if isinstance(at, slice) else np.take(a, at, axis=0)


def _set(a, at, values):
    """``a[at] = values`` for rows of a C-contiguous ``a``: indices through ``np.put`` of
    whole rows (each one opaque item), a third of the cost of ``a[indices] = values``."""
    if isinstance(at, slice) or a.ndim == 1:
        a[at] = values
        return
    row = np.dtype((np.void, a.itemsize * a.shape[1]))
    values = np.ascontiguousarray(values, dtype=a.dtype)
    np.put(a.view(row).reshape(-1), at, values.view(row).reshape(-1))


def _mix(prep, at, n):
    """Light-mix ``slots``, ``weights`` of the ``n`` texels ``at`` (indices or a slice)."""
    if prep.slots is None:
        return np.zeros((n, 1), np.int32), None
    return _get(prep.slots, at), _get(prep.weights, at)


def _refresh(table, cells, prep, rgb, s0, s1, t0):
    """Evaluate the band at nodes ``t0`` (block ``s0:s1``) where it is elsewhere.

    A texel whose node moved by one keeps one end of its band (up: the old ``t0 + 1``
    is the new ``t0``; down: the old ``t0`` the new ``t0 + 1``) and evaluates one node;
    other moves evaluate two; the unmixing coordinates are kept from the first. Where
    every texel of the block moved (a first call, a long jump) its rows are read and
    written as one slice, not gathered and scattered one by one."""
    moved = np.flatnonzero(prep.t0[s0:s1] != t0)
    if moved.size == 0:
        return
    whole = moved.size == s1 - s0
    at, new = (slice(s0, s1), t0) if whole else (moved + s0, t0[moved])
    old = _get(prep.t0, at).astype(np.int32)
    fresh = old < 0
    if fresh.all():
        _set(prep.u, at, _coordinates(table, cells, _get(rgb, at)))
    elif fresh.any():
        rows = np.flatnonzero(fresh) + s0 if whole else at[fresh]
        _set(prep.u, rows, _coordinates(table, cells, np.take(rgb, rows, axis=0)))
    up = (old == new - 1) & ~fresh
    down = old == new + 1
    slots, weights = _mix(prep, at, new.size)
    cube = _cube(table, _get(prep.u, at))
    found = _node(table, cells, cube, slots, weights, new + up)  # up: t0 + 1, else t0
    lo_old = _get(prep.lo, at)
    lo = np.where(up[:, None], lo_old + _get(prep.step, at), found)
    hi = np.where(up[:, None], found, lo_old)                    # down: the old t0
    far = np.flatnonzero(~(up | down))                           # new, or moved further
    if far.size == new.size:
        hi = _node(table, cells, cube, slots, weights, new + 1)
    elif far.size:
        hi[far] = _node(table, cells, (cube[0][far], cube[1][far]), slots[far],
                        None if weights is None else weights[far], new[far] + 1)
    _set(prep.lo, at, lo)
    hi -= lo
    _set(prep.step, at, hi)
    _set(prep.t0, at, new)


def evaluate_prepared(table, prep, rgb, years, out=None, cells=None, codes=False):
    """Aged linear sRGB of colours ``rgb`` (n, 3) after ``years``: as
    :func:`.colourtable.evaluate` with the rates of ``prep``, whose band is updated.

    Parameters
    ----------
    table : ColourTable
    prep : PreparedTexels
        Of the same texels (updated in place).
    rgb : ndarray, shape (n, 3)
        Linear sRGB in [0, 1].
    years : float
        >= 0.
    out : ndarray, shape (n, 3) or (n, 4), optional
        Written in its first three channels.
    cells : TableCells, optional
        :func:`table_cells` of ``table`` (made when not given; keep it for the next call).
    codes : bool
        Write the 8-bit sRGB codes over 255 of the aged colour (what a byte sRGB image
        stores as that code: :func:`..colour.srgb8.srgb_code_floats`), encoded block by
        block on the evaluator's threads, instead of the linear colour.
    """
    rgb = np.asarray(rgb, dtype=np.float32).reshape(-1, 3)
    n = rgb.shape[0]
    if n != prep.n:
        raise ValueError(f"{n} colours for {prep.n} prepared texels")
    res = np.empty((n, 3), dtype=np.float32) if out is None else out
    if years == 0 and not table.history:
        res[:, :3] = srgb_code_floats(rgb) if codes else rgb
        return res
    cells = table_cells(table) if cells is None else cells

    def block(s0):
        s1 = min(s0 + _BLOCK, n)
        t0, ft = dose_node(table, prep.total[s0:s1], float(years))
        _refresh(table, cells, prep, rgb, s0, s1, t0)
        change = prep.step[s0:s1] * ft
        change += prep.lo[s0:s1]
        aged_colour(rgb[s0:s1], change, res[s0:s1], codes)

    in_blocks(block, n, _BLOCK, _THREADS)
    return res
