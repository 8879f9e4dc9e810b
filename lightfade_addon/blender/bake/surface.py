"""The baked surface as an irradiance meter: a Lambertian for the bake, the real
material for every other ray.

Cycles' DIFFUSE bake without colour divides the diffuse light a closure reflects by the
closure's diffuse colour.  That is the irradiance only for plain diffuse closures: a
Principled BSDF's sheen and subsurface reflect by their own laws, so with them the
quotient follows the surface's own colour and finish (sheen 0.6 on a black/white checker:
squares 38 % apart, the mean 19 % low), and a black texel (diffuse colour 0) bakes as 0.

For the bake, each baked material therefore gets a second, temporary Material Output
(target Cycles, made active) fed by::

    Mix Shader(Fac = Light Path "Is Camera Ray",
               0: the material's own Surface,  1: Diffuse BSDF, the probe)

Cycles starts every bake sample at the texel as a camera ray (``path_state_init_integrator``
sets ``PATH_RAY_CAMERA`` for camera and bake paths alike), so the texel is shaded as the
probe, a Lambertian whose DIFFUSE pass (its colour divided out) is the irradiance
whatever the material; every ray after the
first bounce (light the object reflects onto itself, other targets seen from a texel)
sees the material as it is.  A Mix Shader with a factor of exactly 0 or 1 evaluates only
that input, so nothing of the real surface leaks into the texel.  The output's other
inputs (Volume, Displacement, Thickness) are fed as before, so displacement and bump
through the Displacement output shape the probe too; where the shader feeding the
output has a linked Normal input (a Principled BSDF with a normal or bump map), the
probe takes that normal as well.  Emission of the baked
surface is not part of the DIFFUSE pass, so an emissive target does not count its own
light; emission of other emitters is handled by :func:`.emitters.isolate`.

The probe's colour is the surface's own diffuse colour (a Principled BSDF's Base Color,
a Diffuse BSDF's Color, linked or not), at least :data:`PROBE_FLOOR`; white where another
shader feeds the output.  The pass does not depend on it, Cycles' Russian roulette does:
it lets a path go on with probability √(throughput), so after a white texel paths ran
13 % longer than in a plain bake of the same surface (``docs/bake.md``).

Nothing of the user's graph is touched: no link is cut, no value set; the only change is
which output node is active, put back with the nodes removed on exit.
"""

from __future__ import annotations

from .common import LightFadeBakeError

#: Name (and label) of the temporary output node; also marks a material already set up.
OUTPUT_NAME = "LightFade Exposure Output"
PROBE_PREFIX = "LightFade Exposure "

#: The probe: (name, node type, settings), then links (from node, output, to node, input).
_NODES = (
    ("Ray", "ShaderNodeLightPath", {}),
    ("Probe", "ShaderNodeBsdfDiffuse", {"Color": (1.0, 1.0, 1.0, 1.0), "Roughness": 0.0}),
    ("Mix", "ShaderNodeMixShader", {}),
)
_LINKS = (
    ("Ray", "Is Camera Ray", "Mix", 0),
    ("Probe", "BSDF", "Mix", 2),
)


#: The probe's colour: the surface's own diffuse colour, at least this (Russian roulette
#: then ends paths as in a plain bake; the pass divides the colour out again).
PROBE_FLOOR = 0.25
#: Where a shader keeps its diffuse colour.
_BASE_COLOUR = {"ShaderNodeBsdfPrincipled": "Base Color", "ShaderNodeBsdfDiffuse": "Color"}


def _outputs(tree):
    return [n for n in tree.nodes if n.bl_idname == "ShaderNodeOutputMaterial"]


def _relink(tree, socket, to_socket):
    """Link what feeds ``socket`` into ``to_socket`` as well (muted if that link is);
    returns the source socket."""
    link = socket.links[0]
    tree.links.new(link.from_socket, to_socket).is_muted = link.is_muted
    return link.from_socket


def _colour_probe(tree, shader, made):
    """Give the probe the surface's own diffuse colour, at least :data:`PROBE_FLOOR`."""
    name = _BASE_COLOUR.get(shader.bl_idname)
    socket = shader.inputs.get(name) if name else None
    if socket is None:
        return
    probe = made["Probe"].inputs["Color"]
    if not socket.is_linked:
        probe.default_value = [max(float(v), PROBE_FLOOR) for v in socket.default_value[:3]] + [1.0]
        return
    floor = made["Floor"] = tree.nodes.new("ShaderNodeVectorMath")
    floor.name = floor.label = PROBE_PREFIX + "Floor"
    floor.operation = "MAXIMUM"
    floor.inputs[1].default_value = (PROBE_FLOOR,) * 3
    _relink(tree, socket, floor.inputs[0])
    tree.links.new(floor.outputs["Vector"], probe)


def expose_surface(state, material):
    """Make ``material`` read as the probe at the baked texels only; undone on exit.

    Parameters
    ----------
    state : .state.BakeState
        Records the undo steps.
    material : bpy.types.Material
        A local, node-based material of a baked object (library materials are copied by
        :func:`.targets.attach_targets` first).

    Raises
    ------
    LightFadeBakeError
        When Cycles would not use the temporary output (names the material).
    """
    tree = material.node_tree
    if tree.nodes.get(OUTPUT_NAME) is not None:  # a temporary copy of a prepared material
        return
    active = [(n, n.is_active_output) for n in _outputs(tree)]  # before Blender tidies them
    real = tree.get_output_node("CYCLES")
    made = {}
    for name, idname, inputs in _NODES:
        node = tree.nodes.new(idname)
        node.name = node.label = PROBE_PREFIX + name
        for key, value in inputs.items():
            node.inputs[key].default_value = value
        made[name] = node
    out = made["Output"] = tree.nodes.new("ShaderNodeOutputMaterial")
    out.name = out.label = OUTPUT_NAME

    def undo():
        for node in made.values():
            tree.nodes.remove(node)
        for node, was in active:
            node.is_active_output = was

    state.push(undo)
    for a, socket, b, index in _LINKS:
        tree.links.new(made[a].outputs[socket], made[b].inputs[index])
    tree.links.new(made["Mix"].outputs["Shader"], out.inputs["Surface"])
    if real is not None:
        surface = real.inputs["Surface"]
        if surface.is_linked:
            source = _relink(tree, surface, made["Mix"].inputs[1])
            normal = source.node.inputs.get("Normal")
            if normal is not None and normal.is_linked:  # a BSDF's normal or bump map
                _relink(tree, normal, made["Probe"].inputs["Normal"])
            _colour_probe(tree, source.node, made)
        for socket in real.inputs:
            if socket.identifier == "Surface" or socket.identifier not in out.inputs:
                continue
            twin = out.inputs[socket.identifier]
            if socket.is_linked:
                _relink(tree, socket, twin)
            elif hasattr(socket, "default_value"):
                twin.default_value = socket.default_value
    out.target = "CYCLES"
    out.is_active_output = True
    if tree.get_output_node("CYCLES") != out:
        raise LightFadeBakeError(
            f"Material \"{material.name}\": Cycles would not use LightFade's temporary output "
            "for the exposure bake; report this with the file")
