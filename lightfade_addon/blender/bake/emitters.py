"""Emitters of a scene and their light groups.

An emitter is a lamp, the world, or a mesh with an emissive material whose owner opted in
(*Count Emission as Light*; glazing, screens and glTF emission are not lamps by default,
and their emission is off while baking).  Emitters with the
same spectrum, UV filter and schedule form one light group and are baked into one map:
their doses add linearly (reciprocity), so one map per group carries all the information
aging needs.

A Cycles **light portal** (an Area light with *Portal* on) is not an emitter: it emits
nothing, it only shows Cycles where the world's light comes in through a window. It
stays in the scene while the world or annual daylight is baked (there it lowers the
noise of light through windows) and is hidden in every other group's bake, which has
no world to guide.
"""

from __future__ import annotations

import contextlib
from dataclasses import dataclass, field

from ..vocabulary import resolve_spectrum
from . import daylight as _daylight
from .common import WORLD_EMITTER


@dataclass
class Emitter:
    """A source of light: a light object, ``"World"``, or an emissive mesh."""

    name: str
    kind: str  # SUN POINT SPOT AREA WORLD EMISSIVE DAYLIGHT
    obj: object = None  # bpy.types.Object, None for the world


@dataclass
class LightGroup:
    """Emitters sharing spectrum, UV filter and schedule: one exposure map per object."""

    name: str
    key: tuple
    emitters: list = field(default_factory=list)

    @property
    def member_names(self):
        return [e.name for e in self.emitters]


# ----------------------------------------------------------------------- emission tests


def emission_sockets(material):
    """(node, strength input) pairs that make ``material`` emit; linked inputs count as on."""
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
        if _on(strength, color):
            found.append((node, strength))
    return found


def _on(strength, color):
    return ((strength.is_linked or strength.default_value > 0.0)
            and (color.is_linked or max(color.default_value[:3]) > 0.0))


def is_portal(obj):
    """An Area light with Cycles' *Portal* on (it guides world light, emits none)."""
    light = obj.data if obj.type == "LIGHT" else None
    return light is not None and light.type == "AREA" and bool(
        getattr(getattr(light, "cycles", None), "is_portal", False))


def _is_emissive_mesh(obj):
    return obj.type == "MESH" and any(emission_sockets(s.material) for s in obj.material_slots)


def uncounted_emissive(scene, view_layer=None):
    """Meshes whose materials emit but that are not counted as lamps: ``[(object,
    [material names])]`` (visible to render; *Count Emission as Light* off)."""
    view_layer = view_layer or scene.view_layers[0]
    found = []
    for obj in scene.objects:
        if obj.type != "MESH" or obj.hide_render or obj.name not in view_layer.objects \
                or obj.lightfade_emitter.enabled:
            continue
        names = [s.material.name for s in obj.material_slots if emission_sockets(s.material)]
        if names:
            found.append((obj, list(dict.fromkeys(names))))
    return found


def uncounted_note(found, limit=3):
    """One line naming the uncounted emissive meshes (at most ``limit``) and how to count
    them, or ``""``."""
    if not found:
        return ""
    names = ", ".join(f"\"{obj.name}\" ({', '.join(mats)})" for obj, mats in found[:limit])
    more = f" and {len(found) - limit} more" if len(found) > limit else ""
    return (f"Emissive, not counted as lamps (emission off while baking): {names}{more}; "
            "to count one, select it and tick LightFade > Light Schedule > "
            "Count Emission as Light")


def world_emits(world):
    """The world's Background shader gives light."""
    if world is None or world.node_tree is None:
        return False
    return any(node.type == "BACKGROUND" and not node.mute
               and _on(node.inputs["Strength"], node.inputs["Color"])
               for node in world.node_tree.nodes)


def world_counts(world):
    """The world takes part in aging only when the user gave it a spectrum (not Auto).

    Blender's default grey world would otherwise count as daylight through glass.
    """
    return (world is not None and world.lightfade.enabled and world.lightfade.spectrum != "AUTO"
            and world_emits(world))


# ----------------------------------------------------------------------- queries


def find_emitters(scene, view_layer=None):
    """The emitters of ``scene`` that take part in aging.

    Lamps with non-zero power, visible to render and with ``Light.lightfade.enabled``;
    meshes with an emissive material and ``Object.lightfade_emitter.enabled`` (off by
    default: an emissive material is not a lamp unless the user says so,
    :func:`uncounted_emissive`); the world
    when :func:`world_counts`.  With annual daylight (:mod:`.daylight`), the sun lamps and
    the world standing for daylight give way to one ``"Daylight"`` emitter.

    Returns
    -------
    list of Emitter
    """
    view_layer = view_layer or scene.view_layers[0]
    emitters = []
    for obj in scene.objects:
        if obj.hide_render or obj.name not in view_layer.objects:
            continue
        if obj.type == "LIGHT":
            light = obj.data
            if is_portal(obj):
                continue
            if light.lightfade.enabled and light.energy > 0.0 and max(light.color) > 0.0 \
                    and not _daylight.stands_for_daylight(scene, light.lightfade, light.type):
                emitters.append(Emitter(obj.name, light.type, obj))
        elif obj.type == "MESH" and obj.lightfade_emitter.enabled and _is_emissive_mesh(obj):
            emitters.append(Emitter(obj.name, "EMISSIVE", obj))
    if world_counts(scene.world) and not _daylight.stands_for_daylight(
            scene, scene.world.lightfade, "WORLD"):
        emitters.append(Emitter(WORLD_EMITTER, "WORLD", None))
    daylight = _daylight.daylight_emitter(scene)
    if daylight is not None:
        emitters.append(Emitter(*daylight, None))
    return emitters


#: ``(scene, {name: object}, {key: value})`` while :func:`remembered` is open, else None.
_REMEMBERED = None


@contextlib.contextmanager
def remembered(scene):
    """Within: :func:`schedule_of` finds ``scene``'s emitters in one dict built once, and
    :func:`memo` gives a dict for answers that hold meanwhile (a years change asks every
    aged copy for its maps' emitters and schedules: the same few, a thousand times).

    ``scene.objects.get`` walks the scene's objects, so it cost O(objects) per copy:
    92 ms of a 100 ms years change at 1000 aged objects."""
    global _REMEMBERED
    saved = _REMEMBERED
    _REMEMBERED = (scene, {obj.name: obj for obj in scene.objects}, {})
    try:
        yield
    finally:
        _REMEMBERED = saved


def memo(scene):
    """The dict of answers kept while :func:`remembered` is open on ``scene``, or None."""
    return _REMEMBERED[2] if _REMEMBERED is not None and _REMEMBERED[0] == scene else None


def schedule_of(scene, name, kind):
    """The ``LIGHTFADE_PG_schedule`` of an emitter, or None if it is gone (the daylight
    group's: ``Scene.lightfade_daylight``, enabled while annual daylight is active)."""
    if kind == "DAYLIGHT":
        return scene.lightfade_daylight
    if kind == "WORLD":
        return scene.world.lightfade if scene.world is not None else None
    known = _REMEMBERED[1] if _REMEMBERED is not None and _REMEMBERED[0] == scene else None
    obj = known.get(name) if known is not None else scene.objects.get(name)
    if obj is None:
        return None
    if kind == "EMISSIVE":
        return obj.lightfade_emitter if obj.type == "MESH" else None
    return obj.data.lightfade if obj.type == "LIGHT" else None


def schedule_key(schedule, kind):
    """What must match for emitters to share a map: ``(spectrum id, UV filter, h/day, d/yr)``."""
    return (resolve_spectrum(schedule, kind), bool(schedule.uv_filter),
            round(float(schedule.hours_per_day), 6), round(float(schedule.days_per_year), 6))


def group_name(names):
    """``"Sun"`` for one emitter, ``"Sun +2"`` for Sun and two more."""
    names = sorted(names)
    return names[0] if len(names) == 1 else f"{names[0]} +{len(names) - 1}"


def group_emitters(scene, emitters):
    """Light groups of ``emitters``, in the order of their first member."""
    groups = {}
    for em in emitters:
        key = schedule_key(schedule_of(scene, em.name, em.kind), em.kind)
        groups.setdefault(key, []).append(em)
    return [LightGroup(group_name([e.name for e in members]), key, members)
            for key, members in groups.items()]


def find_groups(scene, view_layer=None):
    """:func:`group_emitters` of :func:`find_emitters`."""
    return group_emitters(scene, find_emitters(scene, view_layer))


# ----------------------------------------------------------------------- isolation


def silence_emission(state, obj):
    """Set every emission strength of ``obj``'s materials to 0 (links cut); undone on exit."""
    for slot in obj.material_slots:
        for _node, socket in emission_sockets(slot.material):
            tree = slot.material.node_tree
            for link in list(socket.links):
                from_socket, to_socket = link.from_socket, link.to_socket
                tree.links.remove(link)
                state.push(lambda t=tree, a=from_socket, b=to_socket: t.links.new(a, b))
            state.set(socket, "default_value", 0.0)


def bakes_sky(group):
    """``group`` bakes the world or annual daylight: light through windows, where a
    portal guides Cycles."""
    return any(e.kind in ("DAYLIGHT", "WORLD") for e in group.emitters)


def isolate(state, scene, group):
    """Let only ``group``'s emitters shine (other lamps hidden, emission off, no world; the
    daylight group: the annual sky as the world)."""
    members = {e.name for e in group.emitters}
    sky = bakes_sky(group)
    if any(e.kind == "DAYLIGHT" for e in group.emitters):
        _daylight.use_annual_world(state, scene)
    elif not sky:
        state.set(scene, "world", None)
    for obj in scene.objects:  # also what LightFade ignores (disabled) must stay dark
        if obj.name in members or obj.hide_render or (sky and is_portal(obj)):
            continue
        if obj.type == "LIGHT":
            state.set(obj, "hide_render", True)
        elif _is_emissive_mesh(obj):
            silence_emission(state, obj)
