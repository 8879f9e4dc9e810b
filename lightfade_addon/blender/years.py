"""The scene's years: one custom property that Blender itself animates and shaders read.

The years live in the scene's custom property ``lightfade_years`` (not in an add-on
property): an F-curve on it evaluates in any Blender, and the aging node group reads
it with an Attribute node of type View Layer. So keyframes, the slider, ``blender -b
file.blend -a`` and the Material Preview follow the years with auto-run of Python
scripts off and LightFade absent. ``Scene.lightfade.years`` is a view of it for
scripts and the panel.
"""

from __future__ import annotations

#: The scene custom property holding the years (read by every aging node group).
YEARS_PROP = "lightfade_years"
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
    """Keyframe the years at ``frame``."""
    write_years(scene, years)
    scene.keyframe_insert(f'["{YEARS_PROP}"]', frame=frame)
