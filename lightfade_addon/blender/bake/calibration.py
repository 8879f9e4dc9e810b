"""Calibration: time tiny bakes on the scene (the first untimed) to estimate how long a
bake will take."""

from __future__ import annotations

from . import sizing
from .emitters import isolate
from .exposure import ExposureBake, scene_and_layer
from .settings import BakeSettings
from .state import BakeState
from .targets import attach_targets, check_bake_result


def calibrate(context_or_scene, obj=None):
    """Time tiny bakes of one target on this scene (:func:`.sizing.calibrate`); store and
    return the rate.

    Returns ``(texel-samples per second, seconds per call)``; :func:`.sizing.estimate`
    uses it for this scene.
    """
    scene, layer = scene_and_layer(context_or_scene)
    objects = [obj] if obj is not None else None
    job = ExposureBake(scene, objects, BakeSettings(resolution=32, samples=1, denoise=False),
                       report=lambda msg: None, progress=lambda f, m: None).plan()
    target = job.targets[:1]
    group = job.groups[0]

    def run(size, samples):
        with BakeState(scene, layer) as state:
            state.configure(samples, 0)
            nodes = attach_targets(state, target)
            image = state.new_image("calibration", size)
            for node in nodes[target[0].name]:
                node.image = image
            isolate(state, scene, group)
            state.select_only(target)
            check_bake_result(state.bake(), target, group)

    rate = sizing.calibrate(run)
    sizing.CALIBRATION[scene.session_uid] = rate
    return rate
