"""Age: prepare aged copies of the target materials and show a number of years.

The order is the promise made to the user: every check that can refuse runs first
(:func:`.targets.check`, no Cycles work yet) and all problems are reported together;
then each object gets its own aged copies (:mod:`.copies`), and each copy its aging
node group (:mod:`.runtime`, :mod:`.group`) between its own Base Color graph and
its BSDF, reading the colour table its recipe and light spectra share (built once for
the file, :mod:`.data`) and the object's exposure maps — a material with parts
gets one such group per recipe in use, mixed by the masks (:mod:`.parts`); the scene's
years drive them all (:mod:`.years`); a gate keeps the group off where it changes
nothing (0 years) and off the rays the scene's *Aged Colour On* leaves out
(:func:`.copies.gate_rays`). Nothing is done per texel. If anything fails on
the way, the copies made so far are removed again.
"""

from __future__ import annotations

import bpy

from . import data as agingdata, frames, parts, runtime
from .apply import sampling
from .copies import assign, copies_of, gate_rays, make_copy
from .years import write_years
from ..errors import AgingError, check_years
from ...progress import console_after
from ..exposure import exposure_uv
from .grids import purge
from ..reset import remove_aged
from ..targets import check, format_problems, targets


def _new_copy(obj, material, plan):
    copy = make_copy(obj, material, plan.colour)
    assign(obj, material, copy)
    props = copy.lightfade
    props.path = plan.path
    props.reason = plan.reason
    props.uv_map = exposure_uv(obj)
    if plan.path == "DIRECT":
        props.albedo = plan.image
    elif plan.path == "FLAT":
        props.flat_colour = plan.flat
    return copy               # the baked path bakes its albedo only when applied (apply.py)


def lock_interface(scene):
    """Turn Render > Lock Interface on, remembering the user's setting for Reset."""
    props = scene.lightfade
    if props.lock_interface_before < 0:
        props.lock_interface_before = int(scene.render.use_lock_interface)
    scene.render.use_lock_interface = True


def table_requests(scene, pairs):
    """``(recipe, spectra keys)`` of the colour tables the pairs' materials age with
    (without parts or a history: those build their own on the way), to build together
    (:func:`.data.tables_built`); a pair whose maps cannot say is left to its step."""
    requests = []
    for obj, material in pairs:
        if parts.has_parts(material) or runtime.material_prior(material) is not None:
            continue
        try:
            keys = agingdata.map_inputs(scene, obj)[1]
            requests.append((runtime.material_recipe(material), keys))
        except (AgingError, KeyError, ValueError):
            continue
    return requests


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
    say = console_after(progress, 2.0, "LightFade Age")    # a long Age says what it does
    for obj, material in pairs:
        for old in copies_of(material, obj):
            remove_aged(old)
    made = []
    requests = table_requests(scene, pairs)
    try:
        with agingdata.tables_built(requests, lambda f, m: say(0.8 * f, m)) as built:
            start = 0.8 if built else 0.0            # the tables' share of the progress
            for k, (obj, material) in enumerate(pairs):
                plan = plans[obj, material]
                copy = _new_copy(obj, material, plan)
                made.append(copy)

                def step(f, msg, k=k, name=material.name):
                    say(start + (1.0 - start) * (k + f) / len(pairs), f"{name}: {msg}")

                step(0.0, "aging group")
                if parts.has_parts(material):            # one shared group per recipe in use
                    parts.prepare(scene, copy, plan.colour, step)
                else:
                    runtime.prepare(scene, copy, plan.colour, step)
                new = runtime.material_prior(material) is None
                gate_rays(copy, plan.colour, scene.lightfade.aged_rays, zero_years=new)
                if not parts.has_parts(material):       # parts render live (their weights bake)
                    frames.add_branch(copy, plan.colour, *sampling(copy))
    except BaseException:
        for copy in made:
            remove_aged(copy)
        raise
    agingdata.purge_tables()
    purge(scene, set())                          # grids live in the tables now
    lock_interface(scene)
    write_years(scene, years)
    say(1.0, f"aged {len(made)} material{'s' * (len(made) != 1)}")
    return made
