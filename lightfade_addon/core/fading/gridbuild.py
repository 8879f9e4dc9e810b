"""Building a :class:`.grid.FadeGrid`: one simulation per concentration node and light mix.

Reciprocity makes the dose axis free: each node is simulated once to the largest
dose with every dose node recorded on the way (``record``).
"""

from __future__ import annotations

import hashlib
import json

import numpy as np

from ..colour.colorimetry import reflectance_to_XYZ
from .grid import FadeGrid, GridSettings
from .lattice import concentration_axis, dose_axis, mix_lattice
from .spectra import WAVELENGTHS

__all__ = ["GRID_FORMAT", "XYZ_FLOOR", "build_grid", "grid_key", "log_change"]

#: Bumped whenever the grid's contents would change for the same inputs.
GRID_FORMAT = 3
#: Smallest XYZ value used in the log ratio (XYZ of a perfect white is about 1).
XYZ_FLOOR = 1e-6


def grid_key(recipe, spectra, max_dose, settings, wavelengths=WAVELENGTHS):
    """Hash of everything a grid depends on: recipe physics, spectra, dose, settings."""
    A, S, ground = recipe.optics(wavelengths)
    parts = {
        "format": GRID_FORMAT,
        "recipe": repr(recipe),
        "beta": recipe.sensitivity(wavelengths).tolist(),
        "settings": repr(settings),
        "max_dose": float(max_dose),
        "solver": recipe.solver(),
    }
    h = hashlib.sha256(json.dumps(parts, sort_keys=True).encode())
    for a in (A, S, ground, np.asarray(spectra, dtype=float), np.asarray(wavelengths, float)):
        h.update(np.ascontiguousarray(a, dtype=float).tobytes())
    return h.hexdigest()[:32]


def log_change(result, lam, shape):
    """``log XYZ_initial`` (``shape + (3,)``, float32) and the change ``log(XYZ / XYZ_initial)``
    at each recorded dose (``(T,) + shape + (3,)``) of a simulation ``result`` over the
    concentration nodes of ``shape``; XYZ floored at :data:`XYZ_FLOOR` (black has no log)."""
    XYZ0 = np.maximum(reflectance_to_XYZ(result.initial, lam), XYZ_FLOOR)
    XYZ = np.maximum(reflectance_to_XYZ(result.history, lam), XYZ_FLOOR)
    T = XYZ.shape[0]
    return (np.log(XYZ0).reshape(shape + (3,)).astype(np.float32),
            np.log(XYZ / XYZ0).reshape((T,) + shape + (3,)))


def build_grid(recipe, spectra, max_dose, settings=GridSettings(), wavelengths=WAVELENGTHS,
               progress=None):
    """Simulate a recipe's grid.

    Parameters
    ----------
    recipe : Recipe
    spectra : array_like, shape (S, W)
        The scene's light spectra, each at 1 lux (``spectra.light_spectrum``).
    max_dose : float
        Largest dose the grid must cover, lux·h.
    settings : GridSettings
    progress : callable(fraction, message), optional

    Returns
    -------
    FadeGrid
    """
    lam = np.asarray(wavelengths, dtype=float)
    spectra = np.atleast_2d(np.asarray(spectra, dtype=float))
    axes = [concentration_axis(settings.points, settings.power) for _ in recipe.unmixed]
    mixes = mix_lattice(spectra.shape[0], settings.mix)
    doses = dose_axis(settings.doses, max_dose)

    nodes = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, len(axes)) \
        if axes else np.zeros((1, 0))
    c = recipe.concentrations(nodes)

    shape = tuple(a.size for a in axes)
    change = np.empty((mixes.shape[0], doses.size) + shape + (3,), dtype=np.float32)
    initial = None
    for k, w in enumerate(mixes):
        if progress:
            progress(k / mixes.shape[0], f"simulating {recipe.name}: light mix {k + 1}/{len(mixes)}")
        r = recipe.simulate(c, w @ spectra, doses[-1], record=doses[1:], wavelengths=lam)
        log_initial, change[k, 1:] = log_change(r, lam, shape)
        if axes:
            initial = log_initial
        change[k, 0] = 0.0
    if progress:
        progress(1.0, f"grid for {recipe.name} ready")
    key = grid_key(recipe, spectra, max_dose, settings, lam)
    return FadeGrid(key, recipe.name, axes, mixes, doses, change, settings.mix, initial)
