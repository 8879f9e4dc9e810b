"""Quality presets of the exposure bake, with the time and noise measured for each.

The figures come from ``benchmarks/bake.py`` (docs/bake.md): a 4 m floor under a sun with
a box casting a shadow that only bounce light reaches, 1024² texels, 2 cores.  Noise is
the relative standard deviation of the difference of two bakes with different seeds
(divided by √2), in the sunlit part and in the bounce-lit shadow; time is relative to the
undenoised 64-sample bake LightFade used before.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Preset:
    """Samples and denoising of one quality level, and what they measured."""

    label: str
    description: str
    samples: int
    denoise: bool
    #: Time of a 1024² floor bake relative to the old 1024², 64-sample bake.
    relative_time: float
    #: Noise in the sunlit part and in the bounce-lit shadow (fractions).
    noise_lit: float
    noise_shadow: float
    #: Adaptive (:mod:`.adaptive`): the 95th percentile of the relative error at lit
    #: texels, and of the object's mean lux, that each map is baked to (None: a fixed
    #: bake of ``samples``); ``samples`` is then the first passes' sum.
    noise_target: float | None = None
    mean_target: float | None = None
    #: Samples per pass of an adaptive bake.
    pass_samples: int = 4


PRESETS = {
    "PREVIEW": Preset(
        "Preview", "4 samples per texel, denoised: a quick look at where the light falls",
        samples=4, denoise=True, relative_time=0.15, noise_lit=0.0014, noise_shadow=0.051),
    "FINAL": Preset(
        "Final", "Passes of 4 samples per texel, denoised, until each map's noise is at the "
        "target (or the cap): the exposure the aging uses",
        samples=8, denoise=True, relative_time=0.18, noise_lit=0.0011, noise_shadow=0.044,
        noise_target=0.18, mean_target=0.01),
}
