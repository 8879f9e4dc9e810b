"""A small Python API for pipelines: bake, age and reset a scene from a script.

Works in Blender (``blender -b file.blend --python script.py``) and with the ``bpy``
module. In an installed extension the package is ``bl_ext.<repo>.lightfade``; the
add-on must be enabled (its properties are registered by ``register()``)::

    import importlib, addon_utils
    mod = next(m for m in addon_utils.modules() if m.__name__.endswith("lightfade"))
    addon_utils.enable(mod.__name__, default_set=True)
    api = importlib.import_module(mod.__name__ + ".api")

    api.bake(scene, quality="FINAL")                  # exposure maps (Cycles), one per light group
    api.age_scene(scene, years=10)                    # aged textures at 10 years
    api.set_years(scene, 25)                          # the materials follow: no Python per pixel
    api.apply_aging(scene)                            # real aged images, for export
    api.material_plan(scene)                          # which path each material takes, why
    api.set_parts(sofa, [dict(name="Frame", recipe="BARE_WOOD", image=mask)])  # by mask
    api.set_daylight(scene, 52.0, 4.5, north=0.0)     # a place: one annual daylight bake
    api.annual_dose(scene, obj)                       # {group: (H, W) lux·h per year}
    api.reset(scene)                                  # back to the original file

From a checkout, ``import lightfade_addon.api`` after enabling ``lightfade_addon``.
"""

from __future__ import annotations

__all__ = ["bake", "age_scene", "set_years", "keyframe_years", "apply_aging", "live_aging",
           "reset", "localize_linked", "material_plan", "set_parts", "set_daylight", "annual_dose", "AgingError"]


def _bpy():
    import bpy

    return bpy


def _scene(scene):
    return scene if scene is not None else _bpy().context.scene


def bake(scene=None, objects=None, resolution=None, samples=None, margin=None, unwrap=False,
         progress=None, quality=None, density=None, max_samples=None, max_minutes=None):
    """Bake exposure maps for ``objects`` (default: meshes whose materials are enabled).

    ``quality`` is ``"PREVIEW"``, ``"FINAL"`` or ``"CUSTOM"`` (default: the scene's, FINAL
    in a new file); ``samples`` counts only with ``"CUSTOM"`` quality. ``density`` is the
    map density in texels per metre and ``resolution`` the largest map size.
    ``max_samples`` and ``max_minutes`` are the cap of the FINAL quality's adaptive bake
    (samples per texel of any map; no further pass after so long).
    Returns the :func:`.blender.bake.bake_exposure` result dict (maps per object, and
    ``"noise"``: the error each map reached and the samples it took).
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
    if quality is not None:
        scene.lightfade_bake.quality = quality
    if density is not None:
        scene.lightfade_bake.texels_per_metre = float(density)
    if max_samples is not None:
        scene.lightfade_bake.max_samples = int(max_samples)
    if max_minutes is not None:
        scene.lightfade_bake.max_minutes = float(max_minutes)
    settings = BakeSettings.from_scene(scene, unwrap=unwrap)
    return bake_exposure(scene, list(objects or []), settings, report=print, progress=progress)


def localize_linked(scene=None):
    """Age Linked Instances: each empty of ``scene`` instancing a collection linked from
    another .blend instances a local one instead, holding local copies of its aging objects
    (their meshes stay the library's); the bake then ages them per instance, and Reset with
    the exposure puts the library's collections back.  Returns one line per collection."""
    from .blender.bake.linked import localize

    return localize(_scene(scene))


def age_scene(scene=None, years=None, objects=(), progress=None):
    """Age the enabled materials (of ``objects``, or all) and show ``years``.

    Returns the aged materials (one per object and material). Raises :class:`AgingError`
    naming every problem found, before anything changes, when something cannot be aged.
    """
    from .blender.aging.prepare import age_scene as _age

    scene = _scene(scene)
    years = scene.lightfade.years if years is None else years
    return _age(scene, years, list(objects), progress, report=print)


def set_years(scene=None, years=0.0):
    """Show ``years`` on the aged materials: one write of the scene's years property,
    which the materials evaluate themselves.

    Nothing is prepared for any number of years (the tables' dose axis is absolute and
    saturates). Stale materials (changed recipe, schedule or light groups) are named in
    one line each with what refreshes them (Age), as the panel says. Raises
    :class:`AgingError` for years that are not a finite number >= 0, before anything
    changes. Returns the seconds taken.
    """
    from .blender.aging.apply import update_scene
    from .blender.errors import check_years

    scene = _scene(scene)
    return update_scene(scene, check_years(years))


def keyframe_years(scene=None, keys=()):
    """Keyframe the scene's years (the custom property ``lightfade_years`` the aged
    materials read): ``keys`` is a sequence of (frame, years) pairs."""
    from .blender.errors import check_years
    from .blender.aging.years import keyframe_years as key

    scene = _scene(scene)
    keys = [(int(frame), check_years(years)) for frame, years in keys]
    for frame, years in keys:
        key(scene, frame, years)


def apply_aging(scene=None, years=None):
    """Real aged images (numpy evaluator of each material's aging table), wired into the
    aged materials in place of their node groups: for export, other engines, painting.

    ``years`` defaults to the scene's. Returns {aged material name: image}.
    :func:`live_aging` puts the node groups back.
    """
    from .blender.aging.apply import apply_aging as _apply

    return _apply(_scene(scene), years)


def live_aging(scene=None):
    """Undo :func:`apply_aging`: the node groups evaluate the years again; returns how
    many applied images were removed."""
    from .blender.aging.apply import live_aging as _live

    return _live(_scene(scene))


def reset(scene=None, exposure=False):
    """Undo aging (and with ``exposure=True`` remove the exposure maps); returns how many
    aged materials were reset."""
    from .blender.reset import reset_scene

    return reset_scene(_scene(scene), exposure=exposure)


def material_plan(scene=None, objects=()):
    """What Age would do, per (object, material): a list of dicts.

    Keys: ``object``, ``material``, ``path`` (``"DIRECT"``, ``"BAKED"`` or ``"FLAT"``),
    ``reason``, ``problems`` (lines saying what to fix) and ``status`` of an existing
    aged copy (``"not aged"``, ``"aged"``, ``"stale: ..."``). Runs no Cycles work.
    """
    from .blender.status import material_status

    scene = _scene(scene)
    return material_status(scene, list(objects))


def set_parts(material, parts=(), rest=None):
    """Say which parts of ``material`` age with which recipe (several materials in one
    texture), replacing its parts; ``parts=()`` removes them.

    Each part is a dict: ``name``, ``recipe`` (``"KEEP"``: does not age, or a recipe
    identifier such as ``"BARE_WOOD"``), exactly one mask — ``image`` (a
    ``bpy.types.Image``, with optional ``uv_map``), ``attribute`` (a colour or float
    attribute of the mesh) or ``node`` (a node's name in the graph, with optional
    ``socket``, its output's name) — and optional ``channel`` (``"R"``, ``"G"``, ``"B"``,
    ``"A"``), ``blue_wool`` (1-8) or ``beta`` (×10⁻⁶). ``rest`` is ``"RECIPE"`` (what no
    part claims ages with the material's recipe) or ``"KEEP"`` (it does not age).
    Raises ``ValueError`` (one line) before anything changes. Press Age (or
    :func:`age_scene`) afterwards; :func:`material_plan` lists what would stop it.
    """
    from .blender.parts.properties import set_parts as _set

    return _set(material, list(parts), rest)


def set_daylight(scene=None, latitude=0.0, longitude=0.0, north=0.0, weather=None):
    """Give the scene a place and climate: daylight becomes one annual bake.

    ``latitude`` (degrees north, -90..90) and ``longitude`` (degrees east, -180..180) of
    the place; ``north`` the counterclockwise angle in degrees from the scene's +Y axis to
    geographic north about +Z (0: +Y is north; 90: -X is north); ``weather`` None (a clear
    sky every day) or the path of an EPW, TMY3 or TMY2 file.  Annual daylight is turned
    on: the next bake lights the scene with the sun over every hour of the year and the
    sky, and the sun lamps standing for daylight are muted in it.  Raises ``ValueError``
    (one line naming the value or the file) before anything changes.  Returns the
    scene's ``lightfade_daylight`` settings.
    """
    from .blender.daylight.place import set_daylight as _set

    return _set(_scene(scene), latitude, longitude, north, weather)


def annual_dose(scene=None, obj=None):
    """``{light group name: (H, W) float32 lux·h per year}`` for ``obj``'s exposure maps.

    Each group's map times its hours per day and days per year (the annual daylight
    group: its year-round mean illuminance × 8760 h). Rows run bottom-up as in the
    image (row 0 is UV v = 0). Raises ``RuntimeError`` (``LightFadeBakeError``) when the
    object has no baked map of a counted emitter.
    """
    from .blender.daylight.doses import annual_dose as _dose

    scene = _scene(scene)
    obj = obj if obj is not None else _bpy().context.object
    return _dose(scene, obj)


def __getattr__(name):
    if name == "AgingError":
        from .blender.errors import AgingError

        return AgingError
    raise AttributeError(name)
