"""``scene``: the pipeline commands through the bpy module (see :mod:`..pipeline`).

``python -m lightfade_addon scene age shot.blend --years 25`` runs exactly what
``blender -c lightfade age shot.blend --years 25`` runs.
"""

from ..cli import command


@command("scene", "bake, age, render or describe .blend files (needs the bpy module)")
def build(parser):
    from ..pipeline import add_subcommands

    add_subcommands(parser)
    parser.set_defaults(run=lambda args: _run(args, parser))


def _run(args, parser):
    from ..pipeline import run

    return run(args, parser)
