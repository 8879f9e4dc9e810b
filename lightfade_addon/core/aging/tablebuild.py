"""Building a colour table (:mod:`.colourtable`): one simulation per concentration node.

The recipe's colourants are simulated at the paper's grid of concentrations (Section 5)
for each light mix of the set's spectra, recording the table's own dose axis (absolute
lux·h, :func:`.colourtable.dose_position`) up to :attr:`TableSettings.ceiling` (with
:attr:`TableSettings.substeps` points per node interval, fitted to the nodes); the
cube's nodes are unmixed (:mod:`.unmix`, to convergence, as ``age-image --exact``),
and so are :attr:`TableSettings.per_cell` random colours in every cell the gamut's
faces cross; their change is interpolated on that grid (:meth:`.grid.FadeGrid.curves`),
the dose axis cut where nothing changes any more, and the node values are the
least-squares fit of the evaluator's own interpolant to those changes
(:mod:`.tablefit`). Tables are kept on disk (:func:`load_or_build`) like grids, keyed
by everything they depend on.
"""

from __future__ import annotations

import hashlib
import io
import json
import math
import os
import tempfile
from dataclasses import dataclass, replace

import numpy as np

from ..fading.cache import directory
from ..colour.colorimetry import linear_srgb_to_XYZ, srgb_encode
from .colourtable import ColourTable, mix_resolution
from ..fading.model import simulate
from ..fading.grid import FadeGrid, GridSettings
from ..fading.gridbuild import XYZ_FLOOR, log_change
from ..fading.lattice import concentration_axis, mix_lattice
from .restore import restore
from ..fading.spectra import WAVELENGTHS, light_spectrum
from .table import in_blocks, mix_slots
from ..fading.unmix import get_unmixer
from .tablefit import (cell_samples, dose_fit, fine_doses, interpolation_matrix, kinked_cells,
                       lattice_solve)

__all__ = ["TABLE_FORMAT", "TableSettings", "build_table", "load_or_build", "table_key"]

#: Bumped whenever a table's contents would change for the same inputs.
TABLE_FORMAT = 2
#: Change (log XYZ) below which the dose axis counts as saturated.
_SATURATED = 2e-4
#: Colours whose change curves are computed at once (bounds the temporaries).
_FIT_BLOCK = 2048
#: Threads the cube's colours are unmixed on.
_THREADS = max(1, min(4, os.cpu_count() or 1))


@dataclass(frozen=True)
class TableSettings:
    """Resolution of a colour table.

    Attributes
    ----------
    side : int
        Nodes per channel of the colour cube (``N``).
    gamma : float
        The cube's encoding ``u = rgb ** (1 / gamma)`` (denser in the darks).
    per_decade : int
        Dose nodes per decade of lux·h.
    low_dose : float
        lux·h of dose node 1 (linear from 0 below it).
    ceiling : float
        Largest dose simulated, lux·h; the axis is cut where the recipe stops changing.
    grid : GridSettings
        Concentration nodes simulated (the paper's grid); the cube's colours are
        unmixed and interpolated on it (``points`` and ``power`` are used).
    substeps : int
        Dose points per node interval simulated and fitted (:mod:`.tablefit`); 1: the
        nodes themselves (2 takes ~0.05 off the 25-year error of smooth colours and
        doubles the simulation).
    per_cell : int
        Random colours per cube cell the gamut's faces cross (:func:`.tablefit.
        kinked_cells`) the node values are fitted to, besides the nodes (0: the nodes'
        own values). Tables with a history use the nodes only.
    """

    side: int = 17
    gamma: float = 2.2
    per_decade: int = 8
    low_dose: float = 1e4
    ceiling: float = 1e14
    grid: GridSettings = GridSettings(points=8)
    substeps: int = 1
    per_cell: int = 4

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
    """A :class:`.grid.FadeGrid` on ``doses`` (the grid's concentration nodes).

    Simulated at :attr:`TableSettings.substeps` points per dose interval and fitted
    to the nodes (:func:`.tablefit.dose_fit`): the change curves' interpolation in
    concentration is linear in the node values, so fitting here is fitting every
    colour's curve."""
    sub = max(1, settings.substeps)
    fine = fine_doses(settings.low_dose, settings.per_decade, doses.size, sub)
    axes = [concentration_axis(settings.grid.points, settings.grid.power)
            for _ in recipe.unmixed]
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


def _saturated_length(curves):
    """Dose nodes to keep: up to the first after which nothing changes by
    :data:`_SATURATED` any more (curves (U, M, T, 3))."""
    last = curves[:, :, -1:]
    moving = np.abs(curves - last).max(axis=(0, 1, 3)) > _SATURATED
    idx = np.flatnonzero(moving)
    return int(min(curves.shape[2], (idx[-1] + 2) if idx.size else 2))


def _unmix(unmixer, encoded):
    """Converged concentrations of encoded colours (n, 3), in blocks on threads (the
    rows are independent: the result does not depend on the blocks)."""
    c = np.zeros((encoded.shape[0], unmixer.Cu))
    if unmixer.Cu == 0:
        return c
    size = -(-encoded.shape[0] // _THREADS)

    def block(s0):
        c[s0:s0 + size] = unmixer.unmix(encoded[s0:s0 + size], encoded=True)

    in_blocks(block, encoded.shape[0], size, _THREADS)
    return c


def _curves(grid, c, initial, offset, rows):
    """Change curves (U, M, T, 3) of samples ``rows``, plus a history's ``offset``."""
    curves = grid.curves(c[rows], None if initial is None else initial[rows])
    if offset is not None:
        curves += offset[rows, None, None, :]
    return curves


def _fit(grid, u, N, c, initial, offset):
    """Node values (N³, M, T, 3) fitted to the samples' curves (:mod:`.tablefit`)."""
    W = interpolation_matrix(u, N)
    M, T = grid.change.shape[:2]
    rhs = np.zeros((N ** 3, M * T * 3))
    for s0 in range(0, u.shape[0], _FIT_BLOCK):
        rows = slice(s0, s0 + _FIT_BLOCK)
        curves = _curves(grid, c, initial, offset, rows)
        rhs += W[rows].T @ curves.reshape(curves.shape[0], -1).astype(np.float64)
    return lattice_solve(W, rhs).reshape(N ** 3, M, T, 3).astype(np.float32)


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
    N = settings.side
    doses = _dose_axis(settings)
    u = cell_samples(N, 0)
    seen = (u / (N - 1)) ** settings.gamma                  # linear sRGB, nodes first
    lost = None
    original = seen
    if prior is not None:
        say(0.0, "restoring the cube's colours to new")
        back = restore(seen, prior.years, recipe, prior.lights, encoding="linear",
                       **(restore_kw or {}))
        original, lost = back.image.astype(float), back.lost.reshape((N,) * 3)
    grid = _simulate(recipe, spectra, doses, settings, say)
    say(0.8, f"unmixing {seen.shape[0]} colours")
    unmixer = get_unmixer(recipe)
    c = _unmix(unmixer, srgb_encode(np.clip(original, 0, 1)))
    if prior is None and settings.per_cell > 0 and unmixer.Cu:
        u = cell_samples(N, settings.per_cell, cells=kinked_cells(c, N))
        seen = original = (u / (N - 1)) ** settings.gamma
        say(0.85, f"unmixing {seen.shape[0] - N ** 3} colours in the cells the gamut crosses")
        c = np.concatenate([c, _unmix(unmixer, srgb_encode(np.clip(seen[N ** 3:], 0, 1)))])
    initial = np.log(np.maximum(unmixer.XYZ(c), XYZ_FLOOR)) if grid.initial is not None else None
    offset = None
    if prior is not None:
        XYZ_seen = np.maximum(linear_srgb_to_XYZ(seen), XYZ_FLOOR)
        XYZ_new = np.maximum(linear_srgb_to_XYZ(np.clip(original, 0, None)), XYZ_FLOOR)
        offset = np.log(XYZ_new / XYZ_seen).astype(np.float32)
    # the axis is cut where the nodes (the first N³ samples) stop changing, then fitted
    T = _saturated_length(_curves(grid, c, initial, offset, slice(0, N ** 3)))
    grid = replace(grid, doses=grid.doses[:T], change=grid.change[:, :T], _spline=None)
    say(0.9, f"fitting the table to {seen.shape[0]} colours")
    fitted = _fit(grid, u, N, c, initial, offset)
    if prior is None:
        fitted[:, :, 0] = 0.0                                   # 0 years: the colour itself
    rows = mix_slots(len(keys), grid.q)
    values = np.zeros((rows.size, T, N, N, N, 3), dtype=np.float16)
    used = rows >= 0
    values[used] = np.moveaxis(fitted[:, rows[used], :T], 0, 2).reshape(
        int(used.sum()), T, N, N, N, 3)
    say(1.0, "table ready")
    return ColourTable(values, doses[:T].astype(np.float64), float(settings.gamma),
                       float(settings.per_decade), float(settings.low_dose), grid.q, len(keys),
                       prior is not None, table_key(recipe, keys, settings, prior), lost)

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
                                       info["S"], bool(info["history"]), key, lost)
        except (OSError, KeyError, ValueError):
            pass
    table = build_table(recipe, spectra_keys_, settings, prior, progress, restore_kw)
    if cache:
        _write(path, table)
    return table


def _write(path, table):
    buf = io.BytesIO()
    np.savez(buf, values=table.values, doses=table.doses, info=json.dumps(table.info()),
             lost=table.lost if table.lost is not None else np.zeros(0, bool))
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=".table-", suffix=".tmp", dir=path.parent)
        with os.fdopen(fd, "wb") as fh:
            fh.write(buf.getvalue())
        os.replace(tmp, path)
    except OSError:
        pass  # a read-only cache only costs a rebuild next time
