"""Preparing an aged copy: the shared colour table and the copy's node group.

Age does nothing per texel. For each aged copy :func:`prepare` finds (or builds once for
the file) the colour table of its recipe under its object's light spectra
(:func:`.agingdata.ensure_table`) and builds the copy's aging node group, which reads
that table, the object's exposure maps and the scene's years (:mod:`.group`).
:func:`insert_aging` is the one step that puts the aging of one recipe between one
colour socket and its BSDF. The years then cost nothing here: the material evaluates
them. :func:`evaluator` reads the same table and maps back for the numpy twin (real
aged images, :mod:`.apply`).
"""

from __future__ import annotations

import hashlib
import zlib

import numpy as np

from ...core.aging.ager import Light
from ...core.aging.colourtable import ColourTable, atlas_layout
from ...core.aging.prepared import evaluate_prepared, prepare_texels, table_cells
from ...core.fading.grid import GridSettings
from ...core.fading.recipes import get_recipe, parse_classes
from ...core.aging.restore import Prior
from . import data as agingdata
from .copies import GROUP_NODE, insert_group, walk
from ..errors import AgingError
from ..exposure import exposure_images, exposure_shape, exposure_signature
from .grids import SceneGridStore
from .group import VERSION_KEY, GroupSpec, new_group
from ..parts.properties import parts_digest
from ..pixels import read_linear, read_rgba, stored_state
from ..vocabulary import RECIPE_IDS, SPECTRUM_IDS

#: The grid a restoration (Already Aged) solves on (the tests patch in a coarser one).
GRID_SETTINGS = GridSettings()
GROUP_PREFIX = "LF_Aging_"

#: Numpy evaluator inputs read from a copy's images, keyed by (the copy's
#: ``session_uid``, lane name) and checked against the images they were read from:
#: ``(table image pointer, ColourTable, TableCells or None)``.
_EVALUATORS = {}
#: The copies' prepared texels (:mod:`..core.aging.prepared`), same keys:
#: ``(inputs key, colour digest, PreparedTexels)``.
_PREPARED = {}
#: The copies' colours held while their images are as loaded (:func:`held_colour`),
#: keyed by (``session_uid``, ""): ``(colour state, (H, W, 4) linear, colour digest)``.
_COLOURS = {}


def clear():
    """Forget every cached evaluator, prepared texels and held colour (file load, reset,
    unregister)."""
    _EVALUATORS.clear()
    _PREPARED.clear()
    _COLOURS.clear()


def forget(copy):
    for cache in (_EVALUATORS, _PREPARED, _COLOURS):
        for key in [k for k in cache if k[0] == copy.session_uid]:
            del cache[key]


def colour_state(copy):
    """What ``copy``'s colour is, without reading its pixels (:func:`..pixels.
    stored_state` of its albedo image, or its flat colour); None where the pixels must
    be read to know (an image painted or written since it was loaded or saved)."""
    props = copy.lightfade
    if props.path == "FLAT":
        return ("flat", tuple(props.flat_colour))
    if props.albedo is None:
        return None
    state = stored_state(props.albedo)
    return None if state is None else (props.path, *state)


def held_colour(scene, copy, state=None):
    """``((H, W, 4) linear colour the copy ages, its twin key)`` (:func:`twin_key`).

    The colour is read (and its digest computed) only when its :func:`colour_state`
    (``state``, when the caller has it) is unknown or changed: a clean texture's
    colour is held (16 bytes a texel), so that writing aged images at other years
    (frame images, Apply) reads, decodes and digests nothing. Not to be written to. On
    the baked path the caller makes the albedo first (:func:`.apply.ensure_albedo`)."""
    slot = _slot(copy, None)
    state = colour_state(copy) if state is None else state
    held = _COLOURS.get(slot)
    if state is not None and held is not None and held[0] == state:
        rgba = held[1]
        return rgba, (*inputs_key(scene, copy), rgba.shape, held[2])
    rgba = original_rgba(copy, exposure_shape(copy.lightfade.aged_object) or (64, 64))
    key = twin_key(scene, copy, rgba)
    if state is None:
        _COLOURS.pop(slot, None)
    else:
        rgba.flags.writeable = False
        _COLOURS[slot] = (state, rgba, key[-1])
    return rgba, key


def material_recipe(material):
    """The core recipe for a material's LightFade settings."""
    return settings_recipe(material.lightfade)


def settings_recipe(props):
    """The core recipe for recipe settings (a material's, a part's or a lane's)."""
    recipe = get_recipe(RECIPE_IDS[props.recipe])
    if props.sensitivity_mode == "BETA":
        return recipe.with_beta(props.beta * 1e-6)
    recipe = recipe.with_blue_wool(props.blue_wool)
    classes = parse_classes(getattr(props, "fastness", ""))     # parts have none
    return recipe.with_classes(classes) if classes else recipe


def material_prior(material):
    """The texture's own history (:class:`..core.restore.Prior`), or None when it is new.

    ``already_years`` under one light: its spectrum, UV filter, lux and hours per day,
    every day of the year (the texture's lux is taken as uniform).
    """
    s = material.lightfade
    if not s.already_years > 0:
        return None
    light = Light(SPECTRUM_IDS[s.already_spectrum], s.already_uv_filter, s.already_lux,
                  s.already_hours_per_day, 365.0)
    return Prior(float(s.already_years), (light,))


def signature(scene, copy):
    """Digest of everything a copy's aging group depends on besides the years.

    Which exposure maps count and their light (spectrum, UV filter, schedule), the UV
    map, the source material's recipe, sensitivity and history, the colour path. Not
    the maps' pixels: the group reads the map images themselves, and a re-bake remaps
    the old images onto the new, so a re-bake of the same light groups reaches every
    view without Age. The scene's *Aged Colour On* (the copy's ray gate) counts too.
    """
    props = copy.lightfade
    source, obj = props.source, props.aged_object
    if source is None or obj is None:
        return ""
    s = source.lightfade
    try:
        maps = [f"{image.name}:{light}" for image, light in exposure_images(scene, obj)]
    except AgingError as err:
        maps = [str(err)]
    parts = [obj.lightfade.uv_map, obj.lightfade.instance_tiles, *maps, s.recipe,
             s.sensitivity_mode, str(s.blue_wool),
             s.fastness, repr(s.beta), repr(material_prior(source)), props.path, props.uv_map,
             scene.lightfade.aged_rays]
    if len(s.parts):                                  # several recipes by mask (.parts)
        parts.append(parts_digest(s))
    return hashlib.sha1("|".join(parts).encode()).hexdigest()


def group_version(copy):
    """The :data:`.group.GROUP_VERSION` of the copy's aging group (0: none or old)."""
    for _tree, node in walk(copy.node_tree):
        if node.name == GROUP_NODE and node.node_tree is not None:
            return int(node.node_tree.get(VERSION_KEY, 0))
    return 0


def group_spec(uv_map, inputs, table_image, tile=""):
    """The :class:`.group.GroupSpec` of a table image and exposure inputs."""
    info = agingdata.table_info(table_image)
    layout = atlas_layout(info)
    return GroupSpec(uv_map=uv_map, maps=tuple(inputs), table_image=table_image,
                     table_size=tuple(table_image.size), side=int(info["side"]),
                     T=int(info["T"]), q=int(info["q"]), S=int(info["S"]),
                     gamma=float(info["gamma"]), per_decade=float(info["per_decade"]),
                     low_dose=float(info["low_dose"]), history=bool(info["history"]),
                     unmix_side=int(info["unmix_side"]), power=float(info["power"]),
                     unmix_y=layout.unmix_y, per_row=layout.per_row, tile=tile)


def aging_group(scene, obj, recipe, prior=None, name="LF_Aging", progress=None):
    """``(group tree, table image, table or None)``: the aging of ``recipe`` (with history
    ``prior``) on ``obj`` under its exposure maps, as a new node group ``name``."""
    inputs, keys = agingdata.map_inputs(scene, obj)
    restore_kw = dict(settings=GRID_SETTINGS, store=SceneGridStore(scene))
    try:
        image, table = agingdata.ensure_table(recipe, keys, prior, progress, restore_kw)
    except ValueError as err:
        raise AgingError(f"Object '{obj.name}', recipe '{recipe.name}': {err}") from None
    spec = group_spec(obj.lightfade.uv_map, inputs, image, obj.lightfade.instance_tiles)
    return new_group(name, spec), image, table


def insert_aging(scene, copy, colour, recipe, prior=None, progress=None):
    """Put the aging of ``recipe`` between the colour socket ``colour`` (a
    :class:`.source.ColourSocket` in ``copy``'s tree) and its BSDF; returns the group node.

    The one step that ages one colour socket with one recipe: the table is shared by
    every copy with the same recipe and light spectra, the group is the copy's own.
    """
    obj = copy.lightfade.aged_object
    group, image, table = aging_group(scene, obj, recipe, prior, GROUP_PREFIX + copy.name,
                                      progress)
    copy.lightfade.table_image = image
    if table is not None or prior is not None:
        copy.lightfade.lost_texels = lost_texels(copy, table or agingdata.read_table(image))
    return insert_group(copy, colour, group)


def prepare(scene, copy, colour, progress=None):
    """Age ``copy``'s colour socket with its source material's recipe (:func:`insert_aging`)."""
    props = copy.lightfade
    if props.aged_object is None or props.source is None:
        raise AgingError(f"Aged material '{copy.name}' lost its object or source: press Reset")
    node = insert_aging(scene, copy, colour, material_recipe(props.source),
                        material_prior(props.source), progress)
    props.signature = signature(scene, copy)
    forget(copy)
    return node


def lost_texels(copy, table):
    """Texels of a copy with a history whose original the light erased (the nearest
    cube node's verdict); 0 without a history or where the colour is not at hand yet."""
    lost = getattr(table, "lost", None)
    props = copy.lightfade
    if lost is None or props.path == "BAKED" and props.albedo is None:
        return 0
    rgb = original_rgba(copy, (1, 1))[..., :3].reshape(-1, 3)
    N = lost.shape[0]
    u = np.rint(np.clip(rgb, 0, 1) ** (1.0 / table.gamma) * (N - 1)).astype(int)
    return int(np.count_nonzero(lost[u[:, 2], u[:, 1], u[:, 0]]))


def original_rgba(copy, shape):
    """(H, W, 4) linear colour the copy ages (the artist's, before the group); ``shape``
    is used by the flat path only."""
    props = copy.lightfade
    if props.path == "FLAT":
        rgba = np.ones((*shape, 4), dtype=np.float32)
        rgba[..., :3] = props.flat_colour
        return rgba
    if props.albedo is None:
        raise AgingError(f"Material '{copy.name}' has no albedo image: press Age again")
    rgba = read_linear(props.albedo) if props.path == "DIRECT" else read_rgba(props.albedo)
    if props.albedo.is_float:                       # a byte image's colours are in [0, 1]
        rgb = np.nan_to_num(rgba[..., :3], nan=0.0, posinf=1.0, neginf=0.0)
        rgba[..., :3] = np.clip(rgb, 0.0, 1.0)      # a Base Color is a reflectance
    return rgba


def _slot(copy, lane):
    return (copy.session_uid, "" if lane is None else lane.name)


def evaluator(copy, lane=None):
    """The :class:`..core.colourtable.ColourTable` ``copy`` reads (or one ``lane`` of a
    copy with parts, :mod:`.parts`), from its table image (cached while the image is
    the same)."""
    image = (copy.lightfade if lane is None else lane).table_image
    key = image.as_pointer() if image else 0
    slot = _slot(copy, lane)
    cached = _EVALUATORS.get(slot)
    if cached is not None and cached[0] == key:
        return cached[1]
    table = agingdata.read_table(image)
    if not isinstance(table, ColourTable):
        raise AgingError(f"Aged material '{copy.name}' lost its aging table: press Age")
    _EVALUATORS[slot] = (key, table, None)
    _PREPARED.pop(slot, None)
    return table


def _cells(copy, lane, table):
    """The table's :class:`..core.prepared.TableCells` (made once per cached table)."""
    slot = _slot(copy, lane)
    key, cached, cells = _EVALUATORS[slot]
    if cells is None:
        for other_key, other, other_cells in _EVALUATORS.values():   # shared tables
            if other_key == key and other_cells is not None:
                cells = other_cells
                break
        else:
            cells = table_cells(table)
        _EVALUATORS[slot] = (key, cached, cells)
    return cells


def inputs_key(scene, copy, lane=None):
    """What the numpy twin's result depends on besides the colour and the years: the
    table image, the copy's signature and its object's exposure. Hashable; reads no
    pixels."""
    props = copy.lightfade
    evaluator(copy, lane)
    return (_EVALUATORS[_slot(copy, lane)][0], props.signature,
            exposure_signature(scene, props.aged_object))


def twin_key(scene, copy, rgba, lane=None):
    """What the numpy twin's result for the colour ``rgba`` (H, W, 4) depends on
    besides the years: :func:`inputs_key`, the size and a digest (CRC-32) of the
    colour. Hashable."""
    flat = np.ascontiguousarray(rgba)
    return (*inputs_key(scene, copy, lane), flat.shape, zlib.crc32(flat.data))


def aged_rgb(scene, copy, rgba, years, lane=None, key=None, out=None, codes=False,
             layout=None):
    """Aged linear colour (in place in ``rgba``'s first three channels, (H, W, 4), or in
    ``out``'s, the same shape) of ``copy`` (or its ``lane``) colour ``rgba`` at
    ``years``: the numpy twin of the node group. With ``codes``, the 8-bit sRGB codes
    over 255 of that colour (what a byte sRGB image is given, :func:`..core.colour.
    srgb8.srgb_code_floats`).

    Everything that does not depend on the years — the texels' annual doses, light-mix
    vertices and, for the years last asked, the change at the two dose nodes around
    them — is kept per copy (:mod:`..core.aging.prepared`) while the table, the copy's
    signature, its object's exposure and the colour are the same (:func:`twin_key`,
    or ``key`` when the caller has it); then a years value costs the dose lookup and
    the colour stage (tens of ms per Mtexel).

    With ``layout`` (:class:`.blocks.Layout`), ``rgba`` (n, 1, 4) holds its samples
    (:meth:`.blocks.Pyramid.samples`) and their annual doses are the level's, extended
    the same way; ``key`` then names the level.
    """
    props = copy.lightfade
    obj = props.aged_object
    table = evaluator(copy, lane)
    H, W = rgba.shape[:2]
    flat = rgba.reshape(H * W, 4)
    slot = _slot(copy, lane)
    key = twin_key(scene, copy, rgba, lane) if key is None else key
    inputs_key, digest = key[:-1], key[-1]
    cached = _PREPARED.get(slot)
    if cached is None or cached[0] != inputs_key:
        inputs, _keys = agingdata.map_inputs(scene, obj)
        prep = prepare_texels(table, _rates(inputs, table.S, (H, W), layout))
    else:
        prep = cached[2]
        if cached[1] != digest:                      # the colour changed: no band is valid
            prep.t0[:] = -1
    _PREPARED[slot] = (inputs_key, digest, prep)
    target = flat if out is None else out.reshape(H * W, 4)
    evaluate_prepared(table, prep, flat[:, :3], float(years), out=target,
                      cells=_cells(copy, lane, table), codes=codes)
    return rgba if out is None else out


def _rates(inputs, S, shape, layout=None):
    """(S, n) annual doses of the texels of an (H, W) colour (:func:`.data.rates`), or of
    the samples of a :class:`.blocks.Layout` (its level's blocks, then the brighter parts
    of the mixed ones)."""
    if layout is None:
        return agingdata.rates(inputs, S, shape)
    return np.ascontiguousarray(layout.extend(agingdata.rates(inputs, S, layout.shape).T).T)
