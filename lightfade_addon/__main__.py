"""``python -m lightfade_addon ...``: the command-line tool (see :mod:`lightfade_addon.cli`)."""

import sys

from .cli import main

sys.exit(main())
