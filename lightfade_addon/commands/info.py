"""``info``: what this installation can do (versions, solver defaults)."""

from ..cli import command


@command("info", "print versions and the physics core's defaults")
def build(parser):
    parser.set_defaults(run=run)


def run(args):
    import numpy

    from .. import __version__
    from ..core import fading

    print(f"lightfade {__version__}")
    print(f"numpy {numpy.__version__}")
    try:
        import colour

        print(f"colour-science {colour.__version__}")
    except ImportError:
        print("colour-science: not installed")
    import inspect

    params = inspect.signature(fading.simulate).parameters
    defaults = ", ".join(f"{k}={params[k].default!r}" for k in ("layers", "steps", "scheme"))
    print(f"simulate defaults: {defaults}")
    return 0
