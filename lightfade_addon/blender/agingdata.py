"""An aged copy's aging data as images in the file: keys, dose rates, the table.

The node group (:mod:`.nodes.aging`) reads these images and the numpy evaluator
(:func:`..core.table.evaluate`) is rebuilt from the same images (:func:`read`), so the
two evaluators share one table.  The images are LightFade's own datablocks (prefix
``LF_``), packed into the .blend on save and removed by Reset:

``LF_Key_<copy>``  8-bit RGBA, Non-Color, the albedo's size: each texel's colour key
    (:func:`..core.table.key_pixels`).
``LF_Rate_<copy>`` float RGBA, Non-Color, the exposure maps' size: annual dose from
    each light spectrum (channels R, G, B, A; up to four spectra) as a fraction of the
    table's last dose node (GPUs may hold float textures in half precision, whose
    largest value, 65504, a dose in lux·h passes).
``LF_Table_<copy>`` float RGBA, Non-Color: the aging table
    (:func:`..core.table.table_pixels`); its shape is in the image's custom property
    ``lightfade_table``.
``LF_New_<copy>``  float, linear: the texture restored to new (only for a material
    with a history, *Already Aged*): the colour the group ages from.
"""

from __future__ import annotations

import bpy
import numpy as np

from ..core.lights import dose_rates, spectra_keys
from ..core.table import AgingTable, Texels, key_pixels, table_layout, table_pixels, \
    texel_positions
from .errors import AgingError
from .nodes.aging import GroupSpec
from .pixels import read_rgba, resample, write_rgba

KEY_PREFIX = "LF_Key_"
RATE_PREFIX = "LF_Rate_"
TABLE_PREFIX = "LF_Table_"
NEW_PREFIX = "LF_New_"
PREFIXES = (KEY_PREFIX, RATE_PREFIX, TABLE_PREFIX, NEW_PREFIX)
#: Custom property of the table image: the table's shape and dose axis.
TABLE_INFO = "lightfade_table"
#: Light spectra a rate image holds (its four channels).
MAX_SPECTRA = 4


def _image(name, size, float_buffer, colorspace="Non-Color"):
    old = bpy.data.images.get(name)
    if old is not None:
        bpy.data.images.remove(old)
    w, h = size
    image = bpy.data.images.new(name, w, h, alpha=True, float_buffer=float_buffer)
    image.colorspace_settings.name = colorspace
    image.alpha_mode = "CHANNEL_PACKED"          # data, never premultiplied
    return image


def _data(copy, lane):
    """Where a preparation's images live: the copy's own fields, or ``lane`` (one recipe
    of a copy with parts, :mod:`.parts`)."""
    return copy.lightfade if lane is None else lane


def _name(prefix, copy, lane):
    return prefix + copy.name + ("" if lane is None else f"~{lane.name}")


def write(copy, ager, lights, at_bake, restored=False, lane=None):
    """Write ``ager``'s table and texel data into the copy's images (or ``lane``'s).

    ``at_bake`` are the lights' exposure maps at the bake's resolution (the rate image).
    """
    props = copy.lightfade
    data = _data(copy, lane)
    keys = spectra_keys(lights)
    if len(keys) > MAX_SPECTRA:
        raise AgingError(f"Material '{props.source.name}' on '{props.aged_object.name}' is "
                         f"lit by {len(keys)} light spectra; at most {MAX_SPECTRA} can age "
                         "in one material: give some lamps the same Spectrum")
    remove(copy, lane)                            # the previous preparation's images
    H, W = ager.shape[:2]
    key = _image(_name(KEY_PREFIX, copy, lane), (W, H), False)
    write_rgba(key, key_pixels(ager.texels.key, (H, W)).astype(np.float32) / 255.0)

    h, w = at_bake.shape[1:]
    rates = dose_rates(lights, at_bake.reshape(len(lights), -1), h * w, keys)
    rgba = np.zeros((h * w, 4), dtype=np.float32)
    rgba[:, :len(keys)] = rates.T / np.float32(ager.table.max_dose)
    rate = _image(_name(RATE_PREFIX, copy, lane), (w, h), True)
    write_rgba(rate, rgba)
    rate.use_half_precision = True                # renderers may hold it as half floats

    table = ager.table
    tw, th = table_layout(table)
    timage = _image(_name(TABLE_PREFIX, copy, lane), (tw, th), True)
    write_rgba(timage, table_pixels(table))
    timage.use_half_precision = True              # its values are half precision already
    timage[TABLE_INFO] = dict(max_dose=table.max_dose, q=table.q, S=table.S, T=table.T,
                              keys=table.keys)

    new = None
    if restored:
        new = _image(_name(NEW_PREFIX, copy, lane), (W, H), True, "Linear Rec.709")
        pixels = np.ones((H * W, 4), dtype=np.float32)
        pixels[:, :3] = ager.original.reshape(-1, 3)
        write_rgba(new, pixels)
    data.key_image, data.rate_image, data.table_image, data.restored_image = \
        key, rate, timage, new


def remove(copy, lane=None):
    """Remove the copy's aging images (or ``lane``'s), if any."""
    props = _data(copy, lane)
    for image in (props.key_image, props.rate_image, props.table_image, props.restored_image):
        if image is not None:
            bpy.data.images.remove(image)
    props.key_image = props.rate_image = props.table_image = props.restored_image = None


def table_info(copy, lane=None):
    info = _data(copy, lane).table_image[TABLE_INFO]
    return {k: info[k] for k in ("max_dose", "q", "S", "T", "keys")}


def key_shape(copy, lane=None):
    """(H, W) of the key image."""
    return tuple(_data(copy, lane).key_image.size)[::-1]


def group_spec(copy, extension="EXTEND", lane=None):
    """The :class:`.nodes.aging.GroupSpec` of the copy's images (or ``lane``'s)."""
    props = _data(copy, lane)
    info = table_info(copy, lane)
    slots = (info["q"] + 1) ** (info["S"] - 1)
    T = info["T"]
    tw, th = props.table_image.size
    return GroupSpec(uv_map=copy.lightfade.uv_map, key_image=props.key_image,
                     key_size=tuple(props.key_image.size), key_extension=extension,
                     rate_image=props.rate_image, S=info["S"], table_image=props.table_image,
                     table_size=(tw, th), T=T, slots=slots, per_row=tw // T, q=info["q"],
                     max_dose=info["max_dose"])


def fingerprint(copy, lane=None):
    """What :func:`read` depends on: the images (new ones on every preparation)."""
    props = _data(copy, lane)
    return tuple(i.as_pointer() if i is not None else 0 for i in
                 (props.key_image, props.rate_image, props.table_image, copy.lightfade.albedo,
                  props.restored_image))


def read(copy, original, lane=None):
    """(table, texels, positions, original) from the copy's images (or ``lane``'s);
    ``original`` is the (H, W, 4) linear colour the keys belong to."""
    props = _data(copy, lane)
    if props.key_image is None or props.table_image is None or props.rate_image is None:
        raise AgingError(f"Aged material '{copy.name}' lost its aging images: press Age")
    info = table_info(copy, lane)
    S, T, q, K = info["S"], info["T"], info["q"], info["keys"]
    slots = (q + 1) ** (S - 1)
    values = read_rgba(props.table_image).reshape(-1, 4)[:K * slots * T, :3]
    table = AgingTable.from_values(values.reshape(K, slots, T, 3), info["max_dose"], S, q)
    codes = np.rint(read_rgba(props.key_image)[..., :3] * 255.0).astype(np.int32)
    key = (codes[..., 0] << 16) | (codes[..., 1] << 8) | codes[..., 2]
    H, W = key.shape
    rate_map = read_rgba(props.rate_image) * np.float32(info["max_dose"])
    rates = np.stack([resample(rate_map[..., s], (H, W)).reshape(-1) for s in range(S)])
    if original.shape[:2] != (H, W):
        raise AgingError(f"Aged material '{copy.name}': its albedo is {original.shape[1]} x "
                         f"{original.shape[0]}, its keys {W} x {H}: press Age")
    texels = Texels.from_linear(key, rates, original[..., :3])
    return table, texels, texel_positions(table, texels), original
