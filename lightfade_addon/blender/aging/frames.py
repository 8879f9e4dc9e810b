"""Renders where LightFade is installed read aged images written for the frame.

The aging group costs Cycles far more per shading point than the artist's own
graph (about forty table and map lookups against one image texture). Where LightFade
is installed, a render does not need it: before each frame (``render_pre``) the
numpy twin writes each aged copy's colour at the frame's years into the copy's
**frame image**, 8-bit sRGB as the artist's textures (:func:`.runtime.aged_rgb`: tens
of ms per Mtexel once the years range is known; nothing when the image holds that
colour already), and the copy shows a BSDF fed by that image instead of the live one.

Each copy's tree gets, beside the live BSDF (and its gate), a **frame branch**: a
duplicate of the colour BSDF whose colour is an Image Texture of the frame image in
the copy's exposure UV map (interpolation and extension as the artist's image), and a
Mix Shader (:data:`FRAME_MIX`) choosing between the live shader (factor 0) and it
(factor 1). Its factor is the scene's custom property :data:`FRAME_PROP` (an
Attribute node, View Layer) times, where 0 years is the original, ``years > 0``.
Cycles compiles a Mix Shader's two closures behind jumps, so at a factor of exactly 0
or 1 the other branch and every node only it uses are skipped: the frame renders at
the price of an image texture, the live material at the live price.

:data:`FRAME_PROP` is 1 only between ``render_pre`` and the end of the render
(``render_post``, ``render_cancel``, ``render_complete``) and is never saved set
(``save_pre`` clears it, ``save_post`` puts it back during a render); the frame images
are *generated* images (nothing of them is saved) shrunk to one texel when saved.
So a saved file opened anywhere, with or without LightFade, renders the live
material, and the viewport always shows it.
"""

from __future__ import annotations

import bpy
from bpy.app.handlers import persistent

from . import runtime
from ..pixels import encode_srgb
from .copies import GATE_AGED, _colour_socket, _duplicate, copies_of
from .years import YEARS_PROP, get_years, years_fcurve
from ..source import FRAME_MIX, GATE_MIX

#: The scene's custom property that switches aged copies to their frame images.
FRAME_PROP = "lightfade_frame_images"
#: Names of the frame branch's nodes (the switch, :data:`..source.FRAME_MIX`, is named
#: there: the colour BSDF is found through its live side).
FRAME_BSDF = "LightFade Frame BSDF"
FRAME_IMAGE = "LightFade Frame Image"
FRAME_UV = "LightFade Frame UV"
FRAME_FAC = "LightFade Frame On"
FRAME_AGED = "LightFade Frame Years"
#: Prefix of the frame images.
FRAME_PREFIX = "LF_Frame_"


def frame_nodes(copy):
    """``[(tree, image node)]`` of the copy's frame branch (none before Age made it)."""
    from .copies import walk

    return [(t, n) for t, n in walk(copy.node_tree) if n.name == FRAME_IMAGE]


def frame_image(copy):
    nodes = frame_nodes(copy)
    return nodes[0][1].image if nodes else None


def _new_image(copy):
    """An 8-bit sRGB generated image, as the artist's textures are: the frame reads as
    many bytes as the original does (a float image: four times as many)."""
    image = bpy.data.images.new(FRAME_PREFIX + copy.name, 1, 1, alpha=True, float_buffer=False)
    image.colorspace_settings.name = "sRGB"
    return image


def _factor(tree, zero_years, at):
    """``FRAME_PROP`` (× ``years > 0`` with ``zero_years``): exactly 0 or 1."""
    x, y = at
    on = tree.nodes.new("ShaderNodeAttribute")
    on.name = on.label = FRAME_FAC
    on.attribute_type, on.attribute_name = "VIEW_LAYER", FRAME_PROP
    on.location = (x, y + 600)
    if not zero_years:
        return on.outputs["Fac"]
    aged = tree.nodes.get(GATE_AGED)
    if aged is None:
        years = tree.nodes.new("ShaderNodeAttribute")
        years.name = years.label = FRAME_AGED
        years.attribute_type, years.attribute_name = "VIEW_LAYER", YEARS_PROP
        years.location = (x, y + 750)
        aged = tree.nodes.new("ShaderNodeMath")
        aged.name = aged.label = FRAME_AGED + " Above Zero"
        aged.operation = "GREATER_THAN"
        aged.location = (x + 150, y + 750)
        tree.links.new(years.outputs["Fac"], aged.inputs[0])
        aged.inputs[1].default_value = 0.0
    both = tree.nodes.new("ShaderNodeMath")
    both.name = both.label = FRAME_FAC + " And Aged"
    both.operation = "MULTIPLY"
    both.location = (x + 300, y + 650)
    tree.links.new(on.outputs["Fac"], both.inputs[0])
    tree.links.new(aged.outputs[0], both.inputs[1])
    return both.outputs[0]


def add_branch(copy, colour, interpolation="Linear", extension="EXTEND", zero_years=True):
    """Give ``copy`` its frame branch (see the module docstring) at the BSDF of
    ``colour``; returns the switch's Mix Shader (None where the BSDF reaches no output).
    Idempotent."""
    tree, socket = _colour_socket(copy, colour)
    if tree.nodes.get(FRAME_MIX) is not None:
        return tree.nodes[FRAME_MIX]
    bsdf = tree.nodes[colour.node]
    live = tree.nodes.get(GATE_MIX) or bsdf
    shaders = [(out, list(out.links)) for out in live.outputs if out.type == "SHADER"]
    if not any(links for _o, links in shaders):
        return None
    x, y = live.location
    used = shaders[0][0] if live == bsdf else next(      # the BSDF's output in use
        o for o in bsdf.outputs if o.type == "SHADER" and o.links)
    frame = _duplicate(tree, bsdf)
    frame.name = frame.label = FRAME_BSDF
    frame.location = (bsdf.location.x, bsdf.location.y - 700)
    image = tree.nodes.new("ShaderNodeTexImage")
    image.name = image.label = FRAME_IMAGE
    image.image = _new_image(copy)
    image.interpolation, image.extension = interpolation, extension
    image.location = (frame.location.x - 300, frame.location.y)
    uv = tree.nodes.new("ShaderNodeUVMap")
    uv.name = uv.label = FRAME_UV
    uv.uv_map = copy.lightfade.uv_map
    uv.location = (image.location.x - 200, image.location.y)
    tree.links.new(uv.outputs["UV"], image.inputs["Vector"])
    tree.links.new(image.outputs["Color"], frame.inputs[list(bsdf.inputs).index(socket)])
    mix = tree.nodes.new("ShaderNodeMixShader")
    mix.name = mix.label = FRAME_MIX
    mix.location = (x + 250, y)
    tree.links.new(_factor(tree, zero_years, (x, y)), mix.inputs["Fac"])
    for out, links in shaders:
        for link in links:
            tree.links.new(mix.outputs[0], link.to_socket)
    tree.links.new(shaders[0][0], mix.inputs[1])                           # Fac 0: live
    tree.links.new(frame.outputs[used.identifier], mix.inputs[2])         # Fac 1: frame
    return mix


# ----------------------------------------------------------------------- per frame


def frame_years(scene):
    """The years of the frame being rendered: the keyed F-curve at the scene's frame
    (the render's frame is set on the scene; its animation is evaluated on the
    render's own copy), else the scene's years."""
    curve = years_fcurve(scene)
    if curve is not None:
        return max(0.0, float(curve.evaluate(scene.frame_current + scene.frame_subframe)))
    return get_years(scene)


#: What each frame image holds: image pointer -> (twin key, years, size).
_WRITTEN = {}


def write_frame(scene, copy, years):
    """Write ``copy``'s aged colour at ``years`` into its frame image (at the texture's
    resolution), unless it holds exactly that already; returns the image (None
    without a frame branch)."""
    from .apply import original_pixels

    image = frame_image(copy)
    if image is None:
        return None
    rgba = original_pixels(scene, copy)
    H, W = rgba.shape[:2]
    key = runtime.twin_key(scene, copy, rgba)
    held = (key, float(years), (W, H))
    if tuple(image.size) == (W, H) and _WRITTEN.get(image.as_pointer()) == held:
        return image
    runtime.aged_rgb(scene, copy, rgba, years, key=key)
    if tuple(image.size) != (W, H):
        image.generated_width, image.generated_height = W, H
    rgba[..., :3] = encode_srgb(rgba[..., :3])
    image.pixels.foreach_set(rgba.reshape(-1))
    image.update()
    image["lightfade_years"] = float(years)
    _WRITTEN[image.as_pointer()] = held
    return image


def write_frames(scene, years=None):
    """Every aged copy of ``scene`` with a frame branch gets its frame image at
    ``years`` (default: the frame's); returns {copy name: image}."""
    from .apply import aged_copies

    years = frame_years(scene) if years is None else float(years)
    out = {}
    for copy in aged_copies(scene):
        image = write_frame(scene, copy, years)
        if image is not None:
            out[copy.name] = image
    return out


def _set(scene, on):
    if on:
        scene[FRAME_PROP] = 1.0
    elif scene.get(FRAME_PROP):
        scene[FRAME_PROP] = 0.0


#: Scenes switched to their frame images by the render in progress.
_RENDERING = set()


@persistent
def on_render_pre(scene, _more=None):
    if not any(frame_nodes(c) for c in copies_of()):
        return
    try:
        write_frames(scene)
    except Exception as err:                      # the live material renders instead
        print(f"LightFade: this frame renders the live aging ({err})")
        _set(scene, False)
        return
    _set(scene, True)
    _RENDERING.add(scene.name)


@persistent
def on_render_end(scene, _more=None):
    _set(scene, False)
    _RENDERING.discard(scene.name)


@persistent
def on_save_pre(_dummy=None, _more=None):
    for scene in bpy.data.scenes:
        _set(scene, False)
    for image in bpy.data.images:
        if image.name.startswith(FRAME_PREFIX) and image.source == "GENERATED" \
                and tuple(image.size) != (1, 1):
            image.generated_width = image.generated_height = 1


@persistent
def on_save_post(_dummy=None, _more=None):
    for name in _RENDERING:
        scene = bpy.data.scenes.get(name)
        if scene is not None:
            _set(scene, True)


HANDLERS = (
    ("render_pre", on_render_pre),
    ("render_post", on_render_end),
    ("render_cancel", on_render_end),
    ("render_complete", on_render_end),
    ("save_pre", on_save_pre),
    ("save_post", on_save_post),
)


def forget():
    """Forget what the frame images hold (file load, unregister)."""
    _WRITTEN.clear()


def remove_frame_images(copy):
    for _tree, node in frame_nodes(copy):
        if node.image is not None:
            _WRITTEN.pop(node.image.as_pointer(), None)
            bpy.data.images.remove(node.image)
            node.image = None

