"""Denoising baked maps with Open Image Denoise, through Blender's compositor.

Blender bundles OIDN; its compositor Denoise node runs headless (``bpy`` module and
``blender -b``) without a camera.  Cycles does not denoise bakes, so each baked map is
put through a compositor tree in a temporary scene::

    Image (baked, HDR) ─┐
    Image (island ids) ─┴─ Denoise (HDR, prefilter None, quality Fast) ─ output

and the result is read back from a temporary EXR.  Where no sample of a small window
found any light (a contact shadow, a closed corner), the denoiser must not invent some:
:func:`guard` caps each denoised texel at the brightest raw texel around it.  OIDN
takes the rare bright paths of bounce-lit shadow for outliers and comes out about 9 %
low there; :func:`preserve_mean` gives each texel back the raw bake's mean over a large
window of texels of similar brightness (unbiased, and precise at that size).  The
*albedo* guide is a flat random colour per UV island (grown over the bake margin): OIDN
keeps edges where the guide changes, so light does not bleed across seams between
islands that lie side by side in UV space.  The guide is noise-free, hence no
prefilter (half the time).
"""

from __future__ import annotations

import contextlib
import os
import tempfile

import bpy
import numpy as np

from ...output import quiet
from .common import TEMP_PREFIX


def island_colours(label):
    """(H, W, 3) guide: a distinct colour in [0.2, 1] per island label, black where -1."""
    rng = np.random.default_rng(12345)
    n = int(label.max()) + 1 if label.size else 0
    palette = rng.uniform(0.2, 1.0, size=(max(n, 1), 3)).astype(np.float32)
    out = np.zeros(label.shape + (3,), dtype=np.float32)
    inside = label >= 0
    out[inside] = palette[label[inside]]
    return out


def max_filter(a, radius):
    """Maximum over a ``(2 radius + 1)²`` window of an (H, W, ...) array (edges clamped).

    ``radius`` passes of a 3-texel maximum along each axis (memory: three copies).
    """
    out = a
    for axis in (0, 1):
        n = out.shape[axis]
        for _ in range(int(radius)):
            padded = np.concatenate([out.take([0], axis), out, out.take([-1], axis)], axis=axis)
            out = np.maximum(np.maximum(padded.take(range(0, n), axis),
                                        padded.take(range(1, n + 1), axis)),
                             padded.take(range(2, n + 2), axis))
    return out


def guard(denoised, raw, radius=4):
    """``denoised`` capped at the local maximum of ``raw`` (and at 0 from below).

    If no path of the 9×9 window around a texel carried light (648 paths at 8 samples),
    its irradiance is ~0 and a denoised value above it is bleed from a bright neighbour
    (a contact shadow next to sunlit floor).  A 5×5 window (200 paths) also zeroed texels
    of shadows that bounce light does reach, where the paths that find light are rare:
    measured, +50 % noise there (8.5 % against 5.7 %) and a point of bias.
    """
    return np.clip(denoised, 0.0, max_filter(raw, radius))


#: the most :func:`preserve_mean` raises (or 1/it lowers) a window's denoised sum
MEAN_GAIN = 4.0


def preserve_mean(denoised, raw, inside, radius=48, block=4, floor=1e-4, parts=None):
    """``denoised`` (H, W) rescaled so that its local mean matches the raw bake's.

    OIDN underestimates where light arrives as rare bright paths (a shadow that only
    bounce light reaches: about −10 % at 8 samples), since it takes them for outliers.
    The raw bake is unbiased, and its mean over a large window is precise, so each
    texel is scaled by ``Σ raw / Σ denoised`` over a (2·radius+1)² window of texels of
    similar brightness inside the UV islands: brightness bands one stop wide (log2 of
    the denoised value; a texel belongs to the two bands around it with hat weights),
    so that a shadow is corrected by shadow texels only and its edges stay as sharp as
    the denoiser made them.  The sums are taken per ``block``² tile (a tile's texels
    share the factor of their bands: a smooth field).  The factor is held within
    [1/:data:`MEAN_GAIN`, :data:`MEAN_GAIN`] = [0.25, 4]: where light arrives by rare
    bright paths the denoiser takes the brightest for outliers and a window's raw sum can
    be several times its denoised one; a clip at 2 threw that light away (the lampshade
    room's poster under a frosted-glass pendant, 128 samples: −1.3 % with the clip at
    [0.5, 2], −0.0 % without, its raw mean +0.7 %; docs/bake.md), while no clip at all
    let a band the denoiser had all but emptied multiply its few texels without bound
    (bpy 4.2's OIDN: a chair half under a table read 658 lux against 515 for one in the
    sun; at 4 it reads below it, and the pendant's worst floor, rug or poster is 1.55 %).
    A map shared by several objects (an atlas of small ones, an instanced source's
    tiles) is corrected cell by cell (``parts``): a window never mixes two objects, whose
    denoiser losses differ (the same poster in its atlas beside the rug: −3.7 %).

    Parameters
    ----------
    denoised, raw : ndarray, shape (H, W)
        Irradiance (any unit), denoised and as baked.
    inside : ndarray of bool, shape (H, W)
        Texels inside the UV islands (grown over the margin).
    parts : iterable of (row slice, column slice), optional
        Cells of the map corrected each on its own (texels outside them are left as
        denoised).
    """
    from scipy.ndimage import uniform_filter

    if parts is not None:
        out = np.array(denoised, dtype=np.float32)
        for cell in parts:
            out[cell] = preserve_mean(out[cell], np.asarray(raw)[cell],
                                      np.asarray(inside)[cell], radius, block, floor)
        return out
    den = np.asarray(denoised, dtype=np.float32)
    h, w = den.shape
    top = float(den[inside].max()) if inside.any() else 0.0
    if top <= 0.0:
        return den.copy()
    # each texel's band (two neighbours, hat weights) and tile
    position = np.log2(np.maximum(den, np.float32(top * floor)) / np.float32(top))   # <= 0
    lowest = np.floor(position.min())
    band = np.floor(position - lowest).astype(np.int64)
    upper = (position - lowest - band).astype(np.float64)
    bands = int(band.max()) + 2
    rows, cols = -(-h // block), -(-w // block)
    tile = ((np.arange(h) // block)[:, None] * cols + np.arange(w) // block).ravel()
    low_bin = (band.ravel() * (rows * cols) + tile)
    high_bin = low_bin + rows * cols
    keep = inside.ravel()

    def window_sums(values):
        v = values.ravel().astype(np.float64) * keep
        sums = (np.bincount(low_bin, v * (1.0 - upper.ravel()), bands * rows * cols)
                + np.bincount(high_bin, v * upper.ravel(), bands * rows * cols))
        size = (1, 2 * (radius // block) + 1, 2 * (radius // block) + 1)
        return uniform_filter(sums.reshape(bands, rows, cols), size, mode="constant").ravel()

    a, b = window_sums(raw), window_sums(den)
    ratio = np.ones_like(b)
    np.divide(a, b, out=ratio, where=b > 0)
    ratio[b > 0] = np.clip(ratio[b > 0], 1.0 / MEAN_GAIN, MEAN_GAIN)
    factor = ratio[low_bin] * (1.0 - upper.ravel()) + ratio[high_bin] * upper.ravel()
    return den * np.where(keep, factor, 1.0).reshape(h, w).astype(np.float32)


def _image(name, rgb):
    h, w = rgb.shape[:2]
    img = bpy.data.images.new(TEMP_PREFIX + name, w, h, alpha=False, float_buffer=True)
    img.colorspace_settings.is_data = True
    px = np.ones((h, w, 4), dtype=np.float32)
    px[..., :3] = rgb
    img.pixels.foreach_set(px.ravel())
    return img


def _set(node, name, value, prop, prop_value):
    """Set a Denoise option: an input socket from 4.5/5.0 on, a node property before."""
    if name in node.inputs:
        node.inputs[name].default_value = value
    elif hasattr(node, prop):
        setattr(node, prop, prop_value)


def _tree(scene):
    """A compositor tree of ``scene`` and its output node (5.0 changed the API)."""
    if bpy.app.version >= (5, 0, 0):  # 5.0: node-group compositor, Group Output
        tree = bpy.data.node_groups.new(TEMP_PREFIX + "Denoise", "CompositorNodeTree")
        scene.compositing_node_group = tree
        tree.interface.new_socket("Image", in_out="OUTPUT", socket_type="NodeSocketColor")
        return tree, tree.nodes.new("NodeGroupOutput")
    scene.use_nodes = True  # 4.2-4.5: the scene's own tree, Composite node
    tree = scene.node_tree
    tree.nodes.clear()
    return tree, tree.nodes.new("CompositorNodeComposite")


@contextlib.contextmanager
def _temporary_scene(width, height):
    scene = bpy.data.scenes.new(TEMP_PREFIX + "Denoise")
    made_result = "Render Result" not in bpy.data.images
    tree = None
    try:
        scene.render.resolution_x, scene.render.resolution_y = width, height
        scene.render.resolution_percentage = 100
        scene.render.image_settings.file_format = "OPEN_EXR"
        scene.render.image_settings.color_depth = "32"
        # A new scene's compositor runs on the GPU from 5.0 on; headless, making its
        # context fails (three "EGL Error (0x3009): EGL_BAD_MATCH" lines on stderr) before
        # it falls back to the CPU.  OIDN gives the same result on the CPU, at once.
        if hasattr(scene.render, "compositor_device"):
            scene.render.compositor_device = "CPU"
        tree, out = _tree(scene)
        yield scene, tree, out
    finally:
        if bpy.app.version >= (5, 0, 0) and tree is not None:
            bpy.data.node_groups.remove(tree)
        bpy.data.scenes.remove(scene)
        result = bpy.data.images.get("Render Result")
        if made_result and result is not None:
            bpy.data.images.remove(result)


def denoise(rgb, guide=None):
    """Denoise an (H, W, 3) float map with OIDN; ``guide`` is an optional (H, W, 3) albedo.

    Returns the denoised (H, W, 3) float32 array.
    """
    h, w = rgb.shape[:2]
    images = []
    fd, path = tempfile.mkstemp(prefix="lightfade_denoise_", suffix=".exr")
    os.close(fd)
    try:
        with _temporary_scene(w, h) as (scene, tree, out):
            source = tree.nodes.new("CompositorNodeImage")
            source.image = _image("noisy", rgb)
            images.append(source.image)
            node = tree.nodes.new("CompositorNodeDenoise")
            _set(node, "HDR", True, "use_hdr", True)
            _set(node, "Prefilter", "None", "prefilter", "NONE")
            _set(node, "Quality", "Fast", "quality", "FAST")
            tree.links.new(source.outputs["Image"], node.inputs["Image"])
            if guide is not None:
                albedo = tree.nodes.new("CompositorNodeImage")
                albedo.image = _image("guide", guide)
                images.append(albedo.image)
                tree.links.new(albedo.outputs["Image"], node.inputs["Albedo"])
            tree.links.new(node.outputs["Image"], out.inputs[0])
            with quiet("render"):     # 4.x: a status line per compositor operation
                bpy.ops.render.render(scene=scene.name)
            bpy.data.images["Render Result"].save_render(path, scene=scene)
        result = bpy.data.images.load(path)
        images.append(result)
        result.colorspace_settings.is_data = True
        px = np.empty(w * h * 4, dtype=np.float32)
        result.pixels.foreach_get(px)
        return px.reshape(h, w, 4)[..., :3].copy()
    finally:
        for img in images:
            with contextlib.suppress(ReferenceError):
                bpy.data.images.remove(img)
        with contextlib.suppress(OSError):
            os.remove(path)
