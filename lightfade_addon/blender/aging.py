"""Aging materials in Blender: albedo and exposure maps in, aged albedo images out.

For each material with LightFade enabled, used by one mesh object:

1. the albedo is the image feeding the Principled BSDF's Base Color (or the
   material's chosen image, or a flat Base Color turned into an image);
2. the object's exposure maps (lux per emitter, :mod:`.bake`) and the emitters'
   schedules become :class:`~lightfade_addon.core.aging.Light` objects;
3. a :class:`~lightfade_addon.core.aging.TextureAger` is prepared once, its grid
   kept in the .blend (``Scene["lightfade_grids"]``) so render nodes never simulate;
4. a new float image ``LF_Aged_<material>`` receives the aged pixels and a new
   Image Texture node feeding Base Color takes the place of the original link. The
   original image and node stay untouched; :func:`reset_material` puts the link back.

The years slider and the frame-change handler call :func:`update_scene`, which only
runs the dose-dependent part and writes pixels with ``foreach_set``.
"""

from __future__ import annotations

import base64
import collections.abc
import time

import bpy
import numpy as np

from ..core.aging import Light, TextureAger
from ..core.colorimetry import srgb_decode
from ..core.recipes import get_recipe
from .properties import RECIPE_IDS, resolve_spectrum

AGED_PREFIX = "LF_Aged_"
ALBEDO_PREFIX = "LF_Albedo_"
NODE_NAME = "LightFade Aged Albedo"
GRID_STORE = "lightfade_grids"
#: Largest texture LightFade ages (texels); larger ones are refused with a message.
MAX_TEXELS = 8192 * 8192


class AgingError(RuntimeError):
    """A problem the user can fix; the message names the object or material."""


# ----------------------------------------------------------------------- runtime cache

#: material name -> _Aged (runtime state: the prepared ager and the pixel buffer).
_AGED = {}


class _Aged:
    def __init__(self, ager, image, years):
        self.ager = ager
        self.image = image
        self.years = years
        n = ager.original.size // 3
        self.buffer = np.empty((n, 4), dtype=np.float32)
        self.buffer[:, 3] = 1.0


def clear_runtime():
    """Forget prepared agers (on file load, reset and unregister)."""
    _AGED.clear()


# ------------------------------------------------------------------------- the grid store


class SceneGridStore(collections.abc.MutableMapping):
    """``Scene["lightfade_grids"]`` as a mapping of grid keys to bytes (base64 inside)."""

    def __init__(self, scene):
        self.scene = scene

    def _group(self, create=False):
        if GRID_STORE not in self.scene and create:
            self.scene[GRID_STORE] = {}
        return self.scene.get(GRID_STORE)

    def __getitem__(self, key):
        group = self._group()
        if group is None or key not in group:
            raise KeyError(key)
        return base64.b64decode(group[key])

    def __setitem__(self, key, value):
        self._group(create=True)[key] = base64.b64encode(value).decode("ascii")

    def __delitem__(self, key):
        del self._group()[key]

    def __iter__(self):
        group = self._group()
        return iter(list(group.keys()) if group is not None else [])

    def __len__(self):
        group = self._group()
        return len(group) if group is not None else 0


# ------------------------------------------------------------------------ node helpers


def _principled(material):
    """The Principled BSDF feeding the active Material Output, or None."""
    tree = material.node_tree
    if tree is None:
        return None
    outputs = [n for n in tree.nodes if n.type == "OUTPUT_MATERIAL"]
    out = next((n for n in outputs if n.is_active_output), outputs[0] if outputs else None)
    if out is not None and out.inputs["Surface"].is_linked:
        node = out.inputs["Surface"].links[0].from_node
        if node.type == "BSDF_PRINCIPLED":
            return node
    return next((n for n in tree.nodes if n.type == "BSDF_PRINCIPLED"), None)


def albedo_source(material):
    """``(principled, image_node_or_None, link_or_None)`` for a material's albedo.

    Raises AgingError naming the material when it has no nodes, no Principled BSDF,
    or a Base Color fed by something LightFade cannot age.
    """
    if material.library is not None:
        raise AgingError(f"Material '{material.name}' is linked from a library: make it "
                         "local first (Object > Relations > Make Local)")
    if material.node_tree is None:
        raise AgingError(f"Material '{material.name}' has no node tree: enable 'Use Nodes'")
    bsdf = _principled(material)
    if bsdf is None:
        raise AgingError(f"Material '{material.name}' has no Principled BSDF: LightFade ages "
                         "its Base Color")
    socket = bsdf.inputs["Base Color"]
    if not socket.is_linked:
        return bsdf, None, None
    link = socket.links[0]
    node = link.from_node
    if node.name == NODE_NAME:                      # already aged: the original link is stored
        return bsdf, material.node_tree.nodes.get(material.lightfade.original_node), link
    chosen = material.lightfade.albedo_image
    if node.type != "TEX_IMAGE" or node.image is None or (chosen and node.image != chosen):
        raise AgingError(f"Material '{material.name}': Base Color must come straight from an "
                         "Image Texture node (or be a flat colour)")
    return bsdf, node, link


def _check_image(material, image):
    if image.source == "TILED":
        raise AgingError(f"Image '{image.name}' of material '{material.name}' uses UDIM tiles, "
                         "which LightFade does not support yet: bake it to a single image")
    if image.source not in ("FILE", "GENERATED"):
        raise AgingError(f"Image '{image.name}' of material '{material.name}' is a "
                         f"{image.source.lower()}: LightFade ages still images only")
    w, h = image.size
    if w == 0 or h == 0 or not image.has_data and not _try_load(image):
        raise AgingError(f"Image '{image.name}' of material '{material.name}' has no pixels: "
                         "the file is missing? Relink it (File > External Data > Find Missing "
                         "Files) or pack it")
    if w * h > MAX_TEXELS:
        raise AgingError(f"Image '{image.name}' ({w}×{h}) is larger than LightFade's limit of "
                         f"{int(np.sqrt(MAX_TEXELS))}² texels: scale it down")


def _try_load(image):
    try:
        image.pixels[0]
    except Exception:  # noqa: BLE001 (Blender raises various errors for missing files)
        return False
    return image.has_data


def read_rgba(image):
    """(H, W, 4) float32 pixels of an image (foreach_get: fast)."""
    w, h = image.size
    buf = np.empty(w * h * 4, dtype=np.float32)
    image.pixels.foreach_get(buf)
    return buf.reshape(h, w, 4)


def resample(a, shape):
    """Bilinear resampling of an (h, w) map to ``shape`` in UV space (texel centres)."""
    h, w = a.shape
    H, W = shape
    if (h, w) == (H, W):
        return a
    y = np.clip((np.arange(H) + 0.5) * h / H - 0.5, 0, h - 1)
    x = np.clip((np.arange(W) + 0.5) * w / W - 0.5, 0, w - 1)
    y0 = np.minimum(y.astype(int), h - 2 if h > 1 else 0)
    x0 = np.minimum(x.astype(int), w - 2 if w > 1 else 0)
    fy = (y - y0)[:, None]
    fx = (x - x0)[None, :]
    y1 = np.minimum(y0 + 1, h - 1)
    x1 = np.minimum(x0 + 1, w - 1)
    top = a[y0][:, x0] * (1 - fx) + a[y0][:, x1] * fx
    bottom = a[y1][:, x0] * (1 - fx) + a[y1][:, x1] * fx
    return top * (1 - fy) + bottom * fy


# ---------------------------------------------------------------------- lights and maps


def _schedule(scene, item):
    """The schedule of the emitter an exposure map was baked for, or None if gone."""
    if item.emitter_kind == "WORLD":
        return scene.world.lightfade if scene.world else None
    obj = bpy.data.objects.get(item.emitter)
    if obj is None:
        return None
    if item.emitter_kind == "EMISSIVE":
        return obj.lightfade_emitter
    return obj.data.lightfade if obj.type == "LIGHT" else None


def lights_and_exposure(scene, obj, shape):
    """Lights (one per exposure map) and their lux maps resampled to ``shape``."""
    lights, maps = [], []
    for item in obj.lightfade.exposure_maps:
        schedule = _schedule(scene, item)
        if schedule is None or not schedule.enabled or item.image is None:
            continue
        lux = read_rgba(item.image)[..., 0].astype(np.float64)
        lights.append(Light(resolve_spectrum(schedule, item.emitter_kind), schedule.uv_filter,
                            1.0, schedule.hours_per_day, schedule.days_per_year))
        maps.append(np.maximum(resample(lux, shape), 0.0))
    if not lights:
        raise AgingError(f"Object '{obj.name}' has no exposure maps from enabled emitters: "
                         "run Bake Exposure first")
    return lights, np.stack(maps)


def material_recipe(material):
    """The core recipe for a material's LightFade settings."""
    props = material.lightfade
    recipe = get_recipe(RECIPE_IDS[props.recipe])
    if props.sensitivity_mode == "BETA":
        return recipe.with_beta(props.beta * 1e-6)
    return recipe.with_blue_wool(props.blue_wool)


def users_of(material, scene):
    return [o for o in scene.objects if o.type == "MESH" and
            any(slot.material == material for slot in o.material_slots)]


# ------------------------------------------------------------------------------ aging


def _albedo_pixels(material, node, bsdf, shape_hint):
    """(H, W, 4) linear RGBA of the albedo, and the image it came from (or None)."""
    if node is None:                                   # a flat Base Color
        colour = np.array(bsdf.inputs["Base Color"].default_value, dtype=np.float32)
        h, w = shape_hint
        rgba = np.empty((h, w, 4), dtype=np.float32)
        rgba[...] = colour
        return rgba, None
    image = node.image
    _check_image(material, image)
    rgba = read_rgba(image)
    if not image.is_float and image.colorspace_settings.name.lower().startswith("srgb"):
        rgba[..., :3] = srgb_decode(rgba[..., :3])
    return rgba, image


def _aged_image(material, width, height):
    name = AGED_PREFIX + material.name
    image = bpy.data.images.get(name)
    if image is not None and tuple(image.size) != (width, height):
        bpy.data.images.remove(image)
        image = None
    if image is None:
        image = bpy.data.images.new(name, width, height, alpha=True, float_buffer=True)
    image.colorspace_settings.name = "Linear Rec.709"
    return image


def _wire(material, bsdf, node, image):
    """Insert the aged image node before Base Color, remembering the original link."""
    tree = material.node_tree
    props = material.lightfade
    aged = tree.nodes.get(NODE_NAME)
    if aged is None:
        props.original_node = node.name if node is not None else ""
        props.original_output = (bsdf.inputs["Base Color"].links[0].from_socket.identifier
                                 if node is not None else "")
        aged = tree.nodes.new("ShaderNodeTexImage")
        aged.name = aged.label = NODE_NAME
        if node is not None:
            aged.location = (node.location.x, node.location.y - 300)
            aged.interpolation = node.interpolation
            aged.extension = node.extension
            if node.inputs["Vector"].is_linked:
                tree.links.new(node.inputs["Vector"].links[0].from_socket, aged.inputs["Vector"])
        else:
            aged.location = (bsdf.location.x - 400, bsdf.location.y)
    aged.image = image
    tree.links.new(aged.outputs["Color"], bsdf.inputs["Base Color"])


def prepare_material(scene, obj, material, years, progress=None):
    """Prepare aging for one material on one object and show ``years``; returns the image."""
    props = material.lightfade
    bsdf, node, _link = albedo_source(material)
    if node is not None and node.inputs["Vector"].is_linked:
        src = node.inputs["Vector"].links[0].from_node
        if src.type != "UVMAP" or (obj.lightfade.uv_map and src.uv_map not in ("", obj.lightfade.uv_map)):
            raise AgingError(f"Material '{material.name}': the albedo image must use the UV map "
                             f"the exposure was baked on ('{obj.lightfade.uv_map}'), without a "
                             "Mapping node (tiled textures cannot age per texel)")
    maps = [m for m in obj.lightfade.exposure_maps if m.image is not None]
    hint = tuple(maps[0].image.size)[::-1] if maps else (512, 512)
    rgba, source = _albedo_pixels(material, node, bsdf, hint)
    h, w = rgba.shape[:2]
    lights, exposure = lights_and_exposure(scene, obj, (h, w))
    recipe = material_recipe(material)
    max_years = max(100.0, 2.0 * float(years))
    ager = TextureAger(rgba[..., :3], recipe, lights, exposure, max_years=max_years,
                       encoding="linear", progress=progress, store=SceneGridStore(scene))
    image = _aged_image(material, w, h)
    _wire(material, bsdf, node, image)
    props.aged_image = image
    props.aged_object = obj.name
    state = _Aged(ager, image, None)
    state.buffer[:, 3] = rgba[..., 3].reshape(-1)
    _AGED[material.name] = state
    apply_years(material, years, force=True)
    if source is None:
        props.flat_albedo = True
    return image


def _runtime(material, scene):
    """The prepared state of an aged material, rebuilding it after a file load."""
    state = _AGED.get(material.name)
    if state is not None and state.image == material.lightfade.aged_image:
        return state
    obj = scene.objects.get(material.lightfade.aged_object)
    if obj is None:
        return None
    prepare_material(scene, obj, material, scene.lightfade.years)
    return _AGED.get(material.name)


def apply_years(material, years, force=False, scene=None):
    """Write the aged pixels for ``years`` into the material's aged image."""
    state = _AGED.get(material.name)
    if state is None and scene is not None:
        state = _runtime(material, scene)
    if state is None:
        return False
    years = float(years)
    if years > state.ager.max_years and scene is not None:
        obj = scene.objects.get(material.lightfade.aged_object)
        if obj is None:                 # the object is gone: keep the last texture
            return False
        prepare_material(scene, obj, material, years)   # a longer dose axis
        return True
    if not force and state.years == years:
        return False
    state.ager.age(years, out=state.buffer)
    state.image.pixels.foreach_set(state.buffer.ravel())
    state.image.update()
    state.years = years
    return True


def aged_materials(scene):
    """Materials of this scene's objects that LightFade has aged."""
    seen = []
    for obj in scene.objects:
        for slot in obj.material_slots:
            m = slot.material
            if m is not None and m.lightfade.aged_image is not None and m not in seen:
                seen.append(m)
    return seen


def update_scene(scene, years=None):
    """Show ``years`` (default: the scene's slider) on every aged material; seconds taken."""
    t0 = time.perf_counter()
    years = scene.lightfade.years if years is None else years
    for material in aged_materials(scene):
        apply_years(material, years, scene=scene)
    return time.perf_counter() - t0


def reset_material(material):
    """Put the original Base Color link back and remove LightFade's images and node."""
    props = material.lightfade
    tree = material.node_tree
    if tree is not None:
        aged = tree.nodes.get(NODE_NAME)
        bsdf = _principled(material)
        original = tree.nodes.get(props.original_node) if props.original_node else None
        if aged is not None:
            tree.nodes.remove(aged)
        if bsdf is not None and original is not None:
            out = next((s for s in original.outputs if s.identifier == props.original_output),
                       original.outputs["Color"])
            tree.links.new(out, bsdf.inputs["Base Color"])
    image = props.aged_image
    props.aged_image = None
    if image is not None and image.users == 0:
        bpy.data.images.remove(image)
    props.original_node = ""
    props.original_output = ""
    props.aged_object = ""
    props.flat_albedo = False
    _AGED.pop(material.name, None)


def targets(scene, selected):
    """(object, material) pairs to age.

    With meshes selected: every material of theirs (zero configuration: the default
    recipe applies). With nothing selected: the materials with LightFade enabled.
    """
    chosen = [o for o in selected if o.type == "MESH"]
    pairs = []
    for obj in chosen or [o for o in scene.objects if o.type == "MESH"]:
        for slot in obj.material_slots:
            m = slot.material
            if m is not None and (chosen or m.lightfade.enabled) and (obj, m) not in pairs:
                pairs.append((obj, m))
    return pairs


def age_scene(scene, years, selected=(), progress=None, report=None):
    """Prepare and show ``years`` for every target material; returns the images made.

    Raises AgingError for the first material that cannot be aged when nothing can;
    otherwise reports each problem through ``report`` and ages the rest.
    """
    years = float(years)
    if not np.isfinite(years) or years < 0:
        raise AgingError(f"Years must be a number >= 0, got {years!r}")
    pairs = targets(scene, selected)
    if not pairs:
        raise AgingError("Nothing to age: select meshes with materials, or enable LightFade on "
                         "a material (Material Properties > LightFade > Age this Material)")
    done, problems = [], []
    for k, (obj, material) in enumerate(pairs):
        users = users_of(material, scene)
        try:
            if obj.library is not None or obj.data.library is not None:
                raise AgingError(f"Object '{obj.name}' is linked from a library: make it local "
                                 "first")
            if len(users) > 1:
                raise AgingError(
                    f"Material '{material.name}' is used by {len(users)} objects "
                    f"({', '.join(o.name for o in users[:3])}): each lit differently, they need "
                    "their own copies (Object > Relations > Make Single User > Materials)")

            def step(f, msg, k=k, material=material):
                if progress:
                    progress((k + f) / len(pairs), f"{material.name}: {msg}")

            done.append(prepare_material(scene, obj, material, years, step))
        except AgingError as err:
            problems.append(str(err))
    if not done and problems:
        more = f" (and {len(problems) - 1} more problem(s))" if len(problems) > 1 else ""
        raise AgingError(problems[0] + more)
    for problem in problems:
        if report:
            report(problem)
    scene.lightfade.years = years
    scene.render.use_lock_interface = True
    return done
