"""Shared helpers for the scripted demo scenes: light units, collections, images, tagged
materials, tagged lights, cameras and the world.

Meshes with UVs are in :mod:`scenes.meshes`, render settings, stills and saving in
:mod:`scenes.render`, and the builders' command line in :mod:`scenes.cli`.

Conventions the LightFade shell relies on
-----------------------------------------
- Every material meant to age has a Principled BSDF whose Base Color is fed by an Image
  Texture node (node name ``"Albedo"``) holding a packed, sRGB, procedurally generated image,
  and the custom properties ``mat["lightfade_recipe"]`` (one of :data:`RECIPES`) and
  optionally ``mat["lightfade_blue_wool"]`` (ISO Blue Wool class 1-8).
- Its mesh has one UV map ("UVMap") whose islands never overlap, so that a per-texel bake
  maps each texel to one place on the surface (the builders of :mod:`scenes.meshes`).
- Every light's data carries ``lightfade_spectrum`` (one of :data:`SPECTRA`),
  ``lightfade_hours_per_day`` and ``lightfade_uv_filter``.

Light units
-----------
Cycles gives a surface facing a sun of strength ``S`` an irradiance of ``S`` W/m², and a
surface at distance ``r`` from a point or spot light of power ``P`` an irradiance of
``P cos(theta) / (4 pi r^2)`` W/m² (measured with this bpy build: a white Lambertian
surface renders at radiance ``E / pi``). LightFade reads 1 W/m² as 683 lux, so
:func:`lux_from_irradiance` and the ``*_for_lux`` helpers convert with that factor.
"""

from __future__ import annotations

import math

import bpy
import numpy as np
from mathutils import Vector

RECIPES = ("printed-paper", "dyed-fabric", "painted-wood", "bare-wood")
SPECTRA = ("daylight", "daylight-glass", "incandescent", "fluorescent", "led")
LUX_PER_W_M2 = 683.0

# --- units --------------------------------------------------------------------------------


def lux_from_irradiance(E):
    """Illuminance in lux from Blender irradiance ``E`` in W/m² (LightFade's 683 lm/W)."""
    return LUX_PER_W_M2 * E


def sun_strength_for_lux(lux, elevation_deg=90.0):
    """Sun strength (W/m²) giving ``lux`` on a horizontal surface at the given sun elevation."""
    return lux / LUX_PER_W_M2 / math.sin(math.radians(elevation_deg))


def point_power_for_lux(lux, distance, cos_incidence=1.0):
    """Point/spot light power (Blender W) giving ``lux`` at ``distance`` metres.

    ``E = P cos(theta) / (4 pi r^2)`` W/m², times 683 lux per W/m².
    """
    return lux / LUX_PER_W_M2 * 4.0 * math.pi * distance**2 / cos_incidence


# --- scene and collections ------------------------------------------------------------------


def reset():
    """Start from an empty factory scene and return it."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    return bpy.context.scene


def collection(name, parent=None):
    """Get or create the collection ``name``, linked under ``parent`` (default: scene root)."""
    coll = bpy.data.collections.get(name)
    if coll is None:
        coll = bpy.data.collections.new(name)
        (parent or bpy.context.scene.collection).children.link(coll)
    return coll


def collection_objects(coll):
    """Objects of ``coll`` and its child collections (``all_objects`` can be stale after a render)."""
    obs = list(coll.objects)
    for child in coll.children:
        obs.extend(o for o in collection_objects(child) if o not in obs)
    return obs


def set_hidden(objects, hidden):
    """Hide or show objects in both render and viewport."""
    for ob in objects:
        ob.hide_render = hidden
        ob.hide_viewport = hidden


# --- images and materials ---------------------------------------------------------------------


def image_from_array(name, rgb):
    """A packed sRGB byte image holding ``rgb`` (H, W, 3) sRGB-encoded floats, row 0 at bottom."""
    rgb = np.asarray(rgb, dtype=np.float32)
    h, w = rgb.shape[:2]
    img = bpy.data.images.new(name, width=w, height=h, alpha=False, float_buffer=False)
    img.colorspace_settings.name = "sRGB"
    rgba = np.ones((h, w, 4), dtype=np.float32)
    rgba[..., :3] = np.clip(rgb, 0.0, 1.0)
    img.pixels.foreach_set(rgba.ravel())
    img.update()
    img.pack()  # a generated image with edited pixels is packed as PNG
    return img


def new_material(name):
    """A new material with a node tree (Principled BSDF and Material Output)."""
    mat = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):       # Blender 4.x: node trees need use_nodes
        mat.use_nodes = True
    return mat


def aging_material(name, image, recipe, blue_wool=None, roughness=0.6, specular=0.5, sheen=0.0):
    """A Principled material with an image-fed Base Color, tagged for LightFade.

    Parameters
    ----------
    recipe : str
        One of :data:`RECIPES`; stored in ``mat["lightfade_recipe"]``.
    blue_wool : int, optional
        ISO Blue Wool class 1-8; stored in ``mat["lightfade_blue_wool"]``.
    """
    if recipe not in RECIPES:
        raise ValueError(f"material {name!r}: unknown recipe {recipe!r}, expected one of {RECIPES}")
    mat = new_material(name)
    nt = mat.node_tree
    bsdf = nt.nodes["Principled BSDF"]
    tex = nt.nodes.new("ShaderNodeTexImage")
    tex.name = tex.label = "Albedo"
    tex.image = image
    tex.interpolation = "Linear"
    tex.location = (-400, 300)
    nt.links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])
    bsdf.inputs["Roughness"].default_value = roughness
    bsdf.inputs["Specular IOR Level"].default_value = specular
    if sheen:
        bsdf.inputs["Sheen Weight"].default_value = sheen
    mat["lightfade_recipe"] = recipe
    if blue_wool is not None:
        if not 1 <= int(blue_wool) <= 8:
            raise ValueError(f"material {name!r}: blue wool class {blue_wool} outside 1-8")
        mat["lightfade_blue_wool"] = int(blue_wool)
    return mat


def plain_material(name, colour, roughness=0.7, metallic=0.0, emission=None, strength=0.0):
    """An untagged Principled material of one linear colour (walls, fittings)."""
    mat = new_material(name)
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*colour, 1.0)
    bsdf.inputs["Roughness"].default_value = roughness
    bsdf.inputs["Metallic"].default_value = metallic
    if emission is not None:
        bsdf.inputs["Emission Color"].default_value = (*emission, 1.0)
        bsdf.inputs["Emission Strength"].default_value = strength
    mat.diffuse_color = (*colour, 1.0)
    return mat


def tagged_materials():
    """All materials carrying ``lightfade_recipe``."""
    return [m for m in bpy.data.materials if "lightfade_recipe" in m]


# --- lights and cameras -----------------------------------------------------------------------


def aim(ob, target):
    """Point an object's -Z axis (lights, cameras) at ``target``, keeping +Y up."""
    d = Vector(target) - ob.location
    ob.rotation_mode = "QUATERNION"
    ob.rotation_quaternion = d.to_track_quat("-Z", "Y")


def add_light(name, kind, energy, location, coll=None, *, spectrum, hours_per_day, uv_filter,
              target=None, direction=None, **settings):
    """A light object, its data tagged for LightFade.

    ``target`` aims the light at a point; ``direction`` (for suns) is the direction the light
    travels. Extra keyword ``settings`` are set on the light data (``spot_size``, ...).
    """
    if spectrum not in SPECTRA:
        raise ValueError(f"light {name!r}: unknown spectrum {spectrum!r}, expected one of {SPECTRA}")
    data = bpy.data.lights.new(name, kind)
    data.energy = energy
    for k, v in settings.items():
        setattr(data, k, v)
    data["lightfade_spectrum"] = spectrum
    data["lightfade_hours_per_day"] = float(hours_per_day)
    data["lightfade_uv_filter"] = bool(uv_filter)
    ob = bpy.data.objects.new(name, data)
    (coll or bpy.context.scene.collection).objects.link(ob)
    ob.location = location
    if direction is not None:
        ob.rotation_mode = "QUATERNION"
        ob.rotation_quaternion = Vector(direction).to_track_quat("-Z", "Y")
    elif target is not None:
        aim(ob, target)
    return ob


def sun_direction(elevation_deg, azimuth_deg):
    """Unit vector the sunlight travels along: azimuth from +x toward +y, downward by elevation."""
    e, a = math.radians(elevation_deg), math.radians(azimuth_deg)
    return Vector((math.cos(e) * math.cos(a), math.cos(e) * math.sin(a), -math.sin(e)))


def add_camera(name, location, target, lens=35.0, coll=None):
    data = bpy.data.cameras.new(name)
    data.lens = lens
    data.sensor_fit = "HORIZONTAL"
    ob = bpy.data.objects.new(name, data)
    (coll or bpy.context.scene.collection).objects.link(ob)
    ob.location = location
    aim(ob, target)
    return ob


def world_sky(scene, colour, strength, name="World"):
    """A uniform-colour world (sky fill light) of the given strength."""
    world = bpy.data.worlds.new(name)
    if bpy.app.version < (5, 0, 0):  # Blender 4.x: no node tree until this (5.0+: always on)
        world.use_nodes = True
    bg = world.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (*colour, 1.0)
    bg.inputs["Strength"].default_value = strength
    scene.world = world
    return world
