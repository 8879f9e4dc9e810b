"""Command-line commands; importing this package registers them with :mod:`..cli`."""

from . import info  # noqa: F401
from . import age_image  # noqa: F401
from . import scene  # noqa: F401
