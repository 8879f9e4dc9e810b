"""Which objects get exposure maps, and how Cycles is told where to write them.

Each target is baked in its own real materials: LightFade adds an Image Texture node
(made active: Cycles bakes into the active image node of each material) and a temporary
output that shows the baked texels as a Lambertian probe (:mod:`.surface`: the map is the light
arriving, whatever the material's colour or finish), and removes both afterwards; every
other ray sees the real materials, so the light the object bounces onto itself is what its
materials really reflect.  Where one material serves several targets of the same Cycles
call, each further object gets a temporary copy through an object-linked slot (Blender's
``slot.link = 'OBJECT'``), so every object writes into its own map; so does a material
linked from a library (or overridden from one), which is never edited.
"""

from __future__ import annotations

import bpy

from .common import TEMP_PREFIX, LightFadeBakeError
from .surface import expose_surface

NODE_NAME = "LightFade Exposure Target"


def _is_linked(obj):
    return any(idb is not None and (idb.library is not None or idb.override_library is not None)
               for idb in (obj, obj.data))


def find_targets(scene, selected=None):
    """Objects to bake: the selected ones, else every mesh using an enabled material."""
    if selected:
        return list(selected)
    return [obj for obj in scene.objects
            if obj.type == "MESH" and any(s.material is not None and s.material.lightfade.enabled
                                          for s in obj.material_slots)]


def validate_targets(objects, unwrap, instanced=()):
    """Split ``objects`` into bakeable meshes, warnings (skipped) and problems (refusals).
    ``instanced``: local objects baked through a stand-in (:mod:`.stand_in`), whose mesh
    is only read and so may be a library's (:mod:`.linked`).

    Returns ``(targets, warnings, problems)``; every message names the object.
    """
    targets, warnings, problems = [], [], []
    for obj in objects:
        if obj.type != "MESH":
            warnings.append(f"Skipped \"{obj.name}\": not a mesh ({obj.type.lower()}); only "
                            "meshes get exposure maps")
        elif _is_linked(obj) and not (obj in instanced and obj.library is None
                                      and obj.override_library is None):
            problems.append(f"\"{obj.name}\" is linked from a library: make local first "
                            "(Object > Relations > Make Local)")
        elif len(obj.data.polygons) == 0 and not obj.modifiers:  # modifiers may make faces
            warnings.append(f"Skipped \"{obj.name}\": mesh has no faces")
        elif not obj.data.uv_layers and not unwrap:
            warnings.append(f"Skipped \"{obj.name}\": it has no UV map; unwrap it (U) or bake "
                            "with Unwrap enabled")
        else:
            targets.append(obj)
    return targets, warnings, problems


def _stand_in(state, colour):
    """A default-looking material for empty slots (Cycles' default surface is this)."""
    mat = bpy.data.materials.new(TEMP_PREFIX + "Default")
    state.temp_materials.append(mat)
    if bpy.app.version < (5, 0, 0):  # 5.0 made every material node-based
        mat.use_nodes = True
    mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (*colour, 1.0)
    return mat


def _own_copy(state, obj, slot_index, material):
    """Give ``obj`` a private copy of ``material`` in slot ``slot_index`` (object-linked)."""
    copy = material.copy()
    copy.name = TEMP_PREFIX + material.name
    state.temp_materials.append(copy)
    slot = obj.material_slots[slot_index]
    state.set(slot, "link", "OBJECT")
    state.set(slot, "material", copy)
    return copy


def _add_target_node(state, material):
    """Add an active Image Texture node to ``material``; removed (and the active node
    restored) on exit.  Returns the node."""
    tree = material.node_tree
    previous = tree.nodes.active
    node = tree.nodes.new("ShaderNodeTexImage")
    node.name = node.label = NODE_NAME
    tree.nodes.active = node

    def undo():
        tree.nodes.remove(node)
        if previous is not None:
            tree.nodes.active = previous

    state.push(undo)
    return node


def attach_targets(state, objects):
    """One target node per material slot of each object: ``{object name: [nodes]}``.

    Set ``node.image`` on an object's nodes before each Cycles call.
    """
    owner = {}  # material name -> object whose map its target node writes into
    nodes = {}
    for obj in objects:
        if len(obj.material_slots) == 0:
            obj.data.materials.append(None)
            state.push(lambda o=obj: o.data.materials.pop(index=len(o.data.materials) - 1))
        nodes[obj.name] = []
        for i, slot in enumerate(obj.material_slots):
            mat = slot.material
            if mat is None or mat.node_tree is None or (
                    bpy.app.version < (5, 0, 0) and not mat.use_nodes):
                colour = tuple(mat.diffuse_color[:3]) if mat is not None else (0.8, 0.8, 0.8)
                state.set(slot, "link", "OBJECT")
                state.set(slot, "material", _stand_in(state, colour))
                mat = slot.material
            elif (mat.library is not None or mat.override_library is not None
                  or owner.get(mat.name, obj.name) != obj.name):
                mat = _own_copy(state, obj, i, mat)
            if owner.setdefault(mat.name, obj.name) == obj.name and not any(
                    n.id_data == mat.node_tree for n in nodes[obj.name]):
                expose_surface(state, mat)
                nodes[obj.name].append(_add_target_node(state, mat))
    return nodes


def check_bake_result(ret, objects, group):
    if "FINISHED" not in ret:
        names = ", ".join(f"\"{o.name}\"" for o in objects)
        raise LightFadeBakeError(f"Cycles bake of {names} for \"{group.name}\" failed")
