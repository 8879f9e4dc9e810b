"""``blender -c lightfade ...``: LightFade's command-line command (Blender 4.2+).

Blender passes :func:`execute` the arguments that follow the command name as a list of
strings and exits with the int it returns (``bpy.utils.register_cli_command``); the
command runs in background mode after the add-ons are enabled.  The work is done by
:func:`..pipeline.main`, which ``python -m lightfade_addon scene`` calls too.
"""

import bpy

COMMAND = "lightfade"
_handles = []


def execute(argv):
    """The registered callback: ``argv`` is everything after ``-c lightfade``."""
    from ..pipeline import main

    return main(list(argv), prog=f"blender -c {COMMAND}")


def register():
    _handles.append(bpy.utils.register_cli_command(COMMAND, execute))


def unregister():
    while _handles:
        bpy.utils.unregister_cli_command(_handles.pop())
