"""``python -m lightfade_addon ...``: the command-line tool (see :mod:`lightfade_addon.cli`)."""

import os
import sys

from .cli import main

sys.exit(main(prog=f"{os.path.basename(sys.executable)} -m {__package__}"))
