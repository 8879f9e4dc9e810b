"""The scene's years: one custom property that Blender itself animates and shaders read.

The years live in the scene's custom property ``lightfade_years`` (not in an add-on
property): an F-curve on it evaluates in any Blender, and the aging node group reads
it with an Attribute node of type View Layer. So keyframes, the slider, ``blender -b
file.blend -a`` and the Material Preview follow the years with auto-run of Python
scripts off and LightFade absent. ``Scene.lightfade.years`` is a view of it for
scripts and the panel.

Keys on the years are **linear**: a time-lapse shows years at a steady rate. Keys made
by :func:`keyframe_years` (``api.keyframe_years``, the panel's *Key Years* button) are
linear as they are made; keys inserted otherwise (*I* over the Years field, a script's
``scene.keyframe_insert``) come with Blender's default, Bezier, and :func:`linear_keys`
turns those into linear (LightFade runs it after every change to an action and before
saving; :mod:`.handlers`). Any other interpolation (Sine, Quadratic, Constant, ...)
is the artist's choice and stays. Linear keys are plain Blender data: the saved file
animates them the same without LightFade.
"""

from __future__ import annotations

#: The scene custom property holding the years (read by every aging node group).
YEARS_PROP = "lightfade_years"
#: The F-curve data path of the years on the scene.
YEARS_PATH = f'["{YEARS_PROP}"]'
#: The slider's soft range.
SOFT_MAX_YEARS = 100.0


def get_years(scene):
    """The scene's years (0 before any were set)."""
    value = scene.get(YEARS_PROP, 0.0)
    try:
        return float(value)
    except (TypeError, ValueError):
        return 0.0


def ensure_years(scene):
    """Create the property (0 years) with its slider settings if the scene has none."""
    if YEARS_PROP not in scene.keys():
        scene[YEARS_PROP] = 0.0
    ui = scene.id_properties_ui(YEARS_PROP)
    ui.update(min=0.0, soft_min=0.0, soft_max=SOFT_MAX_YEARS, precision=1, step=10,
              description="Years of light exposure LightFade shows (keyframe it for a "
              "time-lapse; the aged materials read it without Python)")


def write_years(scene, years):
    """Set the scene's years and tag the scene so that viewports and renders follow."""
    ensure_years(scene)
    scene[YEARS_PROP] = float(years)
    scene.update_tag()


def keyframe_years(scene, frame, years):
    """Keyframe the years at ``frame`` (a linear key)."""
    write_years(scene, years)
    scene.keyframe_insert(YEARS_PATH, frame=frame)
    linear_keys(scene)


def years_fcurve(scene):
    """The F-curve animating the scene's years, or None.

    Blender 4.4+ keeps F-curves in an action's slot (channelbag); 4.2 on the action.
    """
    anim = scene.animation_data
    action = anim.action if anim is not None else None
    if action is None:
        return None
    if hasattr(anim, "action_slot"):
        from bpy_extras.anim_utils import action_get_channelbag_for_slot

        bag = action_get_channelbag_for_slot(action, anim.action_slot)
        curves = bag.fcurves if bag is not None else ()
    else:
        curves = action.fcurves
    return next((c for c in curves if c.data_path == YEARS_PATH), None)


def linear_keys(scene):
    """Make the years' Bezier keys linear (Blender's default, eased in and out);
    other interpolations are kept. Returns how many keys changed."""
    curve = years_fcurve(scene)
    if curve is None:
        return 0
    changed = 0
    for point in curve.keyframe_points:
        if point.interpolation == "BEZIER":
            point.interpolation = "LINEAR"
            changed += 1
    if changed:
        curve.update()
    return changed
