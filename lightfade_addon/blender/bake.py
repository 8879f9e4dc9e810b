"""Exposure bake: per-texel illuminance (lux) from each emitter, with Cycles.

For every target mesh and every emitter of the scene (lamp, world, emissive mesh) one
float image is baked, so that each emitter keeps its own spectrum and schedule.  Each
emitter is isolated in turn (other lamps hidden from render, world removed, other
emission strengths set to 0), the target gets a temporary diffuse material whose active
Image Texture node points at the map, and Cycles bakes the DIFFUSE pass with DIRECT and
INDIRECT light and no COLOR: the irradiance the texel receives, with real occlusion and
inter-reflection from the rest of the scene.  :class:`BakeState` restores every setting
it changed, also when the bake fails.

Calibration (measured with Blender 5.0.1, Cycles CPU; pinned by
``tests/blender/test_bake.py``)
-----------------------------------------------------------------------------------------
Cycles' diffuse bake without colour returns ``B = E / pi``, where ``E`` is the irradiance
in Blender's nominal radiometric units (W/m²).  The maps store::

    lux = 683 lm/W * pi * B          (LUX_PER_BAKE_UNIT = 683 pi = 2145.7)

Measured ``B`` for each emitter (plane facing the emitter, white or not: COLOR is divided
out):

============================  ==============================  =======================
emitter                        measured B                     illuminance (lux)
============================  ==============================  =======================
sun, strength S, angle θ       S cosθ / pi  (0.31830 for S=1)  683 S cosθ
point, power P, distance r     P / (4 pi² r²) (±0.02 %)        683 P / (4 pi r²)
spot, power P (on axis)        P / (4 pi² r²)  as a point      683 P / (4 pi r²)
area, power P (small, axis)    P / (pi² r²)                    683 P / (pi r²)
world, background strength W   W (open hemisphere)             683 pi W
emission strength L (plane)    L (infinite emitting plane)     683 pi L
============================  ==============================  =======================

So a point lamp's "watts" are its radiant flux over the full sphere (``I = P / 4pi``
W/sr); a spot lamp keeps the point lamp's intensity inside its cone (its cone does not
concentrate the power); an area lamp's watts leave one side as a Lambertian emitter
(``I0 = P / pi``); world strength and emission strength are radiances (W/m²/sr).
"""

from __future__ import annotations

import contextlib
import math
import time
from dataclasses import dataclass

import bpy
import numpy as np

__all__ = [
    "LUX_PER_WATT",
    "LUX_PER_BAKE_UNIT",
    "BakeSettings",
    "BakeState",
    "Emitter",
    "LightFadeBakeError",
    "bake_exposure",
    "find_emitters",
    "find_targets",
    "exposure_image_name",
]

#: Luminous efficacy assumed for Blender's nominal radiometric watts (lm/W).
LUX_PER_WATT = 683.0
#: Lux per unit of Cycles' DIFFUSE (no colour) bake value: ``683 * pi``.
LUX_PER_BAKE_UNIT = LUX_PER_WATT * math.pi

WORLD_EMITTER = "World"
_TEMP_PREFIX = "LF_TMP_"


class LightFadeBakeError(RuntimeError):
    """A bake that cannot start; the message names the object and what to fix."""


@dataclass
class BakeSettings:
    """Bake parameters (defaults match ``Scene.lightfade``).

    Attributes
    ----------
    resolution : int
        Width and height of each map, px.
    samples : int
        Cycles samples per texel.
    margin : int
        Bake margin, px.
    unwrap : bool
        Smart UV Project meshes that have no UV map (otherwise they are skipped).
    """

    resolution: int = 1024
    samples: int = 64
    margin: int = 16
    unwrap: bool = False

    @classmethod
    def from_scene(cls, scene, unwrap=False):
        props = scene.lightfade
        return cls(props.bake_resolution, props.bake_samples, props.bake_margin, unwrap)


@dataclass
class Emitter:
    """A source of light to bake one map for.

    ``name`` is the light object's name, ``"World"``, or the emissive object's name.
    """

    name: str
    kind: str  # SUN POINT SPOT AREA WORLD EMISSIVE
    obj: object = None  # bpy.types.Object, None for the world


def exposure_image_name(obj_name, emitter_name):
    """Name of the image holding ``obj_name``'s exposure to ``emitter_name``."""
    return f"LF_Exposure_{obj_name}_{emitter_name}"


# ----------------------------------------------------------------------- scene queries


def _emission_sockets(material):
    """(node, input) pairs whose value makes ``material`` emit; linked inputs count as on."""
    if material is None or material.node_tree is None:
        return []
    found = []
    for node in material.node_tree.nodes:
        if node.mute:
            continue
        if node.type == "EMISSION":
            strength, color = node.inputs["Strength"], node.inputs["Color"]
        elif node.type == "BSDF_PRINCIPLED":
            strength, color = node.inputs["Emission Strength"], node.inputs["Emission Color"]
        else:
            continue
        on_strength = strength.is_linked or strength.default_value > 0.0
        on_color = color.is_linked or max(color.default_value[:3]) > 0.0
        if on_strength and on_color:
            found.append((node, strength))
    return found


def _is_emissive_mesh(obj):
    return obj.type == "MESH" and any(
        _emission_sockets(slot.material) for slot in obj.material_slots
    )


def _world_emits(world):
    if world is None or world.node_tree is None:
        return False
    for node in world.node_tree.nodes:
        if node.type == "BACKGROUND" and not node.mute:
            s, c = node.inputs["Strength"], node.inputs["Color"]
            if (s.is_linked or s.default_value > 0) and (c.is_linked or max(c.default_value[:3]) > 0):
                return True
    return False


def _renders(obj, view_layer):
    return not obj.hide_render and obj.name in view_layer.objects


def find_emitters(scene, view_layer=None):
    """The emitters of ``scene`` that take part in aging.

    Lamps with non-zero power, visible to render and with ``Light.lightfade.enabled``;
    the world if its background emits and ``World.lightfade.enabled``; meshes with an
    emissive material and ``Object.lightfade_emitter.enabled``.

    Returns
    -------
    list of Emitter
    """
    view_layer = view_layer or scene.view_layers[0]
    emitters = []
    for obj in scene.objects:
        if not _renders(obj, view_layer):
            continue
        if obj.type == "LIGHT":
            light = obj.data
            if light.lightfade.enabled and light.energy > 0.0 and max(light.color) > 0.0:
                emitters.append(Emitter(obj.name, light.type, obj))
        elif obj.type == "MESH" and obj.lightfade_emitter.enabled and _is_emissive_mesh(obj):
            emitters.append(Emitter(obj.name, "EMISSIVE", obj))
    world = scene.world
    if world is not None and world.lightfade.enabled and _world_emits(world):
        emitters.append(Emitter(WORLD_EMITTER, "WORLD", None))
    return emitters


def _is_linked(obj):
    return any(
        idb is not None and (idb.library is not None or idb.override_library is not None)
        for idb in (obj, obj.data)
    )


def find_targets(scene, selected=None):
    """Objects to bake: the selected ones, else every mesh using an enabled material."""
    if selected:
        return list(selected)
    return [
        obj for obj in scene.objects
        if obj.type == "MESH"
        and any(s.material is not None and s.material.lightfade.enabled for s in obj.material_slots)
    ]


# ----------------------------------------------------------------------- state handling


def _snapshot_rna(struct, names):
    return {n: getattr(struct, n) for n in names if hasattr(struct, n)}


def _restore_rna(struct, values):
    for name, value in values.items():
        try:
            setattr(struct, name, value)
        except (AttributeError, TypeError, ValueError):
            pass


_RENDER_KEYS = ("engine",)
_BAKE_KEYS = ("margin", "margin_type", "use_clear", "use_selected_to_active", "target",
              "use_pass_direct", "use_pass_indirect", "use_pass_color", "use_cage",
              "cage_extrusion", "max_ray_distance", "normal_space", "save_mode")
_CYCLES_KEYS = ("device", "samples", "use_adaptive_sampling", "use_denoising", "bake_type",
                "time_limit", "seed", "use_animated_seed")


class BakeState(contextlib.AbstractContextManager):
    """Everything the bake changes, put back on exit (normal, error or cancel).

    Covers render engine, Cycles and bake settings, the world, lamp ``hide_render``,
    emission strengths (and their links) of emissive materials, the material slots of
    the targets (and slots it appended), the view layer's material override, selection,
    active object and object hide state, and it deletes the temporary materials and images
    it made.
    """

    def __init__(self, scene, view_layer):
        self.scene = scene
        self.view_layer = view_layer
        self._undo = []  # callables, run in reverse on exit
        self.temp_materials = []
        self.temp_images = []

    # -- registration of changes
    def push(self, fn):
        self._undo.append(fn)

    def set(self, struct, name, value):
        """``setattr(struct, name, value)``, remembering the old value."""
        old = getattr(struct, name)
        setattr(struct, name, value)
        self.push(lambda: setattr(struct, name, old))

    def __enter__(self):
        scene, vl = self.scene, self.view_layer
        render = _snapshot_rna(scene.render, _RENDER_KEYS)
        bake = _snapshot_rna(scene.render.bake, _BAKE_KEYS)
        world = scene.world
        self.push(lambda: _restore_rna(scene.render, render))
        self.push(lambda: _restore_rna(scene.render.bake, bake))
        self.push(lambda: setattr(scene, "world", world))
        scene.render.engine = "CYCLES"  # creates scene.cycles settings if missing
        cycles = _snapshot_rna(scene.cycles, _CYCLES_KEYS)
        self.push(lambda: _restore_rna(scene.cycles, cycles))
        override = vl.material_override
        self.push(lambda: setattr(vl, "material_override", override))
        vl.material_override = None
        active = vl.objects.active
        selected = [o for o in vl.objects if o.select_get()]

        def restore_selection():
            for o in vl.objects:
                o.select_set(False)
            for o in selected:
                with contextlib.suppress(ReferenceError, RuntimeError):
                    o.select_set(True)
            with contextlib.suppress(ReferenceError):
                vl.objects.active = active

        self.push(restore_selection)
        return self

    def __exit__(self, exc_type, exc, tb):
        errors = []
        for fn in reversed(self._undo):
            try:
                fn()
            except Exception as err:  # keep restoring the rest
                errors.append(err)
        self._undo.clear()
        for mat in self.temp_materials:
            with contextlib.suppress(ReferenceError):
                bpy.data.materials.remove(mat)
        for img in self.temp_images:
            with contextlib.suppress(ReferenceError):
                bpy.data.images.remove(img)
        self.temp_materials.clear()
        self.temp_images.clear()
        if errors and exc_type is None:
            raise errors[0]
        return False

    # -- helpers used by the bake
    def silence_emission(self, obj):
        """Set every emission strength of ``obj``'s materials to 0 (links cut), restored on exit."""
        for slot in obj.material_slots:
            for node, socket in _emission_sockets(slot.material):
                tree = slot.material.node_tree
                for link in list(socket.links):
                    from_socket, to_socket = link.from_socket, link.to_socket
                    tree.links.remove(link)
                    self.push(lambda t=tree, a=from_socket, b=to_socket: t.links.new(a, b))
                self.set(socket, "default_value", 0.0)

    def temp_material(self, name, albedo, image):
        """A diffuse material with an active Image Texture node on ``image``."""
        mat = bpy.data.materials.new(_TEMP_PREFIX + name)
        self.temp_materials.append(mat)
        if bpy.app.version < (5, 0, 0):
            mat.use_nodes = True
        tree = mat.node_tree
        tree.nodes.clear()
        out = tree.nodes.new("ShaderNodeOutputMaterial")
        bsdf = tree.nodes.new("ShaderNodeBsdfDiffuse")
        bsdf.inputs["Color"].default_value = (*albedo, 1.0)
        tree.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
        tex = tree.nodes.new("ShaderNodeTexImage")
        tex.image = image
        tree.nodes.active = tex
        return mat


def _albedo_estimate(material):
    """Mean reflectance of ``material`` for inter-reflection from the target onto itself.

    The DIFFUSE bake without COLOR divides the albedo out, so this only matters for light
    bouncing off the target back onto itself (concave objects): the Principled Base Color
    if it is a constant, else 0.5 grey.
    """
    if material is not None and material.node_tree is not None:
        for node in material.node_tree.nodes:
            if node.type == "BSDF_PRINCIPLED":
                sock = node.inputs["Base Color"]
                if not sock.is_linked:
                    return tuple(sock.default_value[:3])
                break
    return (0.5, 0.5, 0.5)


# ----------------------------------------------------------------------- the bake


def _validate_targets(objects, unwrap, warn):
    """Split ``objects`` into bakeable meshes; raise on linked data."""
    targets = []
    for obj in objects:
        if obj.type != "MESH":
            warn(f"Skipped \"{obj.name}\": not a mesh ({obj.type.lower()}); only meshes get exposure maps")
            continue
        if _is_linked(obj):
            raise LightFadeBakeError(
                f"\"{obj.name}\" is linked from a library: make local first (Object > Relations > Make Local)"
            )
        if not obj.data.uv_layers:
            if not unwrap:
                warn(f"Skipped \"{obj.name}\": it has no UV map; unwrap it (U) or bake with Unwrap enabled")
                continue
        if len(obj.data.polygons) == 0:
            warn(f"Skipped \"{obj.name}\": mesh has no faces")
            continue
        targets.append(obj)
    return targets


def _smart_unwrap(obj, view_layer):
    """Smart UV Project ``obj`` (it had no UV map)."""
    for o in view_layer.objects:
        o.select_set(False)
    obj.select_set(True)
    view_layer.objects.active = obj
    obj.data.uv_layers.new(name="LightFadeUV")
    bpy.ops.object.mode_set(mode="EDIT")
    try:
        bpy.ops.mesh.select_all(action="SELECT")
        bpy.ops.uv.smart_project(island_margin=0.01)
    finally:
        bpy.ops.object.mode_set(mode="OBJECT")


def _new_map_image(name, size):
    img = bpy.data.images.new(_TEMP_PREFIX + name, size, size, alpha=False, float_buffer=True)
    img.colorspace_settings.is_data = True  # lux, not colour: no view transform
    return img


def _store_map(obj, emitter, baked, final_name, uv_name):
    """Scale ``baked`` from bake units to lux, name and pack it, record it on ``obj``.

    A re-bake replaces the previous ``LF_Exposure_*`` image everywhere it is used
    (``ID.user_remap``: node trees and properties pointing at it follow) and removes it.
    """
    pixels = np.empty(len(baked.pixels), dtype=np.float32)
    baked.pixels.foreach_get(pixels)
    pixels = pixels.reshape(-1, 4)
    pixels[:, :3] *= LUX_PER_BAKE_UNIT
    pixels[:, 3] = 1.0
    baked.pixels.foreach_set(pixels.ravel())
    bake_id = 1
    old = bpy.data.images.get(final_name)
    if old is not None and old is not baked and old.library is None:
        bake_id = int(old.get("lightfade_bake_id", 0)) + 1
        old.user_remap(baked)
        bpy.data.images.remove(old)
    baked.name = final_name
    baked.file_format = "OPEN_EXR"
    baked["lightfade_bake_id"] = bake_id
    baked.update()
    baked.pack()
    maps = obj.lightfade.exposure_maps
    item = maps.get(emitter.name)
    if item is None:
        item = maps.add()
        item.name = emitter.name
    item.emitter = emitter.name
    item.emitter_kind = emitter.kind
    item.image = baked
    obj.lightfade.uv_map = uv_name
    return baked


def _isolate(state, scene, emitters, current):
    """Make ``current`` the only emitter that shines."""
    for em in emitters:
        if em is current:
            continue
        if em.kind == "WORLD":
            state.set(scene, "world", None)
        elif em.kind == "EMISSIVE":
            state.silence_emission(em.obj)
        else:
            state.set(em.obj, "hide_render", True)
    if current.kind != "WORLD":
        state.set(scene, "world", None)


def bake_exposure(context_or_scene, objects, settings=None, report=None, progress=None):
    """Bake one illuminance map (lux) per (mesh, emitter) pair.

    Parameters
    ----------
    context_or_scene : bpy.types.Context or bpy.types.Scene
        Where to bake; with a scene, its first view layer is used.
    objects : iterable of bpy.types.Object or None
        Objects to bake; empty or None: every mesh using a material with LightFade
        enabled.
    settings : BakeSettings, optional
        Default: :meth:`BakeSettings.from_scene`.
    report : callable(str), optional
        Receives warnings (skipped objects); default: print.
    progress : callable(done, total, text), optional
        Called before each (object, emitter) bake.

    Returns
    -------
    dict
        ``{"maps": {object_name: {emitter_name: bpy.types.Image}}, "skipped": [messages],
        "emitters": [(name, kind)], "seconds": float}``.  Image pixels are lux (R=G=B).

    Raises
    ------
    LightFadeBakeError
        Nothing to bake, no emitters, or linked library data.
    """
    if isinstance(context_or_scene, bpy.types.Scene):
        scene = context_or_scene
        view_layer = scene.view_layers[0]
        if bpy.context.scene == scene:
            view_layer = bpy.context.view_layer
    else:
        scene = context_or_scene.scene
        view_layer = context_or_scene.view_layer
    settings = settings or BakeSettings.from_scene(scene)
    view_layer.update()  # objects linked by scripts join view_layer.objects on update
    skipped = []

    def warn(msg):
        skipped.append(msg)
        (report or print)(msg)

    objects = list(objects or [])
    if not objects:
        objects = find_targets(scene)
        if not objects:
            raise LightFadeBakeError(
                "Nothing to bake: select mesh objects, or enable LightFade on their materials "
                "(Material Properties > LightFade)"
            )
    targets = _validate_targets(objects, settings.unwrap, warn)
    if not targets:
        raise LightFadeBakeError("Nothing to bake: " + "; ".join(skipped))
    emitters = find_emitters(scene, view_layer)
    if not emitters:
        raise LightFadeBakeError(
            "No emitters in the scene: add a lamp, an emissive mesh or a world with non-zero strength "
            "(and keep their LightFade 'Include in Aging' on)"
        )
    if bpy.context.mode != "OBJECT" and bpy.context.object is not None:
        bpy.ops.object.mode_set(mode="OBJECT")

    result = {"maps": {}, "skipped": skipped, "emitters": [(e.name, e.kind) for e in emitters]}
    start = time.perf_counter()
    total = len(targets) * len(emitters)
    done = 0
    with BakeState(scene, view_layer) as state:
        cycles = scene.cycles
        cycles.device = "CPU"
        cycles.samples = settings.samples
        cycles.use_adaptive_sampling = False
        cycles.use_denoising = False
        cycles.time_limit = 0.0
        bake = scene.render.bake
        bake.margin = settings.margin
        bake.margin_type = "EXTEND"
        bake.use_clear = True
        bake.use_selected_to_active = False
        bake.target = "IMAGE_TEXTURES"
        bake.use_pass_direct, bake.use_pass_indirect, bake.use_pass_color = True, True, False

        for obj in targets:
            state.set(obj, "hide_render", False)
            if obj.hide_get(view_layer=view_layer):
                obj.hide_set(False, view_layer=view_layer)
                state.push(lambda o=obj: o.hide_set(True, view_layer=view_layer))
            if not obj.data.uv_layers:
                _smart_unwrap(obj, view_layer)
            uv_name = obj.data.uv_layers.active.name
            result["maps"][obj.name] = {}
            for emitter in emitters:
                if emitter.obj is obj:
                    continue  # an emissive object's own light: not exposure of itself
                done += 1
                if progress is not None:
                    progress(done, total, f"{obj.name} <- {emitter.name}")
                print(f"LightFade: baking {obj.name} <- {emitter.name} ({emitter.kind.lower()}) "
                      f"[{done}/{total}]", flush=True)
                _bake_pair(state, scene, view_layer, obj, emitter, emitters, settings, uv_name,
                           result["maps"][obj.name])
    result["seconds"] = time.perf_counter() - start
    return result


def _cycles_bake(settings, uv_name):
    """Bake the DIFFUSE pass (direct + indirect, no colour) of the selected object."""
    return bpy.ops.object.bake(
        type="DIFFUSE",
        pass_filter={"DIRECT", "INDIRECT"},
        margin=settings.margin,
        margin_type="EXTEND",
        use_clear=True,
        target="IMAGE_TEXTURES",
        save_mode="INTERNAL",
        uv_layer=uv_name,
    )


def _bake_pair(state, scene, view_layer, obj, emitter, emitters, settings, uv_name, out):
    """Bake ``obj``'s exposure to ``emitter`` inside its own nested restore scope."""
    final_name = exposure_image_name(obj.name, emitter.name)
    image = _new_map_image(final_name, settings.resolution)
    state.temp_images.append(image)  # until stored
    with BakeState(scene, view_layer) as inner:
        _isolate(inner, scene, emitters, emitter)
        slots = obj.material_slots
        if len(slots) == 0:
            obj.data.materials.append(None)
            inner.push(lambda: obj.data.materials.pop(index=len(obj.data.materials) - 1))
        for i, slot in enumerate(obj.material_slots):
            mat = inner.temp_material(f"{obj.name}_{i}", _albedo_estimate(slot.material), image)
            old = slot.material
            slot.material = mat
            inner.push(lambda s=slot, m=old: setattr(s, "material", m))
        for o in view_layer.objects:
            if o.select_get():
                o.select_set(False)
        obj.select_set(True)
        view_layer.objects.active = obj
        ret = _cycles_bake(settings, uv_name)
        if "FINISHED" not in ret:
            raise LightFadeBakeError(f"Cycles bake of \"{obj.name}\" for \"{emitter.name}\" failed")
    out[emitter.name] = _store_map(obj, emitter, image, final_name, uv_name)
    state.temp_images.remove(image)  # it is the map now
