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
    noise_target : float or None
        Adaptive bake (:mod:`.adaptive`): the relative error (95th percentile over lit
        texels) each map is baked to; None: one pass of ``samples``.
    mean_target : float
        Adaptive: the relative standard error of each object's mean lux (0: none).
    pass_samples : int
        Adaptive: samples per pass (``samples`` // ``pass_samples`` first passes, at
        least two).
    max_samples : int
        Adaptive: the cap, samples per texel of any map.
    max_seconds : float
        Adaptive: no pass beyond the first ones starts after this many seconds of the
        bake (0: no limit).
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
    noise_target: float | None = None
    mean_target: float = 0.0
    pass_samples: int = 4
    max_samples: int = 128
    max_seconds: float = 0.0

    @property
    def adaptive(self):
        return self.noise_target is not None

    @property
    def first_passes(self):
        """Passes every map gets: one for a fixed bake."""
        from .adaptive import MIN_PASSES

        if not self.adaptive:
            return 1
        return max(MIN_PASSES, int(self.samples) // max(int(self.pass_samples), 1))

    @property
    def cap_samples(self):
        """Samples per texel of a map at the cap (at least the first passes')."""
        if not self.adaptive:
            return int(self.samples)
        return max(self.first_passes * int(self.pass_samples), int(self.max_samples))

    @property
    def most_passes(self):
        """Passes of a map at the cap: the first ones, then one a round, each round at
        most :data:`.adaptive.MAX_GROWTH` × the samples so far."""
        from .adaptive import MAX_GROWTH

        passes, samples = self.first_passes, self.first_passes * self.samples_per_pass()
        while samples < self.cap_samples:
            passes, samples = passes + 1, samples * MAX_GROWTH
        return passes

    def samples_per_pass(self):
        return int(self.pass_samples) if self.adaptive else int(self.samples)

    @classmethod
    def from_scene(cls, scene, unwrap=False):
        """The scene's settings: quality preset, density, max size (``bake_resolution``).

        A preset brings its samples (and an adaptive one its noise target, with the cap
        of ``Scene.lightfade_bake``: ``max_samples``, ``max_minutes``);
        ``Scene.lightfade.bake_samples`` counts with the Custom quality only.
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
            noise_target=preset.noise_target if preset else None,
            mean_target=(preset.mean_target or 0.0) if preset else 0.0,
            pass_samples=preset.pass_samples if preset else 4,
            max_samples=bake.max_samples,
            max_seconds=bake.max_minutes * 60.0,
        )
