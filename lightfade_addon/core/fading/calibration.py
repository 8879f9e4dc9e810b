"""Blue Wool calibration: from an ISO Blue Wool class to each colourant's ``beta``.

A Blue Wool class ``k`` means a just-noticeable fade, ΔE*ab = 1.6 (grey scale step 4),
after ``0.4 Mlx·h × 3**(k - 1)`` of a UV-free reference light (CIE D65 behind a UV
filter; DESIGN.md, "Light spectra and sensitivity"). A recipe's ``calibration`` says
what the class fixes (``docs/recipes.md``):

``"colour"``
    the colourant alone at full concentration on the recipe's substrate fades that much
    at that dose (:func:`beta_from_blue_wool` solves for ``beta`` by Brent's method);
``"rate"``
    the recipe's first colourant is calibrated so, and every other colourant of class
    ``k`` is destroyed, in a mid-dark neutral under daylight through glass, as fast as
    a class-``k`` first colourant (:func:`matched_rates`): equal classes, equal rates.

The functions take a :class:`.recipes.Recipe` (they use its ``simulate``, ``optics``,
``solver`` and ``base_concentrations``). A calibrated ``beta`` costs some 17
simulations; it is kept in memory and in the grids' folder on disk
(:func:`.cache.directory`, one small file per recipe, colourant and class, keyed by
everything it depends on), so a new process does not solve it again.
"""

from __future__ import annotations

import functools
import hashlib
import json
import os
import tempfile
from dataclasses import replace

import numpy as np
from scipy.optimize import brentq

from ..colour.colorimetry import delta_E_ab, reflectance_to_Lab
from .model import simulate
from .spectra import WAVELENGTHS, light_spectrum

__all__ = [
    "CALIBRATIONS",
    "JND_DELTA_E",
    "MATCHING_LIGHT",
    "RATE_REFERENCE",
    "beta_from_blue_wool",
    "blue_wool_dose",
    "matched_rates",
]

#: A just-noticeable colour change, ΔE*ab (ISO grey scale step 4).
JND_DELTA_E = 1.6
#: Dose for a just-noticeable fade of Blue Wool class 1, lux·h, UV-free light.
BLUE_WOOL_1_DOSE = 0.4e6
#: What a Blue Wool class fixes (see :class:`Recipe`).
CALIBRATIONS = ("colour", "rate")
#: Concentration of every colourant in the neutral where :func:`matched_rates` compares
#: them (a mid-dark grey: charcoal unmixes to about 0.6-0.8 of each).
RATE_REFERENCE = 0.5
#: Light in which :func:`matched_rates` compares colourants: daylight behind window
#: glass, the light of the ISO 105-B02 fastness test (filtered xenon arc).
MATCHING_LIGHT = ("daylight-glass", False)
#: Bumped whenever a calibrated ``beta`` would change for the same recipe and class.
CALIBRATION_FORMAT = 1


def blue_wool_dose(blue_wool):
    """Dose (lux·h) for a just-noticeable fade of Blue Wool class ``blue_wool``.

    ``0.4 Mlx·h × 3**(class - 1)``: about 0.4 Mlx·h for class 1 and 875 Mlx·h for
    class 8 (fractional classes interpolate geometrically).

    Examples
    --------
    >>> blue_wool_dose(3) / 1e6
    3.6
    """
    k = float(blue_wool)
    if not 1.0 <= k <= 8.0:
        raise ValueError(f"Blue Wool class must lie in 1..8, got {blue_wool!r}")
    return BLUE_WOOL_1_DOSE * 3.0 ** (k - 1.0)


def _calibration_fade(recipe, j, beta, dose, wavelengths):
    """ΔE*ab of colourant ``j`` alone at full concentration after ``dose`` lux·h."""
    c = recipe.base_concentrations()
    c[j] = 1.0
    sens = np.zeros(len(recipe.colourants))
    sens[j] = beta
    E0 = light_spectrum(recipe.calibration_light, wavelengths, recipe.calibration_uv_filter)
    r = recipe.simulate(c, E0, dose, wavelengths=wavelengths, sensitivity=sens)
    return float(delta_E_ab(reflectance_to_Lab(r.initial, wavelengths),
                            reflectance_to_Lab(r.reflectance, wavelengths)))


def _disk_key(recipe, j, blue_wool, lam):
    """Hash of everything colourant ``j``'s calibrated ``beta`` depends on."""
    parts = [CALIBRATION_FORMAT, repr(recipe), int(j), float(blue_wool), JND_DELTA_E,
             BLUE_WOOL_1_DOSE]
    h = hashlib.sha256(json.dumps(parts, default=str).encode())
    light = light_spectrum(recipe.calibration_light, lam, recipe.calibration_uv_filter)
    for a in (*recipe.optics(lam), light, lam):
        h.update(np.ascontiguousarray(a, dtype=float).tobytes())
    return h.hexdigest()[:32]


def _disk_path(key):
    from .cache import directory          # (cache imports the grid builder, which needs us)

    return directory() / f"beta-{key}.json"


def _load_beta(path):
    try:
        with open(path, encoding="utf-8") as f:
            beta = float(json.load(f)["beta"])
    except (OSError, ValueError, KeyError, TypeError):
        return None
    return beta if np.isfinite(beta) and beta > 0 else None


def _store_beta(path, beta):
    """Write atomically (a temporary file renamed into place); a read-only folder is
    not an error: the value is only not kept."""
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, suffix=".tmp")
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            json.dump({"beta": beta}, f)
        os.replace(tmp, path)
    except OSError:
        pass


@functools.lru_cache(maxsize=256)
def _beta_cached(recipe, j, blue_wool, wavelengths):
    lam = np.asarray(wavelengths)
    path = _disk_path(_disk_key(recipe, j, blue_wool, lam))
    beta = _load_beta(path)
    if beta is None:
        beta = _solve_beta(recipe, j, blue_wool, lam)
        _store_beta(path, beta)
    return beta


#: Where :func:`_solve_beta` starts, log(beta): the recipes' roots lie in -16 … -8.
_LOG_BETA_START = -13.0
#: Secant steps :func:`_solve_beta` takes before it brackets the root by plain steps.
_SECANT_STEPS = 8
#: The ``log beta`` the plain steps search (:func:`_stepped_bracket`); the secant's too.
_LOG_BETA_RANGE = (-30.0, 30.0)


def _solve_beta(recipe, j, blue_wool, lam):
    """``beta`` whose calibration fade is exactly :data:`JND_DELTA_E` (Brent's method).

    The root is bracketed by secant steps on ``log ΔE`` against ``log beta`` (a small
    fade is nearly proportional to ``beta``: the first step from
    :data:`_LOG_BETA_START` lands within a few per cent of it), then Brent's method
    takes it to 1e-10 in ``log beta`` inside the tightest bracket found: 5–8
    simulations, where stepping from ``log beta = -30`` by 4 took 13–16 (0.11–0.13 s
    each calibration; an Age of two recipes solves four).  Should the steps not
    bracket it (a fade that saturates), the plain steps do.
    """
    dose = blue_wool_dose(blue_wool)
    seen = {}                               # Brent's method starts at the bracket's ends

    def excess(log_beta):                   # grows monotonically with beta
        if log_beta not in seen:
            seen[log_beta] = _calibration_fade(recipe, j, np.exp(log_beta), dose, lam) - JND_DELTA_E
        return seen[log_beta]

    lo, hi = _secant_bracket(excess)
    if lo is None or hi is None:
        lo, hi = _stepped_bracket(recipe, j, excess)
    return float(np.exp(brentq(excess, lo, hi, xtol=1e-10)))


def _secant_bracket(excess, width=1e-6):
    """``(lo, hi)`` with ``excess(lo) < 0 <= excess(hi)``, at most ``width`` apart once
    the secant steps on ``log(excess + JND)`` reach it; ``None`` for a side not found."""
    lo = hi = None
    x, g_prev, x_prev = _LOG_BETA_START, None, None
    for _ in range(_SECANT_STEPS):
        f = excess(x)
        if not np.isfinite(f):
            return None, None
        if f < 0:
            lo = x if lo is None else max(lo, x)
        else:
            hi = x if hi is None else min(hi, x)
        fade = f + JND_DELTA_E
        if fade <= 0 or (lo is not None and hi is not None and hi - lo <= width):
            break
        g = np.log(fade / JND_DELTA_E)           # 0 at the root
        slope = 1.0                              # a small fade: ΔE ∝ beta
        if g_prev is not None and x != x_prev and g != g_prev:
            slope = (g - g_prev) / (x - x_prev)
        if not slope > 0.05:                    # flat (saturated): leave it to the steps
            break
        g_prev, x_prev = g, x
        step = -g / slope
        if lo is None or hi is None:
            if abs(step) < width:               # converged from one side: step across
                step = width if hi is None else -width
            x = min(max(x + step, _LOG_BETA_RANGE[0]), _LOG_BETA_RANGE[1])
        else:                                   # stay inside what is known
            x = min(max(x + step, lo + width / 4), hi - width / 4)
    return lo, hi


def _stepped_bracket(recipe, j, excess):
    """``(lo, hi)`` bracketing the root by steps of 4 in ``log beta`` from -30."""
    lo = hi = _LOG_BETA_RANGE[0]
    while excess(hi) < 0:
        lo, hi = hi, hi + 4.0
        if hi > _LOG_BETA_RANGE[1]:
            raise ValueError(
                f"recipe {recipe.name!r}: colourant {recipe.colourants[j]!r} does not fade "
                f"under the calibration light {recipe.calibration_light!r}"
                f"{' with UV filter' if recipe.calibration_uv_filter else ''}; give beta directly")
    if lo == hi:
        raise ValueError(f"recipe {recipe.name!r}: colourant {recipe.colourants[j]!r} fades "
                         f"visibly at any beta; give beta directly")
    return lo, hi


def matched_rates(recipe, wavelengths=WAVELENGTHS):
    """(C,) fractional loss rate of each colourant per unit ``beta``, per lux·h, in the
    recipe's reference neutral.

    Every colourant with a Blue Wool class at :data:`RATE_REFERENCE` concentration (the
    fixed ones at theirs) on the recipe's substrate, in the recipe's layers, under the
    light at 1 lux: ``-d ln f / d(dose)`` at ``beta = 1``, averaged over the
    layers at the start (equation 3 with the shielding of a mid-dark neutral: where the
    colourants' bands overlap, each shades the others). The light is
    :data:`MATCHING_LIGHT`, daylight through window glass (ISO 105-B02).
    """
    return _rates_cached(replace(recipe, beta=None), tuple(np.asarray(wavelengths, float)))


@functools.lru_cache(maxsize=64)
def _rates_cached(recipe, wavelengths):
    lam = np.asarray(wavelengths)
    c = recipe.base_concentrations()
    classed = [j for j, k in enumerate(recipe.blue_wool) if k is not None]
    c[classed] = RATE_REFERENCE
    E0 = light_spectrum(MATCHING_LIGHT[0], lam, MATCHING_LIGHT[1])
    A, S, ground = recipe.optics(lam)
    dose = 1e-6
    solver = recipe.solver()
    r = simulate(A, S, c, np.ones(len(c)), E0, ground, lam, thickness=recipe.thickness,
                 duration=dose, layers=solver["layers"], steps=1, scheme="paper",
                 kinetics=recipe.kinetics)
    with np.errstate(divide="ignore", invalid="ignore"):
        rates = -np.log(r.fractions / c).mean(axis=-2) / dose
    for j in classed:
        if not rates[j] > 0:
            raise ValueError(f"recipe {recipe.name!r}: colourant {recipe.colourants[j]!r} "
                             f"absorbs none of the calibration light "
                             f"{recipe.calibration_light!r}; give beta directly")
    return rates


def beta_from_blue_wool(recipe, j, blue_wool, wavelengths=WAVELENGTHS):
    """``beta`` of colourant ``j`` of ``recipe`` for ISO Blue Wool class ``blue_wool``.

    With ``recipe.calibration == "colour"``, the colourant alone at full concentration
    on the recipe's substrate, lit by the recipe's calibration light, fades by
    ΔE*ab = 1.6 after :func:`blue_wool_dose`. With ``"rate"``, colourant ``j`` is
    destroyed, in the recipe's reference neutral, as fast as the recipe's first colourant (the reference) of
    class ``blue_wool`` calibrated so, in the recipe's reference neutral
    (:func:`matched_rates`):
    ``beta_j = beta_0(class) × rate_0 / rate_j``. Results are cached.

    Returns
    -------
    float
        ``beta`` in (W m^-2 nm^-1 · nm · h · unit K)^-1, i.e. for an irradiance
        given as the light's spectrum at 1 lux and durations in hours.
    """
    lam = tuple(np.asarray(wavelengths, float))
    recipe = replace(recipe, beta=None)
    if recipe.calibration == "rate" and j != 0:
        rates = matched_rates(recipe, lam)
        return _beta_cached(recipe, 0, float(blue_wool), lam) * rates[0] / rates[j]
    return _beta_cached(recipe, int(j), float(blue_wool), lam)
