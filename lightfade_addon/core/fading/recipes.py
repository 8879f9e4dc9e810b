"""Material recipes: which colourants, on which substrate, how sensitive.

A :class:`Recipe` names its colourants and substrate (bundled data files, see
``docs/data.md``), the light sensitivity of each colourant (directly as ``beta`` or
as an ISO 105-B Blue Wool class), yellowing yields, and the solver settings from the
accuracy study. Which colourants are *unmixed* from a texture's colours and which
have a fixed concentration is part of the recipe: printed paper is unmixed into
cyan, magenta and yellow; bare wood has a fixed lignin content whatever its grain.

Blue Wool classes become ``beta`` in :mod:`.calibration` (each colourant on its own
colour change, or matched rates: ``docs/recipes.md``); :func:`beta_from_blue_wool`,
:func:`blue_wool_dose`, :func:`matched_rates` and :data:`JND_DELTA_E` are re-exported
here.
"""

from __future__ import annotations

import functools
import inspect
from dataclasses import dataclass, replace

import numpy as np

from .calibration import (
    CALIBRATIONS,
    JND_DELTA_E,
    beta_from_blue_wool,
    blue_wool_dose,
    matched_rates,
)
from .colourants import load_colourant, load_substrate
from .model import KINETICS, SimulationResult, simulate
from .lattice import dose_axis
from .spectra import WAVELENGTHS

__all__ = [
    "Recipe",
    "RECIPES",
    "get_recipe",
    "blue_wool_dose",
    "fastness_text",
    "beta_from_blue_wool",
    "matched_rates",
    "JND_DELTA_E",
]

#: Dose nodes every recipe simulation steps at (as many as the grid's default dose axis).
SOLVER_NODES = 65


@dataclass(frozen=True)
class Recipe:
    """A material's fading recipe.

    Attributes
    ----------
    name : str
        Identifier, e.g. ``"printed-paper"``.
    colourants : tuple of str
        Bundled colourant names (or data-file paths), in order.
    substrate : str
        Bundled substrate name (or path): the ground reflectance ``rho*``.
    blue_wool : tuple of float or None
        ISO Blue Wool class per colourant (1 fades fastest, 8 slowest); ``None`` for
        a colourant whose ``beta`` is given directly.
    beta : tuple of float or None
        Sensitivity per colourant where given directly (overrides ``blue_wool``).
    unmixed : tuple of str
        Colourants whose concentrations are unmixed from texture colours.
    fixed : tuple of (str, float)
        Concentrations of the other colourants, the same for every texel.
    yields : tuple of (str, str, float)
        ``(source, product, yield)``: what ``source`` loses, ``product`` gains × yield.
    calibration_light : str
        Light of the Blue Wool calibration (UV-filtered unless the colourant only
        reacts to UV, e.g. lignin, when ``calibration_uv_filter`` is False).
    calibration : {"colour", "rate"}
        What a Blue Wool class fixes (:func:`beta_from_blue_wool`). ``"colour"``: the
        colourant's own colour change, alone at full concentration. ``"rate"``: its
        photochemical rate: a colourant of class ``k`` is destroyed, in a mid-dark
        neutral under the calibration light, as fast as the recipe's first colourant
        (the reference) of class ``k``, so that colourants of one class fade together and a neutral built
        from them fades on tone (dyers' trichromats of matched fastness).
    kinetics : {"first-order", "paper", "shared"}
        The rate law (:func:`.fading.simulate`); first-order by default. Dyes and
        inks in one medium use ``"shared"`` (photosensitised fading: colourants of
        one class lose the same fraction whatever the mixture).
    thickness, layers, steps, scheme
        Medium thickness and solver settings (defaults: the accuracy study's choice).
    description : str
        One line for the UI.
    """

    name: str
    colourants: tuple
    substrate: str
    blue_wool: tuple
    unmixed: tuple
    description: str = ""
    beta: tuple | None = None
    fixed: tuple = ()
    yields: tuple = ()
    calibration_light: str = "daylight"
    calibration_uv_filter: bool = True
    calibration: str = "colour"
    thickness: float = 1.0
    layers: int | None = None
    steps: int | None = None
    scheme: str | None = None
    kinetics: str = "first-order"

    def __post_init__(self):
        C = len(self.colourants)
        if len(self.blue_wool) != C:
            raise ValueError(f"recipe {self.name!r}: blue_wool needs one class per colourant")
        if self.beta is not None and len(self.beta) != C:
            raise ValueError(f"recipe {self.name!r}: beta needs one value per colourant")
        unknown = set(self.unmixed) | {name for name, _ in self.fixed}
        unknown -= set(self.colourants)
        if unknown:
            raise ValueError(f"recipe {self.name!r}: unknown colourants {sorted(unknown)}")
        for k in self.blue_wool:
            if k is not None:
                blue_wool_dose(k)
        if self.calibration not in CALIBRATIONS:
            raise ValueError(f"recipe {self.name!r}: calibration must be one of "
                             f"{CALIBRATIONS}, got {self.calibration!r}")
        if self.kinetics not in KINETICS:
            raise ValueError(f"recipe {self.name!r}: kinetics must be one of {KINETICS}, "
                             f"got {self.kinetics!r}")

    # -- derived views -------------------------------------------------------------

    def index(self, colourant):
        return self.colourants.index(colourant)

    def solver(self):
        """Keyword arguments for :func:`.fading.simulate` (layers, steps, scheme, kinetics)."""
        defaults = inspect.signature(simulate).parameters
        out = {k: (getattr(self, k) if getattr(self, k) is not None else defaults[k].default)
               for k in ("layers", "steps", "scheme")}
        out["kinetics"] = self.kinetics
        return out

    def concentrations(self, unmixed):
        """(N, C) volume fractions: ``unmixed`` (N, Cu) placed among the fixed ones."""
        unmixed = np.asarray(unmixed, dtype=float)
        unmixed = unmixed.reshape(unmixed.shape[0] if unmixed.ndim > 1 else 1, len(self.unmixed))
        c = np.tile(self.base_concentrations(), (unmixed.shape[0], 1))
        for k, name in enumerate(self.unmixed):
            c[:, self.index(name)] = unmixed[:, k]
        return c

    def simulate(self, concentrations, irradiance, duration, record=None,
                 wavelengths=WAVELENGTHS, sensitivity=None):
        """:func:`.fading.simulate` with this recipe's optics, yields and solver.

        Steps are also taken at :data:`SOLVER_NODES` quadratically spaced doses
        (:func:`.lattice.dose_axis`, the grid's dose nodes), so every direct run is as
        fine in time as the grid.

        Parameters
        ----------
        concentrations : array_like, shape (..., C)
            Volume fractions of all colourants (see :meth:`concentrations`).
        irradiance : array_like, shape (W,)
            Light on the surface, e.g. a spectrum at 1 lux; ``duration`` in hours
            then makes doses in lux·h.
        duration : float
            Hours (or any unit matching ``irradiance``).
        record : array_like, optional
            Times at which to also return the reflectance.
        sensitivity : array_like, shape (C,), optional
            ``beta`` (default: :meth:`sensitivity`).

        Returns
        -------
        SimulationResult
        """
        lam = np.asarray(wavelengths, dtype=float)
        A, S, ground = self.optics(lam)
        beta = self.sensitivity(lam) if sensitivity is None else sensitivity
        wanted = None if record is None else np.asarray(record, dtype=float)
        # every run also steps at the grid's dose nodes, so that a direct run is never
        # coarser in time than the grid it is compared with (heavy fades need it)
        steps = dose_axis(SOLVER_NODES, duration)[1:] if duration > 0 else np.zeros(0)
        if wanted is not None:
            steps = np.union1d(steps, wanted)
        r = simulate(A, S, concentrations, beta, irradiance, ground, lam,
                     thickness=self.thickness, duration=duration, record=steps,
                     yields=self.yield_matrix(), **self.solver())
        if wanted is None:
            return SimulationResult(r.initial, r.reflectance, r.fractions)
        at = np.searchsorted(steps, wanted)
        return SimulationResult(r.initial, r.reflectance, r.fractions, r.history[at], wanted)

    def yield_matrix(self):
        """(C, C) yields matrix for :func:`.fading.simulate`, or None."""
        if not self.yields:
            return None
        Y = np.zeros((len(self.colourants),) * 2)
        for src, dst, y in self.yields:
            Y[self.index(src), self.index(dst)] = y
        return Y

    def base_concentrations(self):
        """(C,) concentrations with the fixed colourants set and the unmixed at 0."""
        c = np.zeros(len(self.colourants))
        for name, value in self.fixed:
            c[self.index(name)] = value
        return c

    # -- user adjustments ------------------------------------------------------------

    def with_blue_wool(self, blue_wool):
        """The recipe with its most sensitive colourant at class ``blue_wool``.

        The other colourants keep their class differences (printed paper's magenta
        stays two classes below its cyan); classes are clipped to 1..8.
        """
        classes = [k for k in self.blue_wool if k is not None]
        if not classes:
            return self
        shift = float(blue_wool) - min(classes)
        blue_wool_dose(blue_wool)
        return replace(self, beta=None, blue_wool=tuple(
            None if k is None else float(np.clip(k + shift, 1.0, 8.0)) for k in self.blue_wool))

    def with_classes(self, classes):
        """The recipe with some colourants at other Blue Wool classes (a fugitive dye).

        Parameters
        ----------
        classes : mapping of str to float
            Colourant name -> ISO Blue Wool class (1-8), e.g. ``{"yellow": 2}``: that
            dye fades as fast as a class-2 one while the others keep theirs.

        Raises
        ------
        ValueError
            An unknown colourant, one whose sensitivity is not given as a class (a
            product such as quinone), or a class outside 1-8.
        """
        new = list(self.blue_wool)
        for name, k in classes.items():
            if name not in self.colourants:
                raise ValueError(f"recipe {self.name!r} has no colourant {name!r}; its "
                                 f"colourants: {', '.join(self.colourants)}")
            j = self.index(name)
            if new[j] is None:
                raise ValueError(f"colourant {name!r} of recipe {self.name!r} does not fade "
                                 f"by itself (it is formed by light): no class to set")
            blue_wool_dose(k)
            new[j] = float(k)
        return replace(self, beta=None, blue_wool=tuple(new))

    def with_beta(self, beta):
        """The recipe with its most sensitive colourant at ``beta``, the others scaled."""
        b = self.sensitivity()
        if not np.isfinite(beta) or beta < 0:
            raise ValueError(f"beta must be a finite number >= 0, got {beta!r}")
        return replace(self, beta=tuple(float(x) for x in b * (beta / b.max())))

    # -- physics ----------------------------------------------------------------------

    def optics(self, wavelengths=WAVELENGTHS):
        """``(A, S, substrate)``: (C, W), (C, W), (W,) on ``wavelengths``."""
        return _optics(self.colourants, self.substrate, tuple(np.asarray(wavelengths, float)))

    def sensitivity(self, wavelengths=WAVELENGTHS):
        """(C,) ``beta`` per colourant, per (W m^-2 nm^-1 · nm · h · unit K)."""
        if self.beta is not None:
            return np.asarray(self.beta, dtype=float)
        return np.array([
            0.0 if k is None else beta_from_blue_wool(self, j, k, tuple(wavelengths))
            for j, k in enumerate(self.blue_wool)])


@functools.lru_cache(maxsize=64)
def _optics(colourants, substrate, wavelengths):
    lam = np.asarray(wavelengths)
    data = [load_colourant(name, lam) for name in colourants]
    A = np.stack([d.K for d in data])
    S = np.stack([d.S for d in data])
    return A, S, load_substrate(substrate, lam).reflectance


CMY = ("cyan", "magenta", "yellow")

#: The bundled presets, by name.
RECIPES = {r.name: r for r in (
    Recipe(
        name="printed-paper",
        description="Print or poster on paper: yellow and magenta fade first, greys go "
                    "blue (cyan lasts)",
        colourants=CMY, substrate="paper", unmixed=CMY, calibration="rate",
        kinetics="shared",
        blue_wool=(5.0, 3.5, 3.0)),
    Recipe(
        name="dyed-fabric",
        description="Dyed textile, rug or curtain: dyes of matched fastness, colours fade "
                    "on tone (lighter, duller)",
        colourants=CMY, substrate="fabric", unmixed=CMY, calibration="rate",
        kinetics="shared",
        blue_wool=(4.0, 4.0, 4.0)),
    Recipe(
        name="painted-wood",
        description="Painted furniture or woodwork: lightfast pigments over a white ground, "
                    "fade on tone, about 9x slower than fabric",
        colourants=CMY, substrate="white-ground", unmixed=CMY, calibration="rate",
        kinetics="shared",
        blue_wool=(6.0, 6.0, 6.0)),
    Recipe(
        name="bare-wood",
        description="Unfinished wood: pale woods darken, redden and yellow (lignin to "
                    "quinones), dark woods lighten (brown extractives bleach); most change "
                    "in the first year",
        colourants=("lignin", "quinone", "extractive"), substrate="wood",
        unmixed=("extractive",), fixed=(("lignin", 1.0),),
        yields=(("lignin", "quinone", 0.3),),
        blue_wool=(1.0, None, 2.7), calibration_uv_filter=False),
)}


def parse_classes(text):
    """Per-colourant Blue Wool classes from ``"yellow=2, magenta=3"`` (commas or spaces).

    Returns
    -------
    dict of str to float
        Colourant name -> class, for :meth:`Recipe.with_classes` (empty for blank text).

    Raises
    ------
    ValueError
        A word that is not ``COLOURANT=CLASS`` with a class from 1 to 8.

    Examples
    --------
    >>> parse_classes("yellow=2, magenta=3.5")
    {'yellow': 2.0, 'magenta': 3.5}
    """
    classes = {}
    for word in text.replace(",", " ").split():
        name, sep, value = word.partition("=")
        try:
            k = float(value)
        except ValueError:
            k = float("nan")
        if not sep or not name or not 1.0 <= k <= 8.0:
            raise ValueError(f"{word!r}: expected COLOURANT=CLASS with a Blue Wool class "
                             f"1-8, e.g. yellow=2")
        classes[name] = k
    return classes


def fastness_text(recipe):
    """Each colourant's Blue Wool class on one line, for the UI.

    Colourants formed by light (no class) are left out; a recipe given by ``beta``
    says so.

    Examples
    --------
    >>> fastness_text(RECIPES["printed-paper"])
    'cyan 5 · magenta 3.5 · yellow 3'
    """
    if recipe.beta is not None:
        return "sensitivity given as beta"
    return " · ".join(f"{name} {k:g}" for name, k in zip(recipe.colourants, recipe.blue_wool)
                      if k is not None)


def get_recipe(name):
    """A bundled recipe by name; ValueError listing the valid names otherwise."""
    try:
        return RECIPES[name]
    except KeyError:
        raise ValueError(f"unknown recipe {name!r}; valid recipes: {', '.join(RECIPES)}") from None
