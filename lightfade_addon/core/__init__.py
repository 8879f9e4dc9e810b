"""LightFade's physics and colour science: numpy and colour-science only, never bpy.

The public entry point of the fading model is :func:`simulate` (paper, Section 3).
"""

from .fading.model import SCHEMES, SimulationResult, simulate, trapezoid_weights
from .fading.flux import boundary_fluxes, boundary_fluxes_dense, stack_reflectance
from .fading.kubelka import kubelka_layer, over_ground

__all__ = [
    "SCHEMES",
    "SimulationResult",
    "boundary_fluxes",
    "boundary_fluxes_dense",
    "kubelka_layer",
    "over_ground",
    "simulate",
    "stack_reflectance",
    "trapezoid_weights",
]
