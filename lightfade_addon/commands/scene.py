"""``scene``: the pipeline commands through the bpy module (see :mod:`..pipeline`).

``python -m lightfade_addon scene age shot.blend --years 25`` runs exactly what
``blender -c lightfade age shot.blend --years 25`` runs.
"""

NAME = "scene"
HELP = "bake, age, render or describe .blend files (needs the bpy module)"


def add_arguments(parser):
    from ..pipeline import add_subcommands

    add_subcommands(parser)


def run(args):
    from ..pipeline import run_program

    return run_program(args)
