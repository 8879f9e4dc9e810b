"""The layered fading model: time stepping of colourant volume fractions.

Paper, Section 3. The medium of thickness ``thickness`` is split into ``layers``
equal layers. Within layer ``l`` colourant ``j`` has volume fraction ``f[l, j]``, so
its absorption and scattering coefficients are ``mu_a = f A_j`` and ``mu_s = f S_j``
(``A_j``, ``S_j`` per unit thickness at full concentration) and the layer has
``K = sum_j mu_a``, ``S = sum_j mu_s``. At each time step the fluence rate ``F`` is
evaluated through the stack (equations 1–2, :mod:`.flux`), held constant over the
step, and every colourant in every layer decays.

Two rate laws (``kinetics``):

``"first-order"`` (the default)
    ``f(t + dt) = f(t) exp(-dt * beta * integral(A_j F dlambda))``: each molecule is
    destroyed at a rate set by its own absorption cross-section, ``df/dt = -k f``
    (photochemistry; the CCI Light Damage Calculator's ``exp(-D/K)``). The
    concentration enters only through the shielding of ``F`` by the layers above.
``"paper"``
    Equation (3) as printed, ``f(t + dt) = f(t) exp(-dt * integral(beta mu_a F
    dlambda))`` with ``mu_a = f(t) A_j`` the colourant's *current* coefficient, so
    ``df/dt`` is proportional to ``f**2``.

``"shared"``
    ``f(t + dt) = f(t) exp(-dt * beta_j * sum_i f_i integral(A_i F dlambda) / sum_i
    f_i)``: photosensitised fading, each molecule destroyed at a rate set by the light
    the colourants around it absorb per unit of colourant (dyes in one fibre share the
    reactive oxygen and radicals that any of them makes: "catalytic fading" of dye
    mixtures). One colourant alone fades exactly as with ``"first-order"``; in a
    mixture, colourants of one ``beta`` lose the same fraction in every layer whatever
    their concentrations, so a neutral of matched dyes fades on tone.

In all, ``mu_a`` and ``mu_s`` scale by the same ratio as ``f`` (4)–(5).

Two time-stepping schemes are offered:

``"paper"``
    The rates held over the step: one flux solve per step; first order in the
    step. With ``kinetics="paper"`` this is equations (1)–(5) exactly.
``"heun"``
    An exponential predictor–corrector: predict with (3), solve the fluxes again
    at the predicted state, and take the step with the mean of the two rates.
    Two flux solves per step; second order (see ``docs/accuracy.md``).

Yellowing: with ``yields[j, k] > 0`` what colourant ``j`` loses in a step,
colourant ``k`` gains times ``yields[j, k]`` (lignin turning into quinones).
"""

from __future__ import annotations

import multiprocessing
import os
import sys
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from .layered import LayeredStack, trapezoid_weights

__all__ = ["simulate", "SimulationResult", "SCHEMES", "KINETICS", "trapezoid_weights"]

#: Time-stepping schemes, by name (see the module docstring).
SCHEMES = ("paper", "heun")
#: Rate laws, by name (see the module docstring); the first is the default.
KINETICS = ("first-order", "paper", "shared")

#: Columns (samples × wavelengths) per chunk at least; large enough that numpy's
#: per-call overhead is small against the work of one sweep row.
_CHUNK_COLUMNS = 6144
#: Layer cells (layers × columns) per chunk: few layers get wider chunks, whose fewer,
#: longer numpy calls are cheaper (a colour table's 729 samples of 3 layers in one
#: chunk: 1.44 -> 1.25 s of process time for its three light mixes) while the
#: chunk's (layers, columns) arrays stay small.
_CHUNK_CELLS = 98304
#: Volume fraction below which a fading colourant (``beta > 0``) counts as gone: a
#: chunk whose every fading colourant is below it in every layer stops stepping, its
#: later records its reflectance then. What is left of them can move the reflectance
#: by about 1e-13 (a fraction of 1e-15 of absorption coefficients below 100), far
#: below what any caller keeps (colour tables: float16); fading is steep in log dose,
#: so a colour table's chunks stop at 4e9-7e9 lux·h of their 1e14 axis (97 of 161
#: records), where the fractions would underflow to 0 anyway.
SETTLED = 1e-15
#: Layer-solves (layers × samples × wavelengths × flux solves) above which a run is
#: split over processes by default (about a second on one core).
_PARALLEL_WORK = 5e7


@dataclass(frozen=True)
class SimulationResult:
    """What :func:`simulate` returns.

    Attributes
    ----------
    initial : ndarray, shape (..., W)
        Reflectance before exposure.
    reflectance : ndarray, shape (..., W)
        Reflectance after ``duration``.
    fractions : ndarray, shape (..., layers, C)
        Colourant volume fractions after ``duration``, top layer first.
    history : ndarray, shape (T, ..., W) or None
        Reflectance at the ``record`` times, when asked.
    times : ndarray, shape (T,) or None
        The ``record`` times.
    """

    initial: np.ndarray
    reflectance: np.ndarray
    fractions: np.ndarray
    history: np.ndarray | None = None
    times: np.ndarray | None = None


# -- input checks ------------------------------------------------------------------


def _array(name, value, ndim=None):
    a = np.asarray(value, dtype=float)
    if ndim is not None and a.ndim != ndim:
        raise ValueError(f"{name} must have {ndim} dimension(s), got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} contains NaN or infinite values")
    return a


def _nonnegative(name, a):
    if np.any(a < 0):
        raise ValueError(f"{name} must be >= 0 (min is {a.min():g})")
    return a


def _unit_interval(name, a):
    if np.any((a < 0) | (a > 1)):
        raise ValueError(f"{name} must lie in [0, 1] (range {a.min():g} .. {a.max():g})")
    return a


def _positive_int(name, value):
    if isinstance(value, bool) or int(value) != value or int(value) < 1:
        raise ValueError(f"{name} must be an integer >= 1, got {value!r}")
    return int(value)


def _check_inputs(absorption, scattering, concentrations, sensitivity, irradiance,
                  substrate, wavelengths, thickness, duration, layers, steps, scheme,
                  kinetics, yields, record):
    lam = _array("wavelengths", wavelengths, 1)
    if lam.size < 1 or np.any(np.diff(lam) <= 0):
        raise ValueError("wavelengths must be strictly increasing")
    W = lam.size
    A = _nonnegative("absorption", _array("absorption", absorption, 2))
    S = _nonnegative("scattering", _array("scattering", scattering, 2))
    if A.shape[1] != W or S.shape != A.shape:
        raise ValueError(
            f"absorption {A.shape} and scattering {S.shape} must both be (C, W) with W = "
            f"{W} wavelengths")
    C = A.shape[0]
    c = _unit_interval("concentrations", _array("concentrations", concentrations))
    if c.ndim < 1 or c.shape[-1] != C:
        raise ValueError(f"concentrations must have shape (..., {C}), got {c.shape}")
    beta = _nonnegative("sensitivity", _array("sensitivity", sensitivity, 1))
    if beta.shape != (C,):
        raise ValueError(f"sensitivity must have shape ({C},), got {beta.shape}")
    E0 = _nonnegative("irradiance", _array("irradiance", irradiance, 1))
    if E0.shape != (W,):
        raise ValueError(f"irradiance must have shape ({W},), got {E0.shape}")
    g = _unit_interval("substrate", _array("substrate", substrate, 1))
    if g.shape != (W,):
        raise ValueError(f"substrate must have shape ({W},), got {g.shape}")
    thickness = float(_array("thickness", thickness, 0))
    if thickness <= 0:
        raise ValueError(f"thickness must be > 0, got {thickness:g}")
    duration = float(_nonnegative("duration", _array("duration", duration, 0)))
    layers = _positive_int("layers", layers)
    steps = _positive_int("steps", steps)
    if scheme not in SCHEMES:
        raise ValueError(f"scheme must be one of {SCHEMES}, got {scheme!r}")
    if kinetics not in KINETICS:
        raise ValueError(f"kinetics must be one of {KINETICS}, got {kinetics!r}")
    Y = None
    if yields is not None:
        Y = _nonnegative("yields", _array("yields", yields, 2))
        if Y.shape != (C, C):
            raise ValueError(f"yields must have shape ({C}, {C}), got {Y.shape}")
        if np.any(np.diag(Y) != 0):
            raise ValueError("yields must have a zero diagonal (a colourant cannot feed itself)")
    times = None
    if record is not None:
        times = _array("record", record, 1)
        if times.size and (np.any(np.diff(times) <= 0) or times[0] <= 0
                           or times[-1] > duration * (1 + 1e-12)):
            raise ValueError("record must be increasing times in (0, duration]")
    return A, S, c, beta, E0, g, lam, thickness, duration, layers, steps, Y, times


def _time_grid(duration, steps, record):
    """Step boundaries: ``steps`` uniform steps with the record times inserted.

    Returns the boundaries ``t`` (M + 1,) and, per record time, the index of the
    boundary it falls on. Inserting a record time splits a step in two, which
    only makes the solution more accurate.
    """
    t = np.linspace(0.0, duration, steps + 1)
    if record is None or record.size == 0:
        return t, np.zeros(0, dtype=int)
    tol = 1e-9 * max(duration, 1e-300)
    extra = [r for r in record if np.min(np.abs(t - r)) > tol]
    t = np.union1d(t, extra)
    idx = np.array([int(np.argmin(np.abs(t - r))) for r in record])
    return t, idx


# -- the engine ----------------------------------------------------------------------


def _run_job(job):
    """One chunk of samples, start to end (module level, so that it pickles)."""
    (A, S, beta, E0, g, lam, thickness, layers, fmax, c, t, record_idx, scheme, kinetics,
     Y) = job
    stack = LayeredStack(A, S, beta, E0, g, lam, thickness, layers, c.shape[0], fmax,
                         kinetics)
    f0 = np.broadcast_to(c, (layers, c.shape[0], c.shape[1])).copy()
    return _run_chunk(stack, f0, t, record_idx, scheme, Y)


def _parallelism(workers, work):
    """(workers, "processes" | "threads" | "serial") for ``work`` layer-solves.

    numpy's per-call overhead holds the GIL, and the sweeps make many small calls,
    so threads barely help: big runs use forked processes (never inside Blender,
    whose Python must not be forked), small runs stay on one thread.
    """
    cpus = os.cpu_count() or 1
    can_fork = ("fork" in multiprocessing.get_all_start_methods()
                and "bpy" not in sys.modules)
    if workers is None:
        workers = min(cpus, 8) if (work >= _PARALLEL_WORK and can_fork) else 1
    workers = max(1, int(workers))
    if workers == 1:
        return 1, "serial"
    return workers, ("processes" if can_fork else "threads")


def _chunks(n_samples, W, workers, layers=1):
    """Split the samples into equal chunks: a multiple of ``workers``, each about
    ``max(_CHUNK_COLUMNS, _CHUNK_CELLS / layers)`` columns (samples × wavelengths) wide."""
    count = -(-n_samples * W // max(_CHUNK_COLUMNS, _CHUNK_CELLS // layers))
    if n_samples >= workers:
        count = max(workers, -(-count // workers) * workers)
    count = max(1, min(count, n_samples))
    edges = np.linspace(0, n_samples, count + 1).round().astype(int)
    return list(zip(edges[:-1].tolist(), edges[1:].tolist()))


def _advance(f, rate, dt, yields):
    """Equation (3) with the rates (per unit of colourant) held over ``dt``, plus
    yellowing transfers."""
    new = f * np.exp(-dt * rate)
    if yields is not None:
        new += (f - new) @ yields
    return new


def _run_chunk(stack, f, t, record_idx, scheme, yields):
    """Time-step one chunk; returns (initial, final, fractions, history). Stepping
    stops once every fading colourant is below :data:`SETTLED` (nothing is left to
    change): the remaining records are the reflectance then."""
    wanted = set(record_idx.tolist())
    recorded = {}
    initial = None
    fading = np.flatnonzero(stack.beta > 0)
    for k in range(len(t) - 1):
        if not (f[:, :, fading] >= SETTLED).any():
            break
        dt = t[k + 1] - t[k]
        r0, R0 = stack.rates(f)
        if initial is None:
            initial = R0
        if k in wanted:
            recorded[k] = R0
        if scheme == "paper":
            f = _advance(f, r0, dt, yields)
        else:  # heun: exponential predictor-corrector on the rate
            r1, _ = stack.rates(_advance(f, r0, dt, yields))
            r1 += r0
            r1 *= 0.5
            f = _advance(f, r1, dt, yields)
    final = stack.reflectance(f)
    if initial is None:
        initial = final
    recorded[len(t) - 1] = final
    return initial, final, f, [recorded.get(k, final) for k in record_idx.tolist()]


def simulate(absorption, scattering, concentrations, sensitivity, irradiance,
             substrate, wavelengths, thickness=1.0, duration=1.0, layers=3, steps=4,
             scheme="heun", kinetics="first-order", yields=None, record=None,
             workers=None):
    """Fade layered colourant mixtures under constant irradiance.

    Parameters
    ----------
    absorption, scattering : array_like, shape (C, W)
        Absorption ``A_j`` and scattering ``S_j`` coefficients of each colourant,
        per unit thickness at full concentration (volume fraction 1).
    concentrations : array_like, shape (..., C)
        Initial volume fractions in [0, 1], uniform in depth.
    sensitivity : array_like, shape (C,)
        ``beta`` per colourant; 0 means it does not fade. Units: inverse of
        (irradiance unit × nm × time unit × absorption per unit thickness).
    irradiance : array_like, shape (W,)
        Spectral irradiance ``E0`` on the top surface (e.g. W m^-2 nm^-1).
    substrate : array_like, shape (W,)
        Ground reflectance ``rho*`` in [0, 1].
    wavelengths : array_like, shape (W,)
        Wavelengths in nm, strictly increasing; the spectral integral of
        equation (3) uses the trapezoidal rule over them.
    thickness : float
        Medium thickness (the unit of length of the coefficients); default 1.
    duration : float
        Exposure time (the time unit of ``beta``). Only ``irradiance × duration``
        matters (reciprocity).
    layers, steps : int
        Number of equal layers and of uniform time steps (>= 1). The defaults
        (3 layers, 4 steps of ``"heun"``) are the cheapest setting within max
        CIEDE2000 0.3 of a 1024 × 625 reference with first-order kinetics in the
        accuracy study (``docs/accuracy.md``).
    scheme : {"paper", "heun"}
        ``"paper"``: rates held over each step (first order in the step);
        ``"heun"``: the predictor–corrector (second order, two flux solves per step).
    kinetics : {"first-order", "paper", "shared"}
        The rate law. ``"first-order"``: ``df/dt = -f beta trapz(A_j F)``, each
        molecule fading at its own rate (photochemistry, conservation practice).
        ``"paper"``: equation (3) as printed, ``mu_a = f A_j`` inside the exponent,
        so ``df/dt`` goes as ``f**2``. ``"shared"``: ``df_j/dt = -f_j beta_j
        sum_i f_i trapz(A_i F) / sum_i f_i`` (photosensitised fading; see the module
        docstring). ``scheme="paper", kinetics="paper"`` is
        the paper's equations (1)–(5) exactly.
    yields : array_like, shape (C, C), optional
        ``yields[j, k]``: volume fraction of ``k`` formed per unit lost by ``j``.
    record : array_like, optional
        Increasing times in (0, duration] at which to also return the
        reflectance; each becomes a step boundary.
    workers : int, optional
        Parallel workers over chunks of samples. Default: one for small runs; for
        large ones the CPU count (at most 8), as forked processes outside Blender.
        Results do not depend on it.

    Returns
    -------
    SimulationResult
        ``initial`` and ``reflectance`` (..., W), ``fractions`` (..., layers, C),
        ``history`` (T, ..., W) and ``times`` when ``record`` is given.

    Raises
    ------
    ValueError
        Naming the argument: negative or non-finite values, shape mismatches,
        concentrations or substrate outside [0, 1], non-increasing wavelengths,
        ``layers`` or ``steps`` < 1, unknown scheme or kinetics.

    References
    ----------
    Paper, Section 3: equations (1)–(5), Figure 3. First-order dye loss: Michalski,
    CCI Light Damage Calculator (``c = exp(-D / K)``); Ligterink, inktime.

    Examples
    --------
    >>> import numpy as np
    >>> lam = np.linspace(400, 700, 4)
    >>> A = np.array([[2.0, 1.0, 0.5, 0.1]]); S = np.full((1, 4), 0.1)
    >>> r = simulate(A, S, [0.5], [0.0], np.ones(4), np.full(4, 0.9), lam)
    >>> bool(np.allclose(r.initial, r.reflectance))   # beta = 0: nothing fades
    True
    """
    (A, S, c, beta, E0, g, lam, thickness, duration, layers, steps, Y,
     times) = _check_inputs(absorption, scattering, concentrations, sensitivity,
                            irradiance, substrate, wavelengths, thickness, duration,
                            layers, steps, scheme, kinetics, yields, record)
    C, W = A.shape
    batch = c.shape[:-1]
    flat = c.reshape(-1, C)
    n_samples = flat.shape[0]
    t, record_idx = _time_grid(duration, steps, times)
    # bound on the volume fractions: fading only lowers them; a product can gain at
    # most its yields' worth from sources that start at <= 1
    fmax = 1.0 if Y is None else 1.0 + Y.sum(axis=0)

    solves = len(t) * (2 if scheme == "heun" else 1)
    workers, pool_kind = _parallelism(workers, layers * n_samples * W * solves)
    bounds = _chunks(n_samples, W, workers, layers)
    jobs = [(A, S, beta, E0, g, lam, thickness, layers, fmax, flat[s:e], t, record_idx,
             scheme, kinetics, Y) for s, e in bounds]
    if pool_kind == "processes" and len(jobs) > 1:
        with ProcessPoolExecutor(max_workers=min(workers, len(jobs)),
                                 mp_context=multiprocessing.get_context("fork")) as pool:
            parts = list(pool.map(_run_job, jobs))
    elif pool_kind == "threads" and len(jobs) > 1:
        with ThreadPoolExecutor(max_workers=min(workers, len(jobs))) as pool:
            parts = list(pool.map(_run_job, jobs))
    else:
        parts = [_run_job(job) for job in jobs]

    initial = np.concatenate([p[0] for p in parts]).reshape(batch + (W,))
    final = np.concatenate([p[1] for p in parts]).reshape(batch + (W,))
    fractions = np.concatenate([p[2] for p in parts], axis=1)        # (N, n, C)
    fractions = np.moveaxis(fractions, 0, 1).reshape(batch + (layers, C))
    history = None
    if times is not None:
        history = np.stack(
            [np.concatenate([p[3][i] for p in parts]) for i in range(times.size)]
        ).reshape((times.size,) + batch + (W,)) if times.size else np.zeros((0,) + batch + (W,))
    return SimulationResult(initial, final, fractions, history,
                            None if times is None else times.copy())
