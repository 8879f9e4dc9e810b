"""Refracting glass made clear to every ray where light can leave only through it:
window panes while the sky is baked, a lamp's closed glass while its group is baked.

Cycles' shadow rays stop at a refracting surface (a Glass or Refraction BSDF, a
Principled BSDF's transmission): through a glass window the sky and the sun reach the
room only by paths that bounce off a texel and happen to refract out through the pane.
Light sampling cannot make such paths, so neither the sky map's importance sampling nor
a portal over the window (:mod:`.portals`) helps there: the bake is as noisy as with
neither (a 2 m room with a 1 × 0.6 m pane: 0.75 of the mean per texel against 0.11 for a
pane that lets shadow rays through; ``tests/blender/test_panes.py``).

While the world or annual daylight is baked, each window's material that refracts
(:func:`refracts`) is therefore shown to Cycles as a Transparent BSDF for *every* ray (a
temporary output, made active, as :mod:`.surface` does; where the pane is itself baked,
the probe's "every other ray" input instead).  Both ways of sampling then see the sky
through it straight and agree, so their weighting stays exact.  Its colour is the pane's
transmittance at normal incidence through its two faces (Fresnel) times the colour that
tints what the shader transmits (:func:`pane_colour`)::

    T = (1 - R)²,     R = ((n - 1) / (n + 1))²       (n = 1.5: T = 0.922)

with ``n`` the shader's IOR and the tint its Color (Base Color for a Principled BSDF),
where unlinked (1.5 and white otherwise: a textured tint is left out).  Left out too:
what the pane reflects (into the room and off it), and the larger loss at grazing angles
(a pane passes 0.92 at 0°, 0.88 at 45°, 0.71 at 60°): light through windows reads a few
per cent high at grazing sun.  A material that already lets shadow rays through
(alpha below 0.5, a Transparent BSDF, the *Is Shadow Ray* trick) is left as it is.

The same holds for a lamp closed in glass (a bulb, a lantern, a closed glass shade):
its light leaves only by refracting, as caustics, which a bake of a few samples all but
misses (:func:`lamp_panes`).  Where every ray from a point, spot or area lamp meets a
surface within :data:`ENCLOSURE` and some of those refract, they are clear panes while
the lamp's group is baked.  An open shade (light leaves through its opening) is left as
it is: Cycles samples the opening, and the glass's own share is counted as a plain bake
counts it.
"""

from __future__ import annotations

import bpy
from mathutils import Vector

from .common import LightFadeBakeError
from .surface import OUTPUT_NAME, PROBE_PREFIX

#: Name (and label prefix) of the temporary nodes.
PANE_PREFIX = "LightFade Clear Pane "
_REFRACTING = {"BSDF_GLASS", "BSDF_REFRACTION"}
#: A lamp is closed in where every ray from it meets a surface this near (m).
ENCLOSURE = 0.5
_DEFAULT_IOR = 1.5


def _transmission(node):
    socket = node.inputs.get("Transmission Weight") or node.inputs.get("Transmission")
    return socket is not None and not socket.is_linked and socket.default_value > 0.5


def _alpha_cut(node):
    socket = node.inputs.get("Alpha")
    return socket is not None and not socket.is_linked and socket.default_value < 0.5


def _upstream(tree):
    """The user's unmuted nodes feeding the surface of the output Cycles uses (through
    the bake's probe, :mod:`.surface`, where the material is baked), and every node
    inside the node groups among them (an asset's glass is often a group)."""
    out = tree.get_output_node("CYCLES")
    todo = [out.inputs["Surface"]] if out is not None else []
    seen = {}
    while todo:
        for link in todo.pop().links:
            node = link.from_node
            if link.is_muted or node.mute or node.as_pointer() in seen:
                continue
            seen[node.as_pointer()] = node
            todo.extend(node.inputs)
    nodes = [n for n in seen.values() if not n.name.startswith(PROBE_PREFIX)]
    return nodes + [inner for n in nodes for inner in _inside(n)]


def _inside(node, depth=0):
    """The unmuted nodes inside a node group (nested groups too), where ``node`` is one."""
    tree = getattr(node, "node_tree", None) if node.type == "GROUP" else None
    if tree is None or depth > 8:
        return []
    nodes = [n for n in tree.nodes if not n.mute]
    return nodes + [inner for n in nodes for inner in _inside(n, depth + 1)]


def lets_light_through(material):
    """Light passes ``material`` (a window's glass): the shader feeding its output
    refracts or is transparent (a Glass, Refraction or Transparent BSDF, a Principled
    BSDF with transmission above 0.5 or alpha below 0.5)."""
    tree = material.node_tree if material is not None else None
    return tree is not None and any(
        n.type in _REFRACTING or n.type == "BSDF_TRANSPARENT" or (
            n.type == "BSDF_PRINCIPLED" and (_transmission(n) or _alpha_cut(n)))
        for n in _upstream(tree))


def refracts(material):
    """The node of ``material`` that refracts where shadow rays stop at it, else None
    (also for a material linked from a library, which LightFade cannot show otherwise)."""
    tree = material.node_tree if material is not None else None
    if tree is None or material.library is not None:
        return None
    nodes = _upstream(tree)
    if any(n.type in {"BSDF_TRANSPARENT", "LIGHT_PATH"} for n in nodes):
        return None                             # already clear to shadow rays
    found = None
    for node in nodes:
        if node.type == "BSDF_PRINCIPLED" and _alpha_cut(node):
            return None
        if node.type in _REFRACTING or (node.type == "BSDF_PRINCIPLED" and _transmission(node)):
            found = node
    return found


def _unlinked(node, name, default):
    socket = node.inputs.get(name)
    return socket.default_value if socket is not None and not socket.is_linked else default


def transmittance(ior):
    """``T = (1 - R)²`` of a pane's two faces at normal incidence (see above)."""
    r = ((ior - 1.0) / (ior + 1.0)) ** 2
    return (1.0 - r) ** 2


def pane_colour(node):
    """The clear pane's RGB: ``T`` from the node's IOR times its colour (a Glass or
    Refraction BSDF's Color, a Principled BSDF's Base Color: what tints the light it
    transmits), both where unlinked (1.5 and white otherwise)."""
    t = transmittance(float(_unlinked(node, "IOR", _DEFAULT_IOR)))
    tint = _unlinked(node, "Base Color" if node.type == "BSDF_PRINCIPLED" else "Color",
                     (1.0, 1.0, 1.0, 1.0))
    return tuple(t * min(max(float(c), 0.0), 1.0) for c in tint[:3])


def window_panes(windows):
    """The distinct refracting materials of ``windows``: ``[(material, rgb)]``."""
    found = {}
    for window in windows:
        obj = bpy.data.objects.get(window.obj)
        slot = next((s for s in obj.material_slots if s.name == window.material), None) \
            if obj is not None else None
        material = slot.material if slot is not None else None
        node = refracts(material)
        if node is not None:
            found[material.as_pointer()] = (material, pane_colour(node))
    return list(found.values())


def clear(state, panes):
    """Show each ``(material, rgb)`` of ``panes`` as a clear pane (undone by ``state``)."""
    for material, rgb in panes:
        _clear(state, material, rgb)


def _clear(state, material, rgb):
    tree = material.node_tree
    clear = tree.nodes.new("ShaderNodeBsdfTransparent")
    clear.name = clear.label = PANE_PREFIX + "BSDF"
    clear.inputs["Color"].default_value = (*rgb, 1.0)
    made = [clear]
    active = [(n, n.is_active_output) for n in tree.nodes
              if n.bl_idname == "ShaderNodeOutputMaterial"]
    probe = tree.nodes.get(OUTPUT_NAME)
    previous = None
    if probe is not None and probe.is_active_output:   # the pane is baked too
        mix = probe.inputs["Surface"].links[0].from_node
        old = mix.inputs[1].links[0] if mix.inputs[1].is_linked else None
        previous = (old.from_socket, old.is_muted) if old is not None else None
        tree.links.new(clear.outputs["BSDF"], mix.inputs[1])
    else:
        out = tree.nodes.new("ShaderNodeOutputMaterial")
        out.name = out.label = PANE_PREFIX + "Output"
        out.target = "CYCLES"
        made.append(out)
        tree.links.new(clear.outputs["BSDF"], out.inputs["Surface"])
        out.is_active_output = True

    def undo():
        for node in made:
            tree.nodes.remove(node)
        if probe is not None and previous is not None:
            mix = probe.inputs["Surface"].links[0].from_node
            tree.links.new(previous[0], mix.inputs[1]).is_muted = previous[1]
        for node, was in active:
            node.is_active_output = was

    state.push(undo)
    if probe is None and tree.get_output_node("CYCLES") != made[-1]:
        raise LightFadeBakeError(
            f"Material \"{material.name}\": Cycles would not use LightFade's clear pane "
            "for the sky's bake; turn Portals over Windows off, or report this with the file")


#: The 26 directions to the faces, edges and corners of a cube (unit vectors): the rays
#: that tell whether a lamp is closed in.
_DIRECTIONS = tuple(Vector((x, y, z)).normalized() for x in (-1, 0, 1) for y in (-1, 0, 1)
                    for z in (-1, 0, 1) if (x, y, z) != (0, 0, 0))


def _enclosing(scene, depsgraph, lamp):
    """The refracting materials around ``lamp``: where every ray from it meets a surface
    within :data:`ENCLOSURE` metres (a bulb, a closed shade, a lantern) and some of them
    refract, those (``[(material, node)]``); else []."""
    origin = lamp.matrix_world.translation
    found = []
    for direction in _DIRECTIONS:
        hit, _loc, _normal, index, obj, _matrix = scene.ray_cast(
            depsgraph, origin, direction, distance=ENCLOSURE)
        if not hit:
            return []                           # light leaves this way: not closed in
        if not obj.material_slots:
            continue
        mesh = obj.evaluated_get(depsgraph).data
        slot = obj.material_slots[min(mesh.polygons[index].material_index,
                                      len(obj.material_slots) - 1)]
        node = refracts(slot.material)
        if node is not None:
            found.append((slot.material, node))
    return found


def lamp_panes(scene, depsgraph, group):
    """Refracting materials that close a lamp of ``group`` in (a glass bulb, a closed
    glass shade): ``{material name: (material, rgb, lamp name)}``.  Light leaves such a
    lamp only by refracting, which light sampling cannot follow: at the default quality
    a lamp in a 6 cm glass sphere lit the floor below at 0.35 of the bare lamp (the raw
    bake at 256 samples at 1.7: caustics), so the glass is a clear pane for its group's
    bake too."""
    out = {}
    for emitter in group.emitters:
        if emitter.kind not in ("POINT", "SPOT", "AREA") or emitter.obj is None:
            continue
        for material, node in _enclosing(scene, depsgraph, emitter.obj):
            out.setdefault(material.name, (material, pane_colour(node), emitter.name))
    return out


def lamps_note(found):
    """One line naming the lamps closed in refracting glass (:func:`lamp_panes` of each
    group), or ''."""
    names = sorted({f'"{lamp}" in "{m.name}"' for panes in found
                    for m, _rgb, lamp in panes.values()})
    if not names:
        return ""
    return (f"Lamp(s) closed in glass that refracts ({', '.join(names)}): their light leaves "
            "only by refracting, which Cycles' shadow rays do not follow; the glass is a clear "
            "pane while their group is baked")


def panes_note(panes):
    """One line for the bake report naming the refracting window panes
    (:func:`window_panes`), or ''."""
    if not panes:
        return ""
    names = ", ".join(sorted(f'"{m.name}"' for m, _rgb in panes))
    t = max(max(rgb) for _m, rgb in panes)
    return (f"Window glass {names} refracts, which Cycles' shadow rays do not pass: shown as "
            f"a clear pane (at most {t:.0%} through) while the sky is baked, so that its "
            "light is sampled through the window")
