"""The settings of one exposure bake (:class:`BakeSettings`): from the scene's panel, or
given by a script."""

from __future__ import annotations

from dataclasses import dataclass

from .presets import PRESETS


@dataclass
class BakeSettings:
    """Bake parameters.

    Attributes
    ----------
    resolution : int or None
        Width and height of every map, px; None: from ``texels_per_metre``.
    samples : int
        Cycles samples per texel.
    margin : int
        Bake margin, px.
    unwrap : bool
        Give meshes without a UV map a ``LightFadeUV`` map (otherwise they are skipped).
    denoise : bool
        Denoise each map (OIDN, island-aware).
    texels_per_metre : float
        Map density when ``resolution`` is None.
    max_size : int
        Largest map width from the density.
    seed : int
        Cycles seed (two seeds give independent noise).
    portals : bool
        Portals over windows while the sky is baked (:mod:`.portals`).
    """

    resolution: int | None = None
    samples: int = PRESETS["FINAL"].samples
    margin: int = 16
    unwrap: bool = False
    denoise: bool = True
    texels_per_metre: float = 256.0
    max_size: int = 1024
    seed: int = 0
    portals: bool = True

    @classmethod
    def from_scene(cls, scene, unwrap=False):
        """The scene's settings: quality preset, density, max size (``bake_resolution``).

        A preset brings its samples; ``Scene.lightfade.bake_samples`` counts with the
        Custom quality only.
        """
        props, bake = scene.lightfade, scene.lightfade_bake
        preset = PRESETS.get(bake.quality)
        return cls(
            resolution=None,
            samples=preset.samples if preset else props.bake_samples,
            margin=props.bake_margin,
            unwrap=unwrap,
            denoise=preset.denoise if preset else bake.denoise,
            texels_per_metre=bake.texels_per_metre,
            max_size=props.bake_resolution,
            portals=bake.window_portals,
        )
