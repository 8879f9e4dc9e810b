"""What Age would do and what it did: per (object, material) path, reason and status.

For the panels and :func:`lightfade_addon.api.material_plan`.  Runs no Cycles work.
"""

from __future__ import annotations

from .apply import needs_age, stale_reason
from .copies import copies_of
from .targets import check, targets


#: What brings a stale copy up to date.
REFRESH = "press Age to update it (the Years slider shows it as it was)"


def copy_status(scene, copy):
    """``"aged"``, or ``"stale: <why>"`` for an aged copy."""
    why = stale_reason(scene, copy)
    if not why:
        return "aged"
    blocked = needs_age(scene, copy)
    # the slider writes one property and prepares nothing (that is what keeps it free):
    # only Age (or api.set_years) brings a stale copy up to date, so that is what is said
    return f"stale: {blocked}" if blocked else f"stale: {why}: {REFRESH}"


def material_status(scene, objects=()):
    """A list of dicts: object, material, path, reason, problems, status."""
    pairs = targets(scene, objects)
    plans, _problems = check(scene, pairs)
    rows = []
    for (obj, material), plan in plans.items():
        copy = next(iter(copies_of(material, obj)), None)
        rows.append(dict(object=obj.name, material=material.name, path=plan.path,
                         reason=plan.reason, problems=list(plan.problems),
                         status=copy_status(scene, copy) if copy is not None else "not aged"))
    return rows
