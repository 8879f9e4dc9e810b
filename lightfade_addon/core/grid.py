"""The mixture grid: selective interpolation of simulated fading (paper, Section 5).

Fading is simulated once at the nodes of a grid over

* the concentration of each *unmixed* colourant (``m`` points per axis, spaced as
  ``(k / (m - 1)) ** power`` so that they are denser near zero, where reflectance is
  most nonlinear in concentration),
* the spectral composition of the light (a simplex lattice over the scene's ``S``
  light spectra, resolution ``q``; one node when there is one spectrum), and
* the dose in lux·h (``T`` points spaced quadratically from 0 to ``max_dose``; one
  simulation per concentration and mix gives the whole dose axis through
  ``record``, thanks to reciprocity).

What is stored and interpolated is the *change*: ``log(XYZ_aged / XYZ_initial)``
per node, which varies smoothly where the reflectance itself does not, and which is
exactly zero at zero dose. A texel's aged colour is its original colour times the
interpolated change (``docs/grid.md`` has the accuracy study).
"""

from __future__ import annotations

import hashlib
import io
import itertools
import json
import os
import pathlib
import tempfile
from dataclasses import dataclass

import numpy as np

from .colorimetry import reflectance_to_XYZ
from .fading import simulate
from .spectra import WAVELENGTHS

__all__ = [
    "FadeGrid",
    "GridSettings",
    "build_grid",
    "concentration_axis",
    "dose_axis",
    "mix_lattice",
    "simplex_interpolation",
    "grid_cache_dir",
    "load_or_build",
]

#: Bumped whenever the grid's contents would change for the same inputs.
GRID_FORMAT = 1
#: Smallest XYZ value used in the log ratio (XYZ of a perfect white is about 1).
_XYZ_FLOOR = 1e-6


@dataclass(frozen=True)
class GridSettings:
    """Resolution of a grid.

    Attributes
    ----------
    points : int
        Nodes per concentration axis (``m``; the paper's 6 gives 6^3 = 216).
    power : float
        Spacing exponent of the concentration axes (1 = uniform; 2 = quadratic).
    doses : int
        Nodes on the dose axis (``T``), quadratically spaced.
    mix : int
        Resolution ``q`` of the light-mixture simplex lattice.
    """

    points: int = 10
    power: float = 1.6
    doses: int = 33
    mix: int = 2


def concentration_axis(m, power=1.6):
    """``m`` concentrations in [0, 1], ``(k / (m - 1)) ** power``, denser near 0."""
    if m < 2:
        raise ValueError(f"a concentration axis needs at least 2 points, got {m}")
    return np.linspace(0.0, 1.0, m) ** power


def dose_axis(T, max_dose):
    """``T`` doses in lux·h from 0 to ``max_dose``, quadratically spaced.

    Fading is fastest at first, so the early doses get the dense nodes; a dose
    ``D`` sits at fractional index ``sqrt(D / max_dose) * (T - 1)``.
    """
    if T < 2:
        raise ValueError(f"a dose axis needs at least 2 points, got {T}")
    if not max_dose > 0:
        raise ValueError(f"max_dose must be > 0 lux·h, got {max_dose!r}")
    return max_dose * np.linspace(0.0, 1.0, T) ** 2


def mix_lattice(S, q):
    """The simplex lattice: all weight vectors ``n / q`` with ``n`` summing to ``q``.

    Returns an (M, S) array, M = C(S - 1 + q, q); one row ``[1.0]`` when S = 1.
    Rows are ordered so that :func:`simplex_interpolation` can index them.
    """
    if S == 1:
        return np.ones((1, 1))
    rows = [n for n in itertools.product(range(q + 1), repeat=S) if sum(n) == q]
    return np.array(rows, dtype=float) / q


def _lattice_lookup(S, q):
    """Array from a composition's code ``sum(n_i (q + 1)**i)`` to its lattice row."""
    rows = [n for n in itertools.product(range(q + 1), repeat=S) if sum(n) == q]
    lookup = np.full((q + 1) ** S, -1, dtype=np.int64)
    radix = (q + 1) ** np.arange(S)
    for i, n in enumerate(rows):
        lookup[int(np.dot(n, radix))] = i
    return lookup, radix


def simplex_interpolation(w, q):
    """Lattice nodes and barycentric weights for mixture weights ``w``.

    Parameters
    ----------
    w : ndarray, shape (N, S)
        Non-negative weights summing to 1 (each texel's share of the dose from
        each light spectrum).
    q : int
        Lattice resolution.

    Returns
    -------
    nodes : ndarray of int, shape (N, S)
        Rows of :func:`mix_lattice` (S vertices of the enclosing lattice simplex).
    weights : ndarray, shape (N, S)
        Barycentric weights (non-negative, summing to 1).

    Notes
    -----
    Freudenthal's triangulation in cumulative coordinates ``y_i = q * sum(w[:i+1])``:
    the cube cell is split by sorting the fractional parts, which keeps every
    vertex a valid composition.
    """
    w = np.asarray(w, dtype=float)
    N, S = w.shape
    if S == 1:
        return np.zeros((N, 1), dtype=int), np.ones((N, 1))
    y = q * np.cumsum(w, axis=1)[:, :-1]                   # (N, S-1), non-decreasing
    y = np.clip(y, 0, q)
    base = np.minimum(np.floor(y), q - 1)
    frac = y - base
    # ties go to the later coordinate first, which keeps every vertex non-decreasing
    order = np.argsort(-(frac + 1e-9 * np.arange(S - 1)), axis=1, kind="stable")
    sorted_frac = np.take_along_axis(frac, order, axis=1)
    weights = np.empty((N, S))
    weights[:, 0] = 1.0 - sorted_frac[:, 0]
    weights[:, 1:-1] = sorted_frac[:, :-1] - sorted_frac[:, 1:]
    weights[:, -1] = sorted_frac[:, -1]
    lookup, radix = _lattice_lookup(S, q)
    nodes = np.empty((N, S), dtype=np.int64)
    vertex = base.copy()
    for k in range(S):
        if k > 0:
            np.put_along_axis(vertex, order[:, k - 1:k],
                              np.take_along_axis(vertex, order[:, k - 1:k], axis=1) + 1, axis=1)
        cum = np.concatenate([np.zeros((N, 1)), vertex, np.full((N, 1), q)], axis=1)
        parts = np.diff(cum, axis=1).round().astype(np.int64)
        nodes[:, k] = lookup[parts @ radix]
    return nodes, weights


@dataclass
class FadeGrid:
    """Simulated change of colour over concentrations × light mixture × dose.

    Attributes
    ----------
    key : str
        Hash of everything the grid depends on (the cache key).
    recipe : str
        Recipe name, for messages.
    axes : list of ndarray
        One concentration axis per unmixed colourant.
    mixes : ndarray, shape (M, S)
        The light-mixture lattice (weights of the S spectra).
    doses : ndarray, shape (T,)
        Dose axis, lux·h.
    change : ndarray, shape (M, T, m, ..., m, 3), float32
        ``log(XYZ_aged / XYZ_initial)`` at every node (zero at dose 0).
    q : int
        Lattice resolution of ``mixes``.
    """

    key: str
    recipe: str
    axes: list
    mixes: np.ndarray
    doses: np.ndarray
    change: np.ndarray
    q: int

    @property
    def max_dose(self):
        return float(self.doses[-1])

    # -- interpolation -------------------------------------------------------------

    def _concentration_corners(self, c):
        """Multilinear corners over the concentration axes: (flat index, weight) lists."""
        c = np.asarray(c, dtype=float).reshape(-1, len(self.axes))
        shape = [a.size for a in self.axes]
        lo, fr = [], []
        for k, axis in enumerate(self.axes):
            x = np.clip(c[:, k], 0.0, 1.0)
            i = np.clip(np.searchsorted(axis, x, side="right") - 1, 0, axis.size - 2)
            lo.append(i)
            fr.append((x - axis[i]) / (axis[i + 1] - axis[i]))
        corners = []
        for bits in itertools.product((0, 1), repeat=len(self.axes)):
            flat = np.zeros(c.shape[0], dtype=np.int64)
            weight = np.ones(c.shape[0])
            for k, b in enumerate(bits):
                flat = flat * shape[k] + lo[k] + b
                weight = weight * (fr[k] if b else 1.0 - fr[k])
            corners.append((flat, weight))
        return corners

    def curves(self, c):
        """Change along the dose axis for each concentration, for every mix node.

        Parameters
        ----------
        c : ndarray, shape (U, Cu)
            Concentrations of the unmixed colourants (Cu may be 0).

        Returns
        -------
        ndarray, shape (U, M, T, 3), float32
            ``log(XYZ_aged / XYZ_initial)`` interpolated in concentration.
        """
        M, T = self.change.shape[:2]
        table = self.change.reshape(M, T, -1, 3)
        c = np.asarray(c, dtype=float)
        out = np.zeros((c.shape[0], M, T, 3), dtype=np.float32)
        if not self.axes:
            out[:] = table[:, :, 0][None]
            return out
        for flat, weight in self._concentration_corners(c):
            out += weight[:, None, None, None].astype(np.float32) * \
                np.moveaxis(table[:, :, flat], 2, 0)
        return out

    def dose_position(self, dose):
        """Fractional index on the dose axis (clipped to the axis), (N,) -> (i, frac)."""
        T = self.doses.size
        s = np.sqrt(np.clip(np.asarray(dose, dtype=float) / self.max_dose, 0.0, 1.0)) * (T - 1)
        i = np.minimum(s.astype(np.int64), T - 2)
        return i, s - i

    def log_change(self, c, dose, mix=None):
        """``log(XYZ_aged / XYZ_initial)`` for samples, (N, 3).

        Parameters
        ----------
        c : array_like, shape (N, Cu)
            Concentrations of the unmixed colourants.
        dose : array_like, shape (N,)
            Total dose, lux·h (clipped to the grid's ``max_dose``).
        mix : array_like, shape (N, S), optional
            Dose share of each light spectrum (default: all from the first).
        """
        dose = np.asarray(dose, dtype=float).reshape(-1)
        N = dose.size
        S = self.mixes.shape[1]
        if mix is None:
            mix = np.zeros((N, S))
            mix[:, 0] = 1.0
        nodes, wm = simplex_interpolation(np.asarray(mix, dtype=float).reshape(N, S), self.q)
        curves = self.curves(np.asarray(c, dtype=float).reshape(N, -1))   # (N, M, T, 3)
        i, f = self.dose_position(dose)
        out = np.zeros((N, 3))
        rows = np.arange(N)
        for k in range(nodes.shape[1]):
            cv = curves[rows, nodes[:, k]]                                     # (N, T, 3)
            v = (1 - f)[:, None] * cv[rows, i] + f[:, None] * cv[rows, i + 1]
            out += wm[:, k, None] * v
        return out

    # -- serialisation ------------------------------------------------------------------

    def to_bytes(self):
        """The grid as bytes (an .npz with a checksum), e.g. to store in a .blend."""
        buf = io.BytesIO()
        meta = dict(format=GRID_FORMAT, key=self.key, recipe=self.recipe, q=self.q,
                    naxes=len(self.axes))
        arrays = {f"axis{k}": a for k, a in enumerate(self.axes)}
        arrays.update(mixes=self.mixes, doses=self.doses, change=self.change)
        digest = _digest(arrays)
        meta["sha256"] = digest
        np.savez(buf, meta=np.frombuffer(json.dumps(meta).encode(), dtype=np.uint8), **arrays)
        return buf.getvalue()

    @classmethod
    def from_bytes(cls, data):
        """Inverse of :meth:`to_bytes`; ValueError if the data is corrupt or partial."""
        try:
            with np.load(io.BytesIO(data), allow_pickle=False) as z:
                meta = json.loads(bytes(z["meta"]).decode())
                arrays = {k: z[k] for k in z.files if k != "meta"}
        except Exception as exc:  # zipfile, json and numpy errors alike
            raise ValueError(f"not a readable LightFade grid ({exc})") from None
        if meta.get("format") != GRID_FORMAT:
            raise ValueError(f"grid format {meta.get('format')} is not {GRID_FORMAT}")
        if _digest(arrays) != meta.get("sha256"):
            raise ValueError("grid checksum mismatch (corrupt or partial data)")
        axes = [arrays[f"axis{k}"] for k in range(meta["naxes"])]
        return cls(meta["key"], meta["recipe"], axes, arrays["mixes"], arrays["doses"],
                   arrays["change"], meta["q"])


def _digest(arrays):
    h = hashlib.sha256()
    for name in sorted(arrays):
        a = np.ascontiguousarray(arrays[name])
        h.update(name.encode())
        h.update(str(a.dtype).encode())
        h.update(str(a.shape).encode())
        h.update(a.tobytes())
    return h.hexdigest()


# -- building ---------------------------------------------------------------------------


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
    A, S, ground = recipe.optics(lam)
    beta = recipe.sensitivity(lam)
    axes = [concentration_axis(settings.points, settings.power) for _ in recipe.unmixed]
    mixes = mix_lattice(spectra.shape[0], settings.mix)
    doses = dose_axis(settings.doses, max_dose)

    base = recipe.base_concentrations()
    nodes = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, len(axes)) \
        if axes else np.zeros((1, 0))
    c = np.tile(base, (nodes.shape[0], 1))
    for k, name in enumerate(recipe.unmixed):
        c[:, recipe.index(name)] = nodes[:, k]

    shape = tuple(a.size for a in axes)
    change = np.empty((mixes.shape[0], doses.size) + shape + (3,), dtype=np.float32)
    for k, w in enumerate(mixes):
        if progress:
            progress(k / mixes.shape[0], f"simulating {recipe.name}: light mix {k + 1}/{len(mixes)}")
        r = simulate(A, S, c, beta, w @ spectra, ground, lam, thickness=recipe.thickness,
                     duration=doses[-1], record=doses[1:], yields=recipe.yield_matrix(),
                     **recipe.solver())
        XYZ0 = np.maximum(reflectance_to_XYZ(r.initial, lam), _XYZ_FLOOR)
        XYZ = np.maximum(reflectance_to_XYZ(r.history, lam), _XYZ_FLOOR)
        change[k, 0] = 0.0
        change[k, 1:] = np.log(XYZ / XYZ0).reshape((doses.size - 1,) + shape + (3,))
    if progress:
        progress(1.0, f"grid for {recipe.name} ready")
    key = grid_key(recipe, spectra, max_dose, settings, lam)
    return FadeGrid(key, recipe.name, axes, mixes, doses, change, settings.mix)


# -- the on-disk cache -------------------------------------------------------------------


def grid_cache_dir():
    """``$LIGHTFADE_CACHE``, else ``$XDG_CACHE_HOME/lightfade``, else ``~/.cache/lightfade``."""
    root = os.environ.get("LIGHTFADE_CACHE")
    if root:
        return pathlib.Path(root)
    xdg = os.environ.get("XDG_CACHE_HOME")
    return pathlib.Path(xdg or pathlib.Path.home() / ".cache") / "lightfade"


def load_or_build(recipe, spectra, max_dose, settings=GridSettings(), wavelengths=WAVELENGTHS,
                  cache=True, progress=None, store=None):
    """The grid from ``store``, the disk cache, or built (and put in both).

    The file name is the grid's key, so a change to anything it depends on makes a
    new file. Writes go to a temporary file in the same folder and are renamed into
    place (atomic on POSIX and Windows), so two processes building the same grid
    never leave a partial file; a corrupt or partial file is detected by its
    checksum and rebuilt.

    Parameters
    ----------
    store : MutableMapping[str, bytes], optional
        Looked in first and given every grid used (the Blender layer keeps the
        grids a .blend needs inside the file, so render nodes never simulate).
    """
    key = grid_key(recipe, spectra, max_dose, settings, wavelengths)
    if store is not None and key in store:
        try:
            grid = FadeGrid.from_bytes(store[key])
            if grid.key == key:
                return grid
        except ValueError:
            pass
    grid = _load_or_build_on_disk(key, recipe, spectra, max_dose, settings, wavelengths, cache,
                                  progress)
    if store is not None:
        store[key] = grid.to_bytes()
    return grid


def _load_or_build_on_disk(key, recipe, spectra, max_dose, settings, wavelengths, cache,
                           progress):
    path = grid_cache_dir() / f"grid-{key}.npz"
    if cache and path.exists():
        try:
            grid = FadeGrid.from_bytes(path.read_bytes())
            if grid.key == key:
                return grid
        except (OSError, ValueError):
            pass  # rebuilt below
    grid = build_grid(recipe, spectra, max_dose, settings, wavelengths, progress)
    if cache:
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(prefix=".grid-", suffix=".tmp", dir=path.parent)
            with os.fdopen(fd, "wb") as fh:
                fh.write(grid.to_bytes())
            os.replace(tmp, path)
        except OSError:
            pass  # a read-only cache only costs a rebuild next time
    return grid
