"""Lights and their schedules: from lux, hours and days to doses per texel.

Doses are in lux·h (illuminance × time); by reciprocity they are all the fading
model needs (DESIGN.md, "Units and conventions").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .spectra import WAVELENGTHS, light_spectrum

__all__ = ["Light", "HOURS_PER_YEAR_DEFAULT", "spectra_keys", "dose_rates"]

HOURS_PER_YEAR_DEFAULT = 8.0 * 365.0


@dataclass(frozen=True)
class Light:
    """A light's spectrum and schedule.

    Attributes
    ----------
    spectrum : str
        A :data:`.spectra.LIGHTS` name, e.g. ``"daylight-glass"``.
    uv_filter : bool
        Behind a UV filter.
    lux : float
        Illuminance where the exposure map is 1 (with absolute maps in lux, 1).
    hours_per_day, days_per_year : float
        When the light is on.
    """

    spectrum: str = "daylight-glass"
    uv_filter: bool = False
    lux: float = 150.0
    hours_per_day: float = 8.0
    days_per_year: float = 365.0

    def __post_init__(self):
        for name in ("lux", "hours_per_day", "days_per_year"):
            v = getattr(self, name)
            if not np.isfinite(v) or v < 0:
                raise ValueError(f"light {name} must be a finite number >= 0, got {v!r}")
        if self.hours_per_day > 24 or self.days_per_year > 366:
            raise ValueError("a light cannot be on more than 24 h a day or 366 days a year")

    @property
    def annual_dose(self):
        """lux·h per year where the exposure is 1."""
        return self.lux * self.hours_per_day * self.days_per_year

    def spectrum_1lux(self, wavelengths=WAVELENGTHS):
        return light_spectrum(self.spectrum, wavelengths, self.uv_filter)


def spectra_keys(lights):
    """Distinct (spectrum, uv_filter) pairs, in order of first appearance."""
    keys = []
    for light in lights:
        k = (light.spectrum, light.uv_filter)
        if k not in keys:
            keys.append(k)
    return keys


def dose_rates(lights, exposure, n, keys):
    """Per-texel annual dose per distinct spectrum, (S, n) float32 lux·h a year."""
    rates = np.zeros((len(keys), n), dtype=np.float32)
    if exposure is not None:
        exposure = np.asarray(exposure)
        if exposure.size not in (n, n * len(lights)):
            raise ValueError(f"exposure must have one value per texel ({n}) or one map per "
                             f"light ({len(lights)} × {n}), got shape {exposure.shape}")
        exposure = exposure.reshape((1, n) if exposure.size == n else (len(lights), n))
    for k, light in enumerate(lights):
        row = rates[keys.index((light.spectrum, light.uv_filter))]
        if exposure is None:
            row += np.float32(light.annual_dose)
            continue
        e = exposure[0 if exposure.shape[0] == 1 else k]
        if not np.all(np.isfinite(e)) or np.any(e < 0):
            raise ValueError("exposure must be finite and >= 0")
        row += e.astype(np.float32) * np.float32(light.annual_dose)
    return rates
