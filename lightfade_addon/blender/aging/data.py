"""The aging's data in the file: one shared table image per recipe and light set.

An aged copy's node group (:mod:`.group`) reads two kinds of images, and nothing
Age writes per texel:

``LF_Table_<key>``  float RGBA, Non-Color, half precision: the colour table
    (:func:`..core.colourtable.atlas_pixels`) of one recipe (with its sensitivity and
    history) under one set of light spectra, shared by every copy using them; what it
    is in its custom property ``lightfade_table`` (:meth:`..core.colourtable.ColourTable.info`).
the object's exposure maps  (``LF_Exposure_*``, made by the bake): lux per light group,
    read directly, so a re-bake (which remaps the old images onto the new) reaches every
    view at once.

The numpy evaluator (:func:`..core.colourtable.evaluate`) reads the same table back
(:func:`read_table`) and the same maps (:func:`rates`), so both evaluators share them.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from contextlib import contextmanager
from dataclasses import dataclass

import bpy
import numpy as np

from ...core.aging.colourtable import atlas_pixels, table_from_atlas
from ...core.fading.lights import spectra_keys
from ...core.aging.tablebuild import TableSettings, build_tables, load_or_build, table_key
from ..errors import AgingError
from ..exposure import exposure_images
from ..pixels import read_rgba, resample, write_rgba
from .group import EVAL_PREFIX

TABLE_PREFIX = "LF_Table_"
#: Images of older versions (per-copy keys, rates, restored textures), removed on Age/Reset.
OLD_PREFIXES = ("LF_Key_", "LF_Rate_", "LF_New_")
PREFIXES = (TABLE_PREFIX, *OLD_PREFIXES)
#: Custom property of the table image: the table's shape and axes.
TABLE_INFO = "lightfade_table"
#: Light spectra one table (one aged material) mixes.
MAX_SPECTRA = 4
#: The table every preparation builds (the tests of bookkeeping patch in a coarser one).
TABLE_SETTINGS = TableSettings()
#: Tables built ahead (:func:`tables_built`), by key, for :func:`ensure_table`.
_BUILT = {}


@dataclass(frozen=True)
class MapInput:
    """One exposure map as the group reads it: lux image, its table spectrum, lux·h a year
    per lux (hours a day × days a year)."""

    image: object
    spectrum: int
    hours: float


def map_inputs(scene, obj):
    """``(inputs, spectra keys)``: the object's counted exposure maps and the distinct
    (spectrum, UV filter) pairs they are lit by, in table order."""
    maps = exposure_images(scene, obj)
    keys = spectra_keys([light for _image, light in maps])
    if len(keys) > MAX_SPECTRA:
        raise AgingError(f"Object '{obj.name}' is lit by {len(keys)} light spectra; at most "
                         f"{MAX_SPECTRA} can age one material: give some lamps the same Spectrum")
    inputs = [MapInput(image, keys.index((light.spectrum, light.uv_filter)),
                       float(light.hours_per_day * light.days_per_year)) for image, light in maps]
    return inputs, keys


def find_table(key):
    """The table image of ``key`` in the file, or None."""
    image = bpy.data.images.get(TABLE_PREFIX + key[:16])
    if image is not None and image.get(TABLE_INFO, {}).get("key") == key:
        return image
    return None


def ensure_table(recipe, keys, prior=None, progress=None, restore_kw=None):
    """The table image of ``recipe`` under spectra ``keys`` (with history ``prior``):
    found in the file, else built ahead (:func:`tables_built`), loaded from the disk
    cache or built, and written."""
    key = table_key(recipe, keys, TABLE_SETTINGS, prior)
    image = find_table(key)
    if image is not None:
        return image, None
    table = _BUILT.get(key) if prior is None else None
    if table is None:
        table = load_or_build(recipe, keys, TABLE_SETTINGS, prior, progress,
                              restore_kw=restore_kw)
    image = _half_exr(TABLE_PREFIX + key[:16], atlas_pixels(table))
    image[TABLE_INFO] = table.info()
    return image, table


@contextmanager
def tables_built(requests, progress=None):
    """Within the block, :func:`ensure_table` finds the tables of ``requests``
    (``(recipe, spectra keys)``, no history) that the file lacked ready: built together
    (:func:`..core.aging.tablebuild.build_tables`, several at a time), or read from the
    disk cache. Forgotten on leaving."""
    missing = [(recipe, keys) for recipe, keys in requests
               if find_table(table_key(recipe, keys, TABLE_SETTINGS)) is None]
    built = build_tables(missing, TABLE_SETTINGS, progress) if missing else {}
    _BUILT.update(built)
    try:
        yield len(built)
    finally:
        for key in built:
            _BUILT.pop(key, None)


def _half_exr(name, rgba):
    """A packed image holding ``rgba`` (H, W, 4) as a half-float, PXR24-compressed OpenEXR.

    Blender packs a generated float image as full-float EXR (16 bytes a texel); the
    table's values are half precision already, so the file is written as half floats
    (8 bytes a texel before compression) and that file is packed. PXR24 is lossless on
    half floats and packs a two-spectrum table 6 % smaller than ZIP (2.55 MB against
    2.70 MB; PIZ 3.76, ZIPS 3.46, RLE 4.93).
    """
    H, W = rgba.shape[:2]
    tmp = bpy.data.images.new(name + "_tmp", W, H, alpha=True, float_buffer=True)
    folder = tempfile.mkdtemp(prefix="lightfade_")
    path = os.path.join(folder, "table.exr")
    try:
        tmp.colorspace_settings.name = "Non-Color"
        write_rgba(tmp, rgba)
        settings = bpy.context.scene.render.image_settings
        saved = {k: getattr(settings, k) for k in ("file_format", "color_depth", "exr_codec",
                                                   "color_mode")}
        try:
            settings.file_format, settings.color_mode = "OPEN_EXR", "RGBA"
            settings.color_depth, settings.exr_codec = "16", "PXR24"
            tmp.save_render(path, scene=bpy.context.scene)
        finally:
            for k, v in saved.items():
                setattr(settings, k, v)
        image = bpy.data.images.load(path)
        image.name = name
        image.colorspace_settings.name = "Non-Color"
        image.alpha_mode = "CHANNEL_PACKED"
        image.use_half_precision = True
        image.pack()
        image.filepath = ""
    finally:
        bpy.data.images.remove(tmp)
        shutil.rmtree(folder, ignore_errors=True)
    return image


def table_info(image):
    info = image[TABLE_INFO]
    return {k: info[k] for k in info.keys()}


def read_table(image):
    """The :class:`..core.colourtable.ColourTable` a table image holds."""
    if image is None or TABLE_INFO not in image:
        raise AgingError("An aged material lost its aging table: press Age")
    return table_from_atlas(read_rgba(image), table_info(image))


def rates(inputs, S, shape):
    """(S, H·W) float32 annual dose per spectrum, lux·h, sampled at the texel centres of
    an (H, W) texture (bilinear, as the group's Linear lookups of the maps)."""
    out = np.zeros((S, shape[0] * shape[1]), dtype=np.float32)
    for m in inputs:
        lux = np.maximum(read_rgba(m.image)[..., 0], 0.0)
        out[m.spectrum] += resample(lux, shape).reshape(-1).astype(np.float32) \
            * np.float32(m.hours)
    return out


def used_tables():
    """Table images some aged copy reads (itself or through its parts' lanes)."""
    used = set()
    for m in bpy.data.materials:
        if m.lightfade.source is not None:
            used.update(i for i in (m.lightfade.table_image,
                                    *(lane.table_image for lane in m.lightfade.lanes))
                        if i is not None)
    return used


def purge_tables():
    """Remove table images no aged copy reads, images of older versions, and the
    evaluation groups no aging group uses."""
    for tree in list(bpy.data.node_groups):
        if tree.name.startswith(EVAL_PREFIX) and tree.users == 0:
            bpy.data.node_groups.remove(tree)
    used = used_tables()
    for image in list(bpy.data.images):
        if image.name.startswith(TABLE_PREFIX) and image not in used:
            bpy.data.images.remove(image)
        elif image.name.startswith(OLD_PREFIXES):
            bpy.data.images.remove(image)

