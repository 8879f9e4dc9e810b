"""``blender -c lightfade ...``: LightFade's command-line command (Blender 4.2+).

Blender passes :func:`execute` the arguments that follow the command name as a list of
strings and exits with the int it returns (``bpy.utils.register_cli_command``); the
command runs in background mode after the add-ons are enabled.  The work is done by
:func:`..pipeline.main`, which ``python -m lightfade_addon scene`` calls too.
"""

import atexit

import bpy

COMMAND = "lightfade"
_handles = []


def execute(argv):
    """The registered callback: ``argv`` is everything after ``-c lightfade``."""
    from ..pipeline import main

    return main(list(argv), prog=f"blender -c {COMMAND}")


def register():
    _handles.append(bpy.utils.register_cli_command(COMMAND, execute))
    if not bpy.app.binary_path:
        # The bpy module (binary_path is "") of Blender 4.2 frees registered commands
        # after Python has finalized and crashes at exit (seen with 4.2.23, not 5.2):
        # unregister before that.  Not in Blender itself, which frees them earlier.
        atexit.register(unregister)


def unregister():
    atexit.unregister(unregister)
    while _handles:
        bpy.utils.unregister_cli_command(_handles.pop())
