"""What Age would do and what it did: per (object, material) path, reason and status.

For the panels and :func:`lightfade_addon.api.material_plan`.  Runs no Cycles work.
"""

from __future__ import annotations

from .aging.apply import stale_message
from .aging.copies import copies_of
from .targets import check, targets


def copy_status(scene, copy):
    """``"aged"``, or ``"stale: <why>"`` for an aged copy."""
    return stale_message(scene, copy) or "aged"


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
