"""Building a colour table (:mod:`.colourtable`): one simulation per concentration node.

The recipe's colourants are simulated at the paper's grid of concentrations (Section 5)
for each light mix of the set's spectra, recording the table's dose axis (absolute
lux·h, :func:`.colourtable.dose_position`) up to :attr:`TableSettings.ceiling` with
:attr:`TableSettings.substeps` points per node interval, fitted to the nodes
(:mod:`.tablefit`); the change is interpolated from the grid at the table's own, finer
concentration nodes (:meth:`.grid.FadeGrid.curves`) and the dose axis cut where nothing
changes any more. The unmixing table is ``Φ`` (:mod:`..fading.unmix`, Eq. U2, to
convergence as ``age-image --exact``) at the colour cube's nodes, solved coarse to
fine (:func:`_cube_solution`). A table with a history is built over
the seen colours' cube instead: each node restored to new (:mod:`.restore`), unmixed
and its change interpolated on the paper's grid (:meth:`.grid.FadeGrid.curves`).
Tables are kept on disk (:func:`load_or_build`) like grids, keyed by everything they
depend on.
"""

from __future__ import annotations

import functools
import hashlib
import io
import itertools
import json
import math
import os
import tempfile
from concurrent.futures import ThreadPoolExecutor, wait
from dataclasses import dataclass

import numpy as np

from ..fading.cache import directory
from ..colour.colorimetry import linear_srgb_to_XYZ, srgb_encode
from .colourtable import ColourTable, cube_colours, mix_resolution
from ..fading.model import simulate
from ..fading.grid import FadeGrid, GridSettings
from ..fading.gridbuild import XYZ_FLOOR, log_change
from ..fading.lattice import concentration_axis, mix_lattice
from .restore import restore
from ..fading.spectra import WAVELENGTHS, light_spectrum
from .table import in_blocks, mix_slots
from ..fading.unmix import EXTENSION_STEPS, get_unmixer
from .tablefit import dose_fit, fine_doses

__all__ = ["TABLE_FORMAT", "TableSettings", "build_table", "build_tables", "load_or_build",
           "table_key"]

#: Bumped whenever a table's contents would change for the same inputs.
TABLE_FORMAT = 3
#: Change (log XYZ) below which the dose axis counts as saturated.
_SATURATED = 2e-4
#: ``Φ`` is kept within [-UNMIX_MARGIN, 1 + UNMIX_MARGIN]: past it the clip decides.
UNMIX_MARGIN = 1.0
#: Nodes a side of the coarsest colour cube unmixed from the unmixer's own table
#: (:func:`_cube_solution`): 49 nodes are solved as 7, 13, 25, 49.
_COARSEST = 7
#: Threads the cube's colours are unmixed on.
_THREADS = max(1, min(4, os.cpu_count() or 1))
#: Tables built at once (:func:`build_tables`).
TABLE_THREADS = max(1, min(2, os.cpu_count() or 1))
#: Seconds between :func:`build_tables`' progress reports.
_POLL = 0.25


@dataclass(frozen=True)
class TableSettings:
    """Resolution of a colour table.

    Attributes
    ----------
    side : int
        Nodes per axis of the change table (``N``): per unmixed colourant (with a
        history: per channel of the seen colour's cube).
    unmix_side : int
        Nodes per channel of the unmixing table's colour cube (``A``).
    gamma : float
        The colour cube's encoding ``u = rgb ** (1 / gamma)`` (denser in the darks).
    power : float
        The concentration axis: node ``i`` at ``c = (i / (N - 1)) ** power`` (denser
        near 0, where reflectance changes fastest).
    per_decade : int
        Dose nodes per decade of lux·h.
    low_dose : float
        lux·h of dose node 1 (linear from 0 below it).
    ceiling : float
        Largest dose simulated, lux·h; the axis is cut where the recipe stops changing.
    grid : GridSettings
        The concentration grid simulated (the paper's grid; ``points`` and ``power``):
        the change at the table's nodes (with a history: at the restored colours) is
        interpolated on it.
    substeps : int
        Dose points per node interval simulated and fitted (:mod:`.tablefit`); 1: the
        nodes themselves.
    """

    side: int = 17
    unmix_side: int = 49
    gamma: float = 2.2
    power: float = 1.6
    per_decade: int = 8
    low_dose: float = 1e4
    ceiling: float = 1e14
    grid: GridSettings = GridSettings(points=9)
    substeps: int = 2

def _dose_axis(settings):
    """Dose nodes 0, low, …, ceiling (lux·h)."""
    decades = math.log10(settings.ceiling / settings.low_dose)
    n = int(math.ceil(decades * settings.per_decade)) + 1
    return np.concatenate([[0.0], settings.low_dose * 10.0 ** (np.arange(n) / settings.per_decade)])


def table_key(recipe, spectra_keys_, settings, prior=None):
    """Hash of everything a table depends on."""
    A, S, ground = recipe.optics(WAVELENGTHS)
    parts = {"format": TABLE_FORMAT, "recipe": repr(recipe), "settings": repr(settings),
             "spectra": [list(k) for k in spectra_keys_], "prior": repr(prior),
             "beta": recipe.sensitivity(WAVELENGTHS).tolist(), "solver": recipe.solver()}
    h = hashlib.sha256(json.dumps(parts, sort_keys=True, default=str).encode())
    for a in (A, S, ground):
        h.update(np.ascontiguousarray(a, dtype=float).tobytes())
    return h.hexdigest()[:32]


def _simulate(recipe, spectra, doses, settings, say):
    """A :class:`.grid.FadeGrid` on ``doses`` at the concentration nodes of the paper's
    grid (:attr:`TableSettings.grid`).

    Simulated at :attr:`TableSettings.substeps` points per dose interval and fitted
    to the nodes (:func:`.tablefit.dose_fit`): the change curves' interpolation in
    concentration is linear in the node values, so fitting here is fitting every
    colour's curve."""
    sub = max(1, settings.substeps)
    fine = fine_doses(settings.low_dose, settings.per_decade, doses.size, sub)
    grid = settings.grid
    axes = [concentration_axis(grid.points, grid.power) for _ in recipe.unmixed]
    q = mix_resolution(spectra.shape[0])
    mixes = mix_lattice(spectra.shape[0], q)
    nodes = (np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, len(axes))
             if axes else np.zeros((1, 0)))
    c = recipe.concentrations(nodes)
    shape = tuple(a.size for a in axes)
    A, Sc, ground = recipe.optics(WAVELENGTHS)
    beta = recipe.sensitivity(WAVELENGTHS)
    change = np.empty((mixes.shape[0], fine.size) + shape + (3,), dtype=np.float32)
    initial = None
    for k, w in enumerate(mixes):
        say(0.1 + 0.7 * k / len(mixes), f"simulating {recipe.name}: light mix {k + 1}/{len(mixes)}")
        # the recipe's own solver, stepping at the fine dose points only (its extra
        # cubic nodes, Recipe.simulate, would all lie past 10⁸ lux·h on this long axis)
        r = simulate(A, Sc, c, beta, w @ spectra, ground, WAVELENGTHS,
                     thickness=recipe.thickness, duration=fine[-1], record=fine[1:],
                     yields=recipe.yield_matrix(), **recipe.solver())
        log_initial, change[k, 1:] = log_change(r, WAVELENGTHS, shape)
        if axes:
            initial = log_initial
        change[k, 0] = 0.0
    change = np.moveaxis(dose_fit(np.moveaxis(change, 1, -2), sub), -2, 1)
    return FadeGrid("", recipe.name, axes, mixes, doses, change, q, initial)


def _saturated_length(values):
    """Dose nodes to keep: up to the first after which nothing changes by
    :data:`_SATURATED` any more (values (M, T, ..., 3))."""
    moving = np.abs(values - values[:, -1:]).reshape(values.shape[:2] + (-1,)).max(axis=(0, 2))
    idx = np.flatnonzero(moving > _SATURATED)
    return int(min(values.shape[1], (idx[-1] + 2) if idx.size else 2))


def _solve(unmixer, encoded, extended=False):
    """Converged concentrations (``extended``: ``Φ``, unbounded) of encoded colours
    (n, 3), in blocks on threads (:func:`_by_rows`)."""
    # three colourants: Eq. U1 is square, one solution per colour, reached from the
    # table of Φ; fewer: least squares, whose local minima the full solve must choose
    # as the exact path does
    steps = EXTENSION_STEPS if unmixer.square else None
    if extended:
        return _by_rows(lambda rows: unmixer.extended(encoded[rows], encoded=True, steps=steps),
                        encoded.shape[0], (unmixer.Cu,))
    return _by_rows(lambda rows: unmixer.unmix(encoded[rows], encoded=True),
                    encoded.shape[0], (unmixer.Cu,))


def _by_rows(solve, n, shape):
    """(n,) + ``shape`` rows of ``solve(rows)`` (a slice), in blocks on threads (the rows
    are independent: the result does not depend on the blocks)."""
    out = np.zeros((n,) + tuple(shape))
    if out.size == 0:
        return out
    size = -(-n // _THREADS)

    def block(s0):
        rows = slice(s0, s0 + size)
        out[rows] = solve(rows)

    in_blocks(block, n, size, _THREADS)
    return out


def _midpoints(values, axis):
    """``values`` with the point halfway between each pair of neighbours along ``axis``
    inserted (``n >= 4`` nodes to ``2 n - 1``): the cubic through the four nearest
    nodes, ``(9 (v_i + v_i+1) - v_i-1 - v_i+2) / 16``, one-sided at the ends,
    ``(5 v_0 + 15 v_1 - 5 v_2 + v_3) / 16`` (error O(h⁴) where ``values`` is smooth)."""
    v = np.moveaxis(values, axis, 0)
    n = v.shape[0]
    out = np.empty((2 * n - 1,) + v.shape[1:])
    out[::2] = v
    mid = out[1::2]
    mid[1:-1] = (9.0 * (v[1:-2] + v[2:-1]) - v[:-3] - v[3:]) / 16.0
    mid[0] = (5.0 * v[0] + 15.0 * v[1] - 5.0 * v[2] + v[3]) / 16.0
    mid[-1] = (5.0 * v[-1] + 15.0 * v[-2] - 5.0 * v[-3] + v[-4]) / 16.0
    return np.moveaxis(out, 0, axis)


def _refined(values):
    """``values`` (n, n, n, ...) on the cube of ``2 n - 1`` nodes a side
    (:func:`_midpoints` along each axis)."""
    for axis in range(3):
        values = _midpoints(values, axis)
    return values


def _cube_solution(unmixer, encoded):
    """``Φ`` (A, A, A, Cu), unbounded, at a cube of encoded colours (A, A, A, 3), coarse
    to fine.

    With three colourants (a square system: one solution per colour) every other node
    is the cube of ``(A + 1) / 2`` nodes a side, solved first (the same solve of the
    same colours); the other nodes start from its cubic interpolation
    (:func:`_refined`), about 1e-4 from ``Φ`` where the unmixer's own 17³ table is
    1e-2 off, with its Jacobians interpolated the same way as the step matrix
    (:meth:`..fading.unmix.Unmixer.continued`): the same solution within 4.3e-6 (the
    plain solve's own distance to it: 1.7e-6) for 4.5 evaluations of the forward model
    a node instead of 13. The coarsest cube
    (:data:`_COARSEST`) is solved as the unmixer's table is, without it
    (:meth:`..fading.unmix.Unmixer.direct`: 343 colours, where building the table
    costs 4913). With fewer colourants (least squares, whose local minima depend on
    the start): the plain solve from the unmixer's table at every node."""
    A, Cu = encoded.shape[0], unmixer.Cu
    if not unmixer.square:
        return _solve(unmixer, encoded.reshape(-1, 3), extended=True).reshape(A, A, A, Cu)
    if A % 2 == 0 or A < 2 * _COARSEST - 1:
        flat = encoded.reshape(-1, 3)
        return _by_rows(lambda rows: unmixer.direct(flat[rows], encoded=True),
                        A ** 3, (Cu,)).reshape(A, A, A, Cu)
    coarse = _cube_solution(unmixer, encoded[::2, ::2, ::2])
    inner = np.clip(coarse.reshape(-1, Cu), 0.0, 1.0)
    J = _by_rows(lambda rows: unmixer.jacobian(inner[rows]), inner.shape[0], (3, Cu))
    new = np.ones((A, A, A), dtype=bool)
    new[::2, ::2, ::2] = False
    colours, start = encoded[new], _refined(coarse)[new]
    J = _refined(J.reshape(coarse.shape[:3] + (3, Cu)))[new]
    phi = np.empty((A, A, A, Cu))
    phi[::2, ::2, ::2] = coarse
    phi[new] = _by_rows(lambda rows: unmixer.continued(colours[rows], start[rows], J[rows],
                                                       encoded=True), colours.shape[0], (Cu,))
    return phi


def _unmixing(unmixer, settings, say):
    """``Φ`` at the colour cube's nodes, (A, A, A, 3) axes b, g, r, float16; unused
    colourants 0. It depends on the recipe's optics only: the tables of one recipe
    under several light sets share it (kept per process)."""
    say(0.8, f"unmixing {settings.unmix_side ** 3} colours")
    return _unmixing_cached(unmixer, settings.unmix_side, settings.gamma).copy()


@functools.lru_cache(maxsize=8)
def _unmixing_cached(unmixer, A, gamma):
    """:func:`_unmixing` of an :class:`..fading.unmix.Unmixer` (one per optics)."""
    out = np.zeros((A ** 3, 3))
    encoded = srgb_encode(cube_colours(A, gamma)).reshape(A, A, A, 3)
    phi = _cube_solution(unmixer, encoded).reshape(A ** 3, -1)
    out[:, :unmixer.Cu] = np.clip(phi, -UNMIX_MARGIN, 1.0 + UNMIX_MARGIN)
    return out.reshape(A, A, A, 3).astype(np.float16)


def _curves(grid, unmixer, c):
    """Change curves (n, M, T, 3) of concentrations ``c`` (n, Cu) on the simulated
    ``grid`` (:meth:`.grid.FadeGrid.curves`; where the grid keeps the unexposed colour,
    each colour's own, from the forward model, so it is exact)."""
    initial = np.log(np.maximum(unmixer.XYZ(c), XYZ_FLOOR)) if grid.initial is not None else None
    return grid.curves(c, initial)


def _over_concentrations(recipe, spectra, doses, settings, say):
    """The change (M, T, N, N, N, 3), axes mix, dose, k3, k2, k1, at the concentration
    nodes ``c = (k / (N - 1)) ** power``: the paper's grid (:attr:`TableSettings.grid`,
    coarser) simulated and interpolated there (:meth:`.grid.FadeGrid.curves`: a cubic
    spline of the aged colour, the unexposed colour exact)."""
    N = settings.side
    grid = _simulate(recipe, spectra, doses, settings, say)
    unmixer = get_unmixer(recipe)
    Cu = unmixer.Cu
    k = (np.arange(N) / (N - 1.0)) ** settings.power
    c = np.stack(np.meshgrid(*[k] * Cu, indexing="ij"), -1).reshape(-1, Cu)
    curves = _curves(grid, unmixer, c)                     # (N^Cu, M, T, 3), c1 slowest
    change = np.moveaxis(curves, 0, 2).reshape(curves.shape[1:3] + (N,) * Cu + (1,) * (3 - Cu) + (3,))
    change = np.broadcast_to(change, change.shape[:2] + (N, N, N, 3))
    return np.ascontiguousarray(change.transpose(0, 1, 4, 3, 2, 5))


def _over_seen_colours(recipe, spectra, doses, settings, prior, restore_kw, say):
    """With a history: the change (M, T, N, N, N, 3), axes mix, dose, b, g, r of the
    seen colour's cube, from the restored colour (dose 0: the restoration), and the
    nodes whose original the prior light erased."""
    N = settings.side
    seen = cube_colours(N, settings.gamma)
    say(0.0, "restoring the cube's colours to new")
    back = restore(seen, prior.years, recipe, prior.lights, encoding="linear",
                   **(restore_kw or {}))
    original, lost = back.image.astype(float), back.lost.reshape((N,) * 3)
    grid = _simulate(recipe, spectra, doses, settings, say)
    unmixer = get_unmixer(recipe)
    say(0.8, f"unmixing {seen.shape[0]} colours")
    c = _solve(unmixer, srgb_encode(np.clip(original, 0, 1)))
    curves = _curves(grid, unmixer, c)                     # (N³, M, T, 3)
    XYZ_seen = np.maximum(linear_srgb_to_XYZ(seen), XYZ_FLOOR)
    XYZ_new = np.maximum(linear_srgb_to_XYZ(np.clip(original, 0, None)), XYZ_FLOOR)
    curves += np.log(XYZ_new / XYZ_seen).astype(np.float32)[:, None, None, :]
    change = np.moveaxis(curves, 0, 2).reshape(curves.shape[1:3] + (N, N, N, 3))
    return change, lost


def build_table(recipe, spectra_keys_, settings=TableSettings(), prior=None, progress=None,
                restore_kw=None):
    """Build the colour table of ``recipe`` under the spectra ``spectra_keys_``.

    Parameters
    ----------
    recipe : Recipe
    spectra_keys_ : sequence of (spectrum name, uv_filter)
        The set's spectra (:func:`.lights.spectra_keys`), 1 to 4.
    settings : TableSettings
    prior : Prior, optional
        The texture is already old: the cube's colours are seen colours, restored to
        new first (:func:`.restore.restore`), and the change is from the seen colour.
    progress : callable(fraction, message), optional
    restore_kw : dict, optional
        Extra keyword arguments of :func:`.restore.restore` (grid store, cache).

    Returns
    -------
    ColourTable
    """
    say = progress or (lambda f, m: None)
    keys = [tuple(k) for k in spectra_keys_]
    spectra = np.stack([light_spectrum(s, WAVELENGTHS, uv) for s, uv in keys])
    doses = _dose_axis(settings)
    q = mix_resolution(len(keys))
    if prior is None:
        change, lost = _over_concentrations(recipe, spectra, doses, settings, say), None
        unmix = _unmixing(get_unmixer(recipe), settings, say)
    else:
        change, lost = _over_seen_colours(recipe, spectra, doses, settings, prior,
                                          restore_kw, say)
        u = np.linspace(0.0, 1.0, settings.unmix_side) ** settings.power   # k = u
        b, g, r = np.meshgrid(u, u, u, indexing="ij")
        unmix = np.stack([r, g, b], -1).astype(np.float16)
    T = _saturated_length(change)
    rows = mix_slots(len(keys), q)
    N = settings.side
    values = np.zeros((rows.size, T, N, N, N, 3), dtype=np.float16)
    used = rows >= 0
    values[used] = change[rows[used], :T]
    say(1.0, "table ready")
    return ColourTable(values, doses[:T].astype(np.float64), float(settings.gamma),
                       float(settings.per_decade), float(settings.low_dose), q, len(keys),
                       prior is not None, table_key(recipe, keys, settings, prior), unmix,
                       float(settings.power), lost)

def load_or_build(recipe, spectra_keys_, settings=TableSettings(), prior=None, progress=None,
                  cache=True, restore_kw=None):
    """The table from the disk cache (:func:`.cache.directory`), or built and kept there."""
    key = table_key(recipe, spectra_keys_, settings, prior)
    path = directory() / f"table-{key}.npz"
    if cache:
        try:
            with np.load(path, allow_pickle=False) as z:
                info = json.loads(str(z["info"]))
                if info["key"] == key:
                    lost = z["lost"] if z["lost"].size else None
                    return ColourTable(z["values"], z["doses"], info["gamma"],
                                       info["per_decade"], info["low_dose"], info["q"],
                                       info["S"], bool(info["history"]), key, z["unmix"],
                                       info["power"], lost)
        except (OSError, KeyError, ValueError):
            pass
    table = build_table(recipe, spectra_keys_, settings, prior, progress, restore_kw)
    if cache:
        _write(path, table)
    return table


def _write(path, table):
    buf = io.BytesIO()
    np.savez(buf, values=table.values, doses=table.doses, unmix=table.unmix,
             info=json.dumps(table.info()),
             lost=table.lost if table.lost is not None else np.zeros(0, bool))
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=".table-", suffix=".tmp", dir=path.parent)
        with os.fdopen(fd, "wb") as fh:
            fh.write(buf.getvalue())
        os.replace(tmp, path)
    except OSError:
        pass  # a read-only cache only costs a rebuild next time


def build_tables(requests, settings=TableSettings(), progress=None, threads=None):
    """The tables of several ``(recipe, spectra keys)`` requests (no history), each from
    the disk cache or built and kept there (:func:`load_or_build`), the builds
    :data:`TABLE_THREADS` at a time on threads: the simulation's sweeps, ``Φ``'s blocks
    and the curves' splines are long numpy and scipy calls that release the GIL (the
    ten-material room's two tables on 2 cores: 3.5-3.9 s wall serially, 3.0-3.4 s
    together, for 12-20 % more process time). The keys (and so the Blue Wool
    calibration, many short calls) are computed first, here. ``progress`` is called from
    this thread only: every :data:`_POLL` seconds with the builds' latest steps.

    Returns
    -------
    dict
        ``{table key: ColourTable}``; a request whose build fails is left out (its
        caller builds it again and reports the error).
    """
    say = progress or (lambda f, m: None)
    todo = {}
    for recipe, keys in requests:
        keys = [tuple(k) for k in keys]
        todo.setdefault(table_key(recipe, keys, settings), (recipe, keys))
    for recipe, _keys in todo.values():
        get_unmixer(recipe)                       # one per optics, made here
    out, n = {}, len(todo)
    if not n:
        return out
    order = itertools.count()
    steps = {key: (0.0, "", -1) for key in todo}      # each build's (fraction, message, when)

    def build(key):
        recipe, keys = todo[key]

        def step(f, m):                           # one assignment: safe across threads
            steps[key] = (f, m if recipe.name in m else f"{recipe.name}: {m}", next(order))

        return load_or_build(recipe, keys, settings, progress=step)

    said = None
    with ThreadPoolExecutor(threads or TABLE_THREADS) as pool:
        futures = {pool.submit(build, key): key for key in todo}
        pending = set(futures)
        while pending:
            done, pending = wait(pending, timeout=_POLL)
            for future in done:
                key = futures[future]
                try:
                    out[key] = future.result()
                except ValueError:
                    pass
                steps[key] = (1.0, f"{todo[key][0].name}: table ready", next(order))
            message = max(steps.values(), key=lambda s: s[2])[1]
            now = (sum(s[0] for s in steps.values()) / n, message)
            if message and now != said:           # the last, at 1, is always said
                say(*now)
                said = now
    return out
