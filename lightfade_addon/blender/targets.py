"""Which (object, material) pairs an Age acts on, and every reason it would refuse.

:func:`targets` picks the pairs; :func:`check` runs every check that can refuse —
before any Cycles work — and returns all problems at once, so one message can name
every object and material and what to do.
"""

from __future__ import annotations

from .aging.copies import original
from .exposure import scene_objects
from .aging.parts import part_problems
from .aging.runtime import material_recipe
from .source import material_plan


def _materials(obj):
    return [original(s.material) for s in obj.material_slots if s.material is not None]


def _instanced(selected):
    """Sources aged per instance that the selected empties instance."""
    out = []
    for o in selected:
        if o.instance_type == "COLLECTION" and o.instance_collection is not None:
            out += [s for s in o.instance_collection.all_objects
                    if s.type == "MESH" and s.lightfade.instance_tiles and s not in out]
    return out


def targets(scene, selected=()):
    """``[(object, material)]`` to age; materials are the user's (never aged copies).

    With meshes selected: their ticked materials ("Age this Material"); if none of
    them is ticked, all their materials (zero configuration: the default recipe).
    With nothing selected: the ticked materials of every mesh in the scene.
    """
    chosen = [o for o in selected if o.type == "MESH"] + _instanced(selected)
    objects = chosen or [o for o in scene_objects(scene) if o.type == "MESH"]
    ticked = any(m.lightfade.enabled for o in objects for m in _materials(o))
    pairs = []
    for obj in objects:
        for material in _materials(obj):
            if (material.lightfade.enabled or (chosen and not ticked)) \
                    and (obj, material) not in pairs:
                pairs.append((obj, material))
    return pairs


def check(scene, pairs, need_exposure=True):
    """``(plans, problems)``: the :class:`.source.Plan` of every pair, and every problem
    found (each one line naming the object or material and what to do), in order."""
    plans, problems = {}, []
    for obj, material in pairs:
        plan = material_plan(scene, obj, material, need_exposure)
        if plan.colour is not None:
            plan.problems.extend(p for p in part_problems(obj, material, plan.colour)
                                 if p not in plan.problems)
        problem = recipe_problem(material)
        if problem is not None and problem not in plan.problems:
            plan.problems.append(problem)
        plans[obj, material] = plan
        for problem in plan.problems:
            if problem not in problems:
                problems.append(problem)
    return plans, problems


def recipe_problem(material):
    """One line when the material's *Per-Colourant Classes* cannot be applied, else None."""
    try:
        material_recipe(material)
    except ValueError as exc:
        return (f"Material '{material.name}': Per-Colourant Classes "
                f"'{material.lightfade.fastness}': {exc}; correct or clear the field")
    return None


def material_problems(scene, objects=()):
    """Every material problem Age would refuse that no bake can fix (for the Bake
    operator to report, together with its own checks, before any Cycles work)."""
    return check(scene, targets(scene, objects), need_exposure=False)[1]


def format_problems(problems):
    """One message for a list of problems (first line says how many)."""
    if len(problems) == 1:
        return problems[0]
    return f"{len(problems)} problems, nothing was changed:\n" + "\n".join(
        f"- {p}" for p in problems)
