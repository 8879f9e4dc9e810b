"""The daylight group: one Cycles bake of the year's sun and sky for the scene's place.

When the scene has a place and *Annual Daylight* is on (:mod:`..daylight.place`), the sun
lamps and the world that stand for daylight (their spectrum is ``daylight`` or
``daylight-glass``, Auto included) leave the emitters, and one emitter ``"Daylight"`` of
kind ``DAYLIGHT`` takes their place.  Its bake lights the scene with a temporary World:
an Environment Texture of :func:`..core.daylight.annual_sky_map` (lux·h per year per
steradian, scene coordinates) into a Background of strength 1, the image scaled so that
the bake gives the **year-round mean illuminance** directly::

    pixel = L / (683 lm/W × 8760 h)   ->   stored lux = annual lux·h / 8760 h

(for a uniform sky of radiance ``L`` a Background of strength ``W`` bakes ``B = W`` and
is stored as ``683 π B`` lux, :mod:`.common`; the open plane's dose is ``π L``).  The
group's schedule is 24 h × 365 d (:data:`..daylight.settings.DAYLIGHT_HOURS_PER_DAY`), so
``lux × hours × days`` everywhere downstream is the annual dose in lux·h.  Its spectrum
and UV filter are the scene's daylight settings; the sun lamps are hidden in every bake
(as any lamp outside the group being baked), the user's World is put back and the
temporary world and image are removed when the bake ends, also on error.
"""

from __future__ import annotations

import bpy
import numpy as np

from ..daylight import place as _place
from ..daylight.settings import DAYLIGHT_DAYS_PER_YEAR, DAYLIGHT_HOURS_PER_DAY
from ..vocabulary import resolve_spectrum
from .common import DAYLIGHT_EMITTER, LUX_PER_WATT, TEMP_PREFIX

#: Spectra that mark a sun lamp or a world as daylight.
DAYLIGHT_SPECTRA = ("daylight", "daylight-glass")
#: Image value per lux·h a year per steradian of the annual sky map.
SKY_SCALE = 1.0 / (LUX_PER_WATT * DAYLIGHT_HOURS_PER_DAY * DAYLIGHT_DAYS_PER_YEAR)
SKY_WORLD = TEMP_PREFIX + "AnnualSky"

daylight_active = _place.daylight_active


def stands_for_daylight(scene, schedule, kind):
    """A sun lamp or world whose light the annual daylight bake replaces (True only while
    annual daylight is active)."""
    return (kind in ("SUN", "WORLD") and schedule is not None
            and resolve_spectrum(schedule, kind) in DAYLIGHT_SPECTRA
            and daylight_active(scene))


def problem(scene):
    """One line saying why the daylight group cannot be baked (a weather file missing or
    unreadable, a place out of range), or None; no sky map is computed."""
    try:
        _place.scene_place(scene)
    except _place.DaylightError as err:
        return str(err)
    return None


def replaced_lamps(scene):
    """Names of the sun lamps (and ``"World"``) that annual daylight mutes, in scene order."""
    if not daylight_active(scene):
        return []
    names = [o.name for o in scene.objects
             if o.type == "LIGHT" and o.data.type == "SUN" and not o.hide_render
             and o.data.lightfade.enabled and o.data.energy > 0.0
             and stands_for_daylight(scene, o.data.lightfade, "SUN")]
    world = scene.world
    if world is not None and world.lightfade.enabled and world.lightfade.spectrum != "AUTO" \
            and stands_for_daylight(scene, world.lightfade, "WORLD"):
        names.append("World")
    return names


def sky_pixels(sky):
    """RGBA float32 pixels of an annual sky map, scaled by :data:`SKY_SCALE` (the map's
    row 0 is the nadir, as Blender stores an image's bottom row first)."""
    sky = np.asarray(sky, dtype=np.float32)
    if sky.ndim != 2 or sky.shape[1] != 2 * sky.shape[0]:
        raise ValueError(f"an annual sky map is (w/2, w), got shape {sky.shape}")
    if not np.all(np.isfinite(sky)) or np.any(sky < 0):
        raise ValueError("the annual sky map must be finite and >= 0")
    h, w = sky.shape
    px = np.ones((h, w, 4), dtype=np.float32)
    px[..., :3] = (sky * np.float32(SKY_SCALE))[..., None]
    return px


def use_annual_world(state, scene):
    """Light the scene with the annual sky for this bake (undone by ``state``)."""
    sky = _place.annual_sky(scene)
    h, w = sky.shape
    image = state.new_image("AnnualSky", w, h)
    image.pixels.foreach_set(sky_pixels(sky).ravel())
    world = bpy.data.worlds.new(SKY_WORLD)
    state.push(lambda: bpy.data.worlds.remove(world))
    if bpy.app.version < (5, 0, 0):
        world.use_nodes = True
    nodes, links = world.node_tree.nodes, world.node_tree.links
    nodes.clear()
    env = nodes.new("ShaderNodeTexEnvironment")
    env.name = env.label = "Annual Sky"
    env.image = image
    env.interpolation = "Linear"
    env.projection = "EQUIRECTANGULAR"
    background = nodes.new("ShaderNodeBackground")
    background.inputs["Strength"].default_value = 1.0
    output = nodes.new("ShaderNodeOutputWorld")
    links.new(env.outputs["Color"], background.inputs["Color"])
    links.new(background.outputs["Background"], output.inputs["Surface"])
    world.cycles.sampling_method = "MANUAL"  # importance map at the sky map's own resolution
    world.cycles.sample_map_resolution = int(w)
    state.set(scene, "world", world)
    return world


#: Image property recording the place and weather a daylight map was baked for.
SKY_STAMP = "lightfade_sky"


def sky_stamp(scene):
    """A string naming what the annual sky depends on (place, north, weather, albedo and
    altitude; not the map's width)."""
    key = _place.sky_key(scene)
    return repr(key[:-1] if key is not None else None)


def stamp(image, scene, group):
    """Record on a daylight group's map the place and weather it was baked for."""
    if any(e.kind == "DAYLIGHT" for e in group.emitters):
        image[SKY_STAMP] = sky_stamp(scene)


def sky_changed(scene, image):
    """True when a daylight map was baked for another place, north or weather."""
    baked = image.get(SKY_STAMP) if image is not None else None
    return baked is not None and daylight_active(scene) and baked != sky_stamp(scene)


def daylight_emitter(scene):
    """``(name, kind)`` of the daylight emitter when annual daylight is active, else None."""
    return (DAYLIGHT_EMITTER, "DAYLIGHT") if daylight_active(scene) else None
