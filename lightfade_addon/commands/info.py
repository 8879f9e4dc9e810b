"""``info``: what this installation can do (versions, solver defaults)."""

NAME = "info"
HELP = "print versions and the physics core's defaults"


def add_arguments(parser):
    """No arguments."""


def run(args):
    import inspect
    from importlib.metadata import PackageNotFoundError, version

    from .. import __version__
    from ..core.fading import model as fading

    print(f"lightfade {__version__}")
    for package in ("numpy", "colour-science", "scipy", "OpenImageIO"):
        try:
            print(f"{package} {version(package)}")
        except PackageNotFoundError:
            print(f"{package}: not installed")
    params = inspect.signature(fading.simulate).parameters
    defaults = ", ".join(f"{k}={params[k].default!r}" for k in ("layers", "steps", "scheme"))
    print(f"simulate defaults: {defaults}")
    return 0
