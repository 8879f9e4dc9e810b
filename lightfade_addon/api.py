"""A small Python API for pipelines: bake, age and reset a scene from a script.

Works in Blender (``blender -b file.blend --python script.py``) and with the ``bpy``
module. In an installed extension the package is ``bl_ext.<repo>.lightfade``; the
add-on must be enabled (its properties are registered by ``register()``)::

    import importlib, addon_utils
    mod = next(m for m in addon_utils.modules() if m.__name__.endswith("lightfade"))
    addon_utils.enable(mod.__name__, default_set=True)
    api = importlib.import_module(mod.__name__ + ".api")

    api.bake(scene, resolution=512, samples=32)       # exposure maps (Cycles)
    api.age_scene(scene, years=10)                    # aged textures at 10 years
    api.set_years(scene, 25)                          # scrub without re-preparing
    api.reset(scene)                                  # back to the original file

From a checkout, ``import lightfade_addon.api`` after enabling ``lightfade_addon``.
"""

from __future__ import annotations

__all__ = ["bake", "age_scene", "set_years", "keyframe_years", "reset", "AgingError"]


def _bpy():
    import bpy

    return bpy


def _scene(scene):
    return scene if scene is not None else _bpy().context.scene


def bake(scene=None, objects=None, resolution=None, samples=None, margin=None, unwrap=False,
         progress=None):
    """Bake exposure maps for ``objects`` (default: meshes whose materials are enabled).

    Returns the :func:`.blender.bake.bake_exposure` result dict (maps per object).
    """
    from .blender.bake import BakeSettings, bake_exposure

    scene = _scene(scene)
    props = scene.lightfade
    if resolution is not None:
        props.bake_resolution = int(resolution)
    if samples is not None:
        props.bake_samples = int(samples)
    if margin is not None:
        props.bake_margin = int(margin)
    settings = BakeSettings.from_scene(scene, unwrap=unwrap)
    return bake_exposure(scene, list(objects or []), settings, report=print, progress=progress)


def age_scene(scene=None, years=None, objects=(), progress=None):
    """Age the enabled materials (of ``objects``, or all) and show ``years``.

    Returns the aged images. Raises :class:`AgingError` with a message naming what
    to fix when nothing can be aged.
    """
    from .blender.aging import age_scene as _age

    scene = _scene(scene)
    years = scene.lightfade.years if years is None else years
    return _age(scene, years, list(objects), progress, report=print)


def set_years(scene=None, years=0.0):
    """Show ``years`` on the aged materials (fast: only the dose-dependent part runs)."""
    from .blender.aging import update_scene

    scene = _scene(scene)
    scene.lightfade.years = float(years)
    return update_scene(scene, float(years))


def keyframe_years(scene=None, keys=()):
    """Keyframe the years slider: ``keys`` is a sequence of (frame, years) pairs."""
    scene = _scene(scene)
    for frame, years in keys:
        scene.lightfade.years = float(years)
        scene.lightfade.keyframe_insert("years", frame=int(frame))


def reset(scene=None, exposure=False):
    """Undo aging (and with ``exposure=True`` remove the exposure maps and stored grids)."""
    bpy = _bpy()
    scene = _scene(scene)
    with bpy.context.temp_override(scene=scene):
        return bpy.ops.lightfade.reset(exposure=exposure)


def __getattr__(name):
    if name == "AgingError":
        from .blender.aging import AgingError

        return AgingError
    raise AttributeError(name)
