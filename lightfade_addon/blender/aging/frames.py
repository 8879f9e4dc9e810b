"""Renders where LightFade is installed read aged images written for the frame.

The aging group costs Cycles far more per shading point than the artist's own
graph (about forty table and map lookups against one image texture). Where LightFade
is installed, a Cycles render does not need it: before each frame (``render_pre``) the
numpy twin writes each aged copy's colour at the frame's years into the copy's
**frame image**, 8-bit sRGB as the artist's textures (:func:`.runtime.aged_rgb`: tens
of ms per Mtexel once the years range is known; nothing when the image holds that
colour already), at the detail the camera resolves (:mod:`.detail`: a texture seen
minified is written as a coarser mipmap level would hold it), and the copy shows a BSDF
fed by that image instead of the live one.

Each copy's tree gets, beside the live BSDF (and its gate), a **frame branch**: a
duplicate of the colour BSDF whose colour is an Image Texture of the frame image in
the copy's exposure UV map (interpolation and extension as the artist's image), and a
Mix Shader (:data:`..source.FRAME_MIX`) choosing between the live shader (factor 0)
and it (factor 1). The factor is a constant, 0 in the file: the handler sets it to 1
for the render (where the copy is aged: years above 0, or a texture with a history),
so Cycles' constant folding removes the live branch from the compiled shader — its
nodes, and the table, exposure maps and artist's colour textures it alone reads are
not even loaded — and the frame costs an image texture where the original read one.
Folding still has to convert and fold the aging group's nodes at every render (about
160 in a copy, 20 ms of CPU per aged material per frame: 0.16 s of a 1.4 s frame of
ten materials), so for the render the copy's aging group node reads a **stub** instead:
a copy of its group with the same sockets and no nodes inside (:mod:`.stub`), put back
when the switch goes off (measured, ten 1k materials at 240 × 135: 1 spp 0.35 → 0.17 s
of CPU, Reset 0.12; 16 spp 1.66 → 1.50, Reset 1.33).

The factors are 1 only between ``render_pre`` and the end of the render
(``render_complete``, ``render_cancel``; an animation keeps them on from frame to
frame) and are never saved so (``save_pre`` sets them to 0, ``save_post`` puts them
back during a render); the frame images are *generated* images (nothing of them is
saved) shrunk to one texel when saved. So a saved file opened anywhere, with or
without LightFade, renders the live material, and the viewport always shows it.
"""

from __future__ import annotations

from dataclasses import dataclass

import bpy
import numpy as np
from bpy.app.handlers import persistent

from . import detail, runtime, stub
from .blocks import Pyramid
from .instances import apply_problem
from ..exposure import exposure_shape
from .copies import _colour_socket, _duplicate, copies_of
from .years import get_years, years_fcurve
from ..source import FRAME_MIX, GATE_MIX

#: Names of the frame branch's nodes (the switch, :data:`..source.FRAME_MIX`, is named
#: there: the colour BSDF is found through its live side).
FRAME_BSDF = "LightFade Frame BSDF"
FRAME_IMAGE = "LightFade Frame Image"
FRAME_UV = "LightFade Frame UV"
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


def add_branch(copy, colour, interpolation="Linear", extension="EXTEND"):
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
    mix.inputs["Fac"].default_value = 0.0                 # live, until a render's handler
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


#: What each frame image holds: image pointer -> :class:`Held`.
_WRITTEN = {}


@dataclass
class Held:
    """What a frame image was written from: the twin's key (:func:`.runtime.twin_key`:
    table, signature, exposure, size, the colour's CRC), the years, the image's size,
    its level (:mod:`.detail`), the samples aged (:mod:`.blocks`) and the colour's
    :func:`.runtime.colour_state` (None: read the colour to compare; where it is known,
    :func:`.runtime.held_colour` holds the colour itself, so the next years value ages
    it without reading the texture again)."""

    key: tuple
    years: float
    size: tuple
    state: tuple | None
    level: int = 0
    texels: int = 0


#: How much coarser than its exposure maps a texture may be and still render from frame
#: images: a 32² texture over 64² maps agrees with the live render
#: (tests/blender/test_frames.py); an 8² one over 64² maps rendered 7 % darker at
#: 25 years (the farm test's floor).
MAX_COARSER = 2


def renders_frames(copy):
    """Whether ``copy`` shows frame images in Cycles renders: not when its object is
    aged per instance (one image cannot hold every instance's tile of the exposure
    atlas: the live group reads each instance's own), nor when its texture is more than
    :data:`MAX_COARSER` times coarser than its exposure maps (the live group ages each
    shading point with the exposure there; a frame texel holds one colour for all the
    exposure texels under it)."""
    if apply_problem(copy) is not None:
        return False
    props = copy.lightfade
    shape = exposure_shape(props.aged_object)
    if props.path == "FLAT" or props.albedo is None or shape is None:
        return True
    width, height = props.albedo.size
    return MAX_COARSER * height >= shape[0] and MAX_COARSER * width >= shape[1]


def write_frame(scene, copy, years, view=None, depsgraph=None):
    """Write ``copy``'s aged colour at ``years`` into its frame image, unless it holds
    exactly that already; returns the image (None without a frame branch).

    The image is the texture's resolution, or coarser by the level of detail the camera
    ``view`` resolves (:func:`.detail.camera_view`; None: full resolution): the
    colour's blocks (held while it is the same), aged as their means or, where a block
    mixes two colours, as its two parts (:mod:`.blocks`).
    "Already" is known without reading the colour where its image is as it was loaded,
    saved or generated (:func:`.runtime.colour_state`); else the colour is read and its
    CRC compared (:func:`.runtime.twin_key`). The aged colour is encoded to the image's
    8-bit sRGB codes as it is evaluated (:func:`..core.colour.srgb8.srgb_code_floats`)."""
    from .apply import ensure_albedo

    nodes = frame_nodes(copy)
    image = nodes[0][1].image if nodes else None
    if image is None or not renders_frames(copy):
        return None
    years = float(years)
    if copy.lightfade.path == "BAKED":
        ensure_albedo(scene, copy)
    L = detail.copy_level(copy, nodes[0][1], view, depsgraph)
    state = runtime.colour_state(copy)
    held = _WRITTEN.get(image.as_pointer())
    same = held is not None and tuple(image.size) == held.size and held.level == L
    if same and state is not None and held.state == state and held.years == years \
            and held.key[:-2] == runtime.inputs_key(scene, copy):
        return image
    colour, key = runtime.held_colour(scene, copy, state)
    layout = None
    if L:
        layout, colour, key = _pyramid(image, colour, key).samples(L)
    if same and held.key == key and held.years == years:
        held.state = state
        return image
    codes = np.empty_like(colour)
    codes[..., 3] = colour[..., 3]
    runtime.aged_rgb(scene, copy, colour, years, key=key, out=codes, codes=True, layout=layout)
    if layout is not None:
        codes = layout.image(codes.reshape(-1, 4))
    H, W = codes.shape[:2]
    if tuple(image.size) != (W, H):
        image.generated_width, image.generated_height = W, H
    image.pixels.foreach_set(codes.reshape(-1))
    image.update()
    image["lightfade_years"] = years
    _WRITTEN[image.as_pointer()] = Held(key, years, (W, H), state, L, colour.size // 4)
    return image


def texels_aged(copy):
    """Texels (or blocks and parts, :mod:`.blocks`) the last write of ``copy``'s frame
    image aged."""
    image = frame_image(copy)
    held = None if image is None else _WRITTEN.get(image.as_pointer())
    return 0 if held is None else held.texels


#: The colours of frame images written coarser than their texture: image pointer ->
#: :class:`.blocks.Pyramid`.
_PYRAMIDS = {}


def _pyramid(image, colour, key):
    """The :class:`.blocks.Pyramid` of ``colour`` (twin key ``key``) for ``image``."""
    held = _PYRAMIDS.get(image.as_pointer())
    if held is None or held.key != key:
        held = _PYRAMIDS[image.as_pointer()] = Pyramid(colour, key)
    return held


def _depsgraph(scene):
    """The scene's evaluated depsgraph: brought up to date on the main thread (a
    script's or ``blender -b``'s render); in an interactive render's own thread, as the
    interface last evaluated it (evaluating there would race the interface); None where
    there is none (then the frame images are written whole)."""
    import threading

    try:
        if threading.current_thread() is threading.main_thread():
            return bpy.context.evaluated_depsgraph_get()
        return scene.view_layers[0].depsgraph
    except (AttributeError, IndexError, RuntimeError):
        return None


def write_frames(scene, years=None, camera=True):
    """Every aged copy of ``scene`` with a frame branch gets its frame image at
    ``years`` (default: the frame's), at the detail the scene's camera resolves
    (``camera`` and the scene's *Frame Detail* ``CAMERA``; else whole); returns
    {copy name: image}."""
    from .apply import aged_copies

    years = frame_years(scene) if years is None else float(years)
    view = depsgraph = None
    if camera and scene.lightfade.frame_detail == "CAMERA":
        depsgraph = _depsgraph(scene)
        view = None if depsgraph is None else detail.camera_view(scene, depsgraph)
    out = {}
    for copy in aged_copies(scene):
        image = write_frame(scene, copy, years, view, depsgraph)
        if image is not None:
            out[copy.name] = image
    return out


def switches(scene=None):
    """``[(copy, Mix Shader)]``: the frame switches of the aged copies (of ``scene``)."""
    from .apply import aged_copies

    copies = aged_copies(scene) if scene is not None else copies_of()
    return [(c, t.nodes[FRAME_MIX]) for c in copies if renders_frames(c)
            for t, _n in frame_nodes(c) if t.nodes.get(FRAME_MIX) is not None]


def _shows(copy, years):
    """Whether ``copy`` shows its frame image at ``years``: above 0 years, or at any
    years for a texture with a history (its 0 years is the restoration); at 0 years
    otherwise the live side, whose gate passes the original pixel for pixel."""
    return years > 0 or runtime.material_prior(copy.lightfade.source) is not None


def _switch(mix, on):
    value = 1.0 if on else 0.0
    if mix.inputs["Fac"].default_value != value:      # an edit recompiles the material
        mix.inputs["Fac"].default_value = value


#: Frame switches turned on by the render in progress: material name -> on.
_RENDERING = {}


#: Engines that render the frame images (EEVEE evaluates the live group at about an
#: image's cost already, and a switch flipped per render would recompile its shaders).
FRAME_ENGINES = ("CYCLES",)


@persistent
def on_render_pre(scene, _more=None):
    found = switches(scene) if scene.render.engine in FRAME_ENGINES else []
    if not found:
        return
    years = frame_years(scene)
    try:
        write_frames(scene, years)
    except Exception as err:                      # the live material renders instead
        print(f"LightFade: this frame renders the live aging ({err})")
        for _copy, mix in found:
            _switch(mix, False)
        return
    for copy, mix in found:
        on = _shows(copy, years)
        _switch(mix, on)
        stub.hold(copy, on)
        _RENDERING[copy.name] = on


@persistent
def on_render_end(_scene=None, _more=None):
    stub.release_all()
    for _copy, mix in switches():
        _switch(mix, False)
    _RENDERING.clear()


@persistent
def on_save_pre(_dummy=None, _more=None):
    stub.release_all()
    for _copy, mix in switches():
        _switch(mix, False)
    for image in bpy.data.images:
        if image.name.startswith(FRAME_PREFIX) and image.source == "GENERATED" \
                and tuple(image.size) != (1, 1):
            image.generated_width = image.generated_height = 1


@persistent
def on_save_post(_dummy=None, _more=None):
    for copy, mix in switches():
        if _RENDERING.get(copy.name):
            _switch(mix, True)
            stub.hold(copy, True)


HANDLERS = (
    ("render_pre", on_render_pre),
    ("render_cancel", on_render_end),
    ("render_complete", on_render_end),
    ("save_pre", on_save_pre),
    ("save_post", on_save_post),
)


def forget():
    """Forget what the frame images hold (file load, unregister)."""
    _WRITTEN.clear()
    stub.forget()
    _PYRAMIDS.clear()


def remove_frame_images(copy):
    for _tree, node in frame_nodes(copy):
        if node.image is not None:
            _WRITTEN.pop(node.image.as_pointer(), None)
            _PYRAMIDS.pop(node.image.as_pointer(), None)
            bpy.data.images.remove(node.image)
            node.image = None

