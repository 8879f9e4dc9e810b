"""Shared helpers for the scripted demo scenes: meshes with UVs, tagged materials, tagged
lights, cameras, render settings and a small CLI.

Conventions the LightFade shell relies on
-----------------------------------------
- Every material meant to age has a Principled BSDF whose Base Color is fed by an Image
  Texture node (node name ``"Albedo"``) holding a packed, sRGB, procedurally generated image,
  and the custom properties ``mat["lightfade_recipe"]`` (one of :data:`RECIPES`) and
  optionally ``mat["lightfade_blue_wool"]`` (ISO Blue Wool class 1-8).
- Its mesh has one UV map ("UVMap") whose islands never overlap, so that a per-texel bake
  maps each texel to one place on the surface.
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

import argparse
import math
import os
import time

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


# --- meshes ----------------------------------------------------------------------------------


def box_quads(lo, hi, skip=()):
    """The six faces of an axis-aligned box as rectangles ``(p0, p1, p2, p3)``, CCW outside.

    ``p0 -> p1`` is the face's u direction and ``p0 -> p3`` its v direction (up on walls).
    ``skip`` names faces to leave out: any of ``"+x" "-x" "+y" "-y" "+z" "-z"``.
    """
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    faces = {
        "-y": ((x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)),
        "+x": ((x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)),
        "+y": ((x1, y1, z0), (x0, y1, z0), (x0, y1, z1), (x1, y1, z1)),
        "-x": ((x0, y1, z0), (x0, y0, z0), (x0, y0, z1), (x0, y1, z1)),
        "+z": ((x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)),
        "-z": ((x0, y1, z0), (x1, y1, z0), (x1, y0, z0), (x0, y0, z0)),
    }
    return [q for k, q in faces.items() if k not in skip]


def pack_rectangles(sizes, gap=0.004):
    """Shelf-pack rectangles of physical sizes ``(w, h)`` into the unit square.

    One scale (UV units per metre) for all, as large as fits, so texel density is uniform.

    Returns
    -------
    offsets : list of (u, v)
        Lower-left UV corner of each rectangle.
    scale : float
        UV units per metre.
    """
    order = sorted(range(len(sizes)), key=lambda i: -sizes[i][1])

    def place(s):
        offsets = [None] * len(sizes)
        x = y = gap
        row_h = 0.0
        for i in order:
            w, h = sizes[i][0] * s, sizes[i][1] * s
            if w + 2 * gap > 1.0:
                return None
            if x + w + gap > 1.0:
                y += row_h + gap
                x, row_h = gap, 0.0
            offsets[i] = (x, y)
            x += w + gap
            row_h = max(row_h, h)
        return offsets if y + row_h + gap <= 1.0 else None

    lo, hi = 0.0, 1.0 / max(max(w, h) for w, h in sizes)
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if place(mid) else (lo, mid)
    return place(lo), lo


def _link(name, mesh, coll, material):
    ob = bpy.data.objects.new(name, mesh)
    (coll or bpy.context.scene.collection).objects.link(ob)
    if material is not None:
        mesh.materials.append(material)
    return ob


def mesh_from_quads(name, quads, coll=None, material=None, gap=0.004):
    """An object made of separate rectangles, each its own UV island, packed without overlap."""
    quads = [[Vector(p) for p in q] for q in quads]
    sizes = [((q[1] - q[0]).length, (q[3] - q[0]).length) for q in quads]
    offsets, s = pack_rectangles(sizes, gap=gap)
    verts, faces, uvs = [], [], []
    for q, (w, h), (u0, v0) in zip(quads, sizes, offsets):
        n = len(verts)
        verts.extend(q)
        faces.append((n, n + 1, n + 2, n + 3))
        uvs.extend([(u0, v0), (u0 + w * s, v0), (u0 + w * s, v0 + h * s), (u0, v0 + h * s)])
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([tuple(v) for v in verts], [], faces)
    uv = mesh.uv_layers.new(name="UVMap")
    uv.data.foreach_set("uv", np.asarray(uvs, dtype=np.float32).ravel())
    mesh.update()
    return _link(name, mesh, coll, material)


def grid_mesh(name, nu, nv, fn, coll=None, material=None, smooth=False):
    """A (nu x nv)-quad sheet with UVs = its parameters: ``fn(u, v) -> (x, y, z)``, u, v in [0, 1]."""
    us = np.linspace(0.0, 1.0, nu + 1)
    vs = np.linspace(0.0, 1.0, nv + 1)
    verts = [fn(u, v) for v in vs for u in us]
    faces, uvs = [], []
    for j in range(nv):
        for i in range(nu):
            a = j * (nu + 1) + i
            faces.append((a, a + 1, a + nu + 2, a + nu + 1))
            uvs.extend([(us[i], vs[j]), (us[i + 1], vs[j]), (us[i + 1], vs[j + 1]), (us[i], vs[j + 1])])
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts, [], faces)
    uv = mesh.uv_layers.new(name="UVMap")
    uv.data.foreach_set("uv", np.asarray(uvs, dtype=np.float32).ravel())
    if smooth:
        mesh.shade_smooth()
    mesh.update()
    return _link(name, mesh, coll, material)


def lathe_mesh(name, profile, segments=32, coll=None, material=None, location=(0, 0, 0)):
    """A surface of revolution about z from a profile of ``(radius, z)`` points (radius 0 = pole)."""
    verts, rings = [], []
    for r, z in profile:
        if r == 0:
            rings.append([len(verts)])
            verts.append((0.0, 0.0, z))
        else:
            ring = []
            for k in range(segments):
                a = 2 * math.pi * k / segments
                ring.append(len(verts))
                verts.append((r * math.cos(a), r * math.sin(a), z))
            rings.append(ring)
    faces = []
    for ra, rb in zip(rings[:-1], rings[1:]):
        for k in range(segments):
            k1 = (k + 1) % segments
            if len(ra) == 1:
                faces.append((ra[0], rb[k], rb[k1]))
            elif len(rb) == 1:
                faces.append((ra[k], ra[k1], rb[0]))
            else:
                faces.append((ra[k], ra[k1], rb[k1], rb[k]))
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts, [], faces)
    mesh.shade_smooth()
    mesh.update()
    ob = _link(name, mesh, coll, material)
    ob.location = location
    return ob


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


# --- render --------------------------------------------------------------------------------


def denoiser_available():
    """True if this build's Cycles has OpenImageDenoise (CPU denoising)."""
    try:
        import _cycles
    except ImportError:
        return False
    return bool(getattr(_cycles, "with_openimagedenoise", False))


def configure_render(scene, width=640, height=400, samples=32, engine="CYCLES", *,
                     denoise=True, view_transform="AgX"):
    """Set resolution, engine and CPU Cycles light paths tuned for the demo interiors.

    Denoising (OpenImageDenoise) is used if the build has it; the seed is fixed so that
    renders are reproducible. Exposure and look are scene-specific and left as each scene
    sets them; ``view_transform`` is set (AgX by default; the swatches use Standard).
    """
    scene.render.engine = engine
    scene.render.resolution_x = width
    scene.render.resolution_y = height
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_mode = "RGB"
    scene.render.image_settings.color_depth = "8"
    scene.render.film_transparent = False
    if engine == "CYCLES":
        cy = scene.cycles
        cy.device = "CPU"
        cy.samples = samples
        cy.use_adaptive_sampling = True
        cy.adaptive_threshold = 0.02
        cy.adaptive_min_samples = 0
        cy.seed = 0
        cy.use_animated_seed = False
        cy.max_bounces = 4
        cy.diffuse_bounces = 3
        cy.glossy_bounces = 1
        cy.transmission_bounces = 2
        cy.transparent_max_bounces = 4
        cy.volume_bounces = 0
        cy.caustics_reflective = False
        cy.caustics_refractive = False
        cy.blur_glossy = 1.0
        cy.sample_clamp_direct = 0.0
        cy.sample_clamp_indirect = 10.0
        cy.use_light_tree = True
        use_dn = denoise and denoiser_available()
        cy.use_denoising = use_dn
        if use_dn:
            cy.denoiser = "OPENIMAGEDENOISE"
            cy.denoising_input_passes = "RGB_ALBEDO_NORMAL"
            cy.denoising_prefilter = "ACCURATE"
    elif "EEVEE" in engine:
        scene.eevee.taa_render_samples = samples
    scene.view_settings.view_transform = view_transform
    scene.display_settings.display_device = "sRGB"
    return scene


def view_settings(scene):
    """The scene's colour management as a dict (``view_transform``, ``look``, ``exposure``),
    so that a caller that re-runs :func:`configure_render` can put the scene's own back
    with :func:`apply_view_settings`."""
    v = scene.view_settings
    return dict(view_transform=v.view_transform, look=v.look, exposure=round(v.exposure, 3))


def apply_view_settings(scene, view):
    """Set ``view_transform``, ``look`` and ``exposure`` from a :func:`view_settings` dict."""
    v = scene.view_settings
    v.view_transform = view["view_transform"]
    v.look = view["look"]
    v.exposure = view["exposure"]


def render_still(path, camera=None, scene=None):
    """Render the scene (optionally through ``camera``, an object or its name) to a PNG.

    Returns the elapsed render time in seconds.
    """
    scene = scene or bpy.context.scene
    if camera is not None:
        scene.camera = bpy.data.objects[camera] if isinstance(camera, str) else camera
    scene.render.filepath = os.path.abspath(path)
    t0 = time.perf_counter()
    bpy.ops.render.render(write_still=True, scene=scene.name)
    return time.perf_counter() - t0


def save_blend(path):
    """Pack every image into the file and save it as ``path``."""
    for img in bpy.data.images:
        if img.source in {"GENERATED", "FILE"} and img.packed_file is None and img.has_data:
            img.pack()
    bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(path), compress=True)


# --- command line ------------------------------------------------------------------------------


def main(build, description, argv=None, default_resolution=1024):
    """CLI shared by the scene modules: build, save, optionally render previews."""
    p = argparse.ArgumentParser(description=description)
    p.add_argument("output", nargs="?", help="where to save the .blend (images packed)")
    p.add_argument("--resolution", type=int, default=default_resolution,
                   help="texture size of the largest albedo image (texels)")
    p.add_argument("--render", metavar="PNG", help="also render the main camera to this PNG")
    p.add_argument("--samples", type=int, default=32)
    p.add_argument("--size", type=int, nargs=2, default=(640, 400), metavar=("W", "H"))
    args = p.parse_args(argv)
    info = build(path=args.output, resolution=args.resolution)
    if args.render:
        scene = bpy.context.scene
        configure_render(scene, *args.size, samples=args.samples)
        apply_view_settings(scene, info["view"])
        t = render_still(args.render, camera=info["camera"])
        print(f"rendered {args.render} in {t:.1f} s")
    for k, v in info.items():
        print(f"{k}: {v}")
    return info
