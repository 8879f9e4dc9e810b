"""Shared fixtures for the core tests: a toy three-dye system that needs no data files."""

import numpy as np
import pytest


def gaussian(lam, centre, width, height):
    return height * np.exp(-0.5 * ((lam - centre) / width) ** 2)


@pytest.fixture(scope="session")
def toy():
    """Cyan/magenta/yellow-like absorbers on a white ground, 300-780 nm in 41 samples."""
    lam = np.linspace(300.0, 780.0, 41)
    A = np.stack([
        gaussian(lam, 620, 50, 4.0) + gaussian(lam, 340, 30, 1.5),
        gaussian(lam, 550, 40, 4.0) + gaussian(lam, 360, 30, 1.0),
        gaussian(lam, 430, 35, 4.0) + gaussian(lam, 320, 25, 1.0),
    ])
    S = np.full_like(A, 0.1)
    return dict(
        absorption=A, scattering=S, wavelengths=lam,
        substrate=np.full(41, 0.88),
        irradiance=np.ones(41),
        sensitivity=np.array([0.004, 0.010, 0.006]),
    )


def run(toy, concentrations, **kw):
    from lightfade_addon.core import simulate

    args = dict(toy)
    args.update(kw)
    return simulate(concentrations=concentrations, **args)
