"""Age: prepare aged copies of the target materials and show a number of years.

The order is the promise made to the user: every check that can refuse runs first
(:func:`.targets.check`, no Cycles work yet) and all problems are reported together;
then each object gets its own aged copies (:mod:`.copies`), the Base Color of the
copies on the baked path is evaluated by Cycles (:mod:`.albedo`, one bake per object),
the aging data are prepared (:mod:`.runtime`) and each copy gets its aging node group
(:mod:`.nodes.aging`) between its own Base Color graph and its BSDF — a material with
parts gets one preparation and group per recipe in use, mixed by the masks
(:mod:`.parts`); the scene's years drive them all (:mod:`.years`).
If anything fails on the way, the copies made so far are removed again.
"""

from __future__ import annotations

import bpy

from . import parts, runtime
from .albedo import albedo_image, bake_albedos
from .apply import build_group
from .copies import assign, copies_of, insert_group, make_copy
from .years import write_years
from .errors import AgingError, check_years
from .exposure import exposure_shape, exposure_uv
from .grids import purge
from .reset import remove_aged
from .targets import check, format_problems, targets


def _view_layer(scene):
    context = bpy.context
    return context.view_layer if context.scene == scene else scene.view_layers[0]


def _new_copy(obj, material, plan, years):
    copy = make_copy(obj, material, plan.colour)
    assign(obj, material, copy)
    props = copy.lightfade
    props.path = plan.path
    props.reason = plan.reason
    props.uv_map = exposure_uv(obj)
    props.max_years = runtime.prepared_range(years)
    h, w = exposure_shape(obj)
    if plan.path == "DIRECT":
        props.albedo = plan.image
    elif plan.path == "FLAT":
        props.flat_colour = plan.flat
    else:
        props.albedo = albedo_image(copy, (h, w))
    return copy


def lock_interface(scene):
    """Turn Render > Lock Interface on, remembering the user's setting for Reset."""
    props = scene.lightfade
    if props.lock_interface_before < 0:
        props.lock_interface_before = int(scene.render.use_lock_interface)
    scene.render.use_lock_interface = True


def age_scene(scene, years, selected=(), progress=None, report=None):
    """Age the target materials (see :func:`.targets.targets`) and show ``years``.

    Returns the aged copies, one per (object, material).  Raises :class:`AgingError`
    with every problem found, before anything changes, when any pair cannot be aged.
    """
    years = check_years(years)
    pairs = targets(scene, selected)
    if not pairs:
        raise AgingError("Nothing to age: select meshes with materials, or enable LightFade on "
                         "a material (Material Properties > LightFade > Age this Material)")
    plans, problems = check(scene, pairs)
    if problems:
        raise AgingError(format_problems(problems))
    say = progress or (lambda f, m: None)
    for obj, material in pairs:
        for old in copies_of(material, obj):
            remove_aged(old)
    made = []
    try:
        for obj in dict.fromkeys(obj for obj, _m in pairs):
            jobs = []
            for material in (m for o, m in pairs if o == obj):
                plan = plans[obj, material]
                copy = _new_copy(obj, material, plan, years)
                made.append((copy, plan))
                if plan.path == "BAKED":
                    jobs.append((copy, plan.colour, copy.lightfade.albedo))
            if jobs:
                say(len(made) / (2 * len(pairs)), f"{obj.name}: baking Base Color with Cycles")
                bake_albedos(scene, _view_layer(scene), obj, jobs, exposure_uv(obj),
                             scene.lightfade.bake_margin)
        for k, (copy, plan) in enumerate(made):
            props = copy.lightfade

            def step(f, msg, k=k, name=props.source.name):
                say((len(made) + k + f) / (2 * len(made)), f"{name}: {msg}")

            shape = exposure_shape(props.aged_object)
            if parts.has_parts(props.source):        # one preparation per recipe in use
                parts.make_lanes(copy)
                parts.prepare_lanes(scene, copy, shape, step)
                props.signature = runtime.signature(scene, copy)
                parts.wire(copy, plan.colour, [build_group(copy, lane) for lane in props.lanes])
                parts.bake_weights(scene, _view_layer(scene), copy, plan.colour)
                continue
            runtime.prepare(scene, copy, shape, step)
            props.signature = runtime.signature(scene, copy)
            insert_group(copy, plan.colour, build_group(copy), props.restored_image)
    except BaseException:
        for copy, _plan in made:
            remove_aged(copy)
        raise
    purge(scene, parts.grids_in_use())
    lock_interface(scene)
    write_years(scene, years)
    return [copy for copy, _plan in made]
