"""The argument parser of the scene commands, shared by both entry points.

``blender -c lightfade <sub-command> ...`` (:mod:`..blender.cli_command`) and
``python -m lightfade_addon scene <sub-command> ...`` (:mod:`..commands.scene`) build
their sub-commands with :func:`add_subcommands`, so both accept exactly the same
arguments.  Usage errors exit with status 2 (argparse's convention).
"""

from __future__ import annotations

import argparse
import math

from ..commands import ArgumentParser as Parser  # one-line usage errors, exit status 2

#: Bake overrides: (flag, property path on the scene, type, metavar, help).  Each flag
#: sets that setting of the opened file before a bake (and is kept in the saved file);
#: a new bake setting is one row.  Values are checked against the setting's range or
#: items once the add-on is registered.
BAKE_FLAGS = (
    ("--quality", "lightfade_bake.quality", str, "NAME",
     "exposure bake quality: preview, final (presets with their own samples and "
     "denoising) or custom (--samples); default: the file's setting"),
    ("--density", "lightfade_bake.texels_per_metre", float, "TEXELS_PER_M",
     "exposure map density, texels per metre of surface (default: the file's setting)"),
    ("--resolution", "lightfade.bake_resolution", int, "PX",
     "largest exposure map width and height, pixels (default: the file's setting)"),
    ("--samples", "lightfade.bake_samples", int, "N",
     "Cycles samples per texel, with --quality custom (default: the file's setting)"),
    ("--margin", "lightfade.bake_margin", int, "PX",
     "bake margin past UV island borders, pixels (default: the file's setting)"),
)


def _years(text):
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"years must be a number, got {text!r}") from None
    if not math.isfinite(value) or value < 0:
        raise argparse.ArgumentTypeError(f"years must be a number >= 0, got {text!r}")
    return value


def _add_files(p):
    p.add_argument("files", nargs="+", metavar="FILE.blend",
                   help="one or more .blend files; each is processed on its own and a "
                        "failing file does not stop the others")


def _add_bake_flags(p):
    g = p.add_argument_group("bake settings (used when a bake runs)")
    for flag, _prop, kind, metavar, help_text in BAKE_FLAGS:
        g.add_argument(flag, type=kind, metavar=metavar, help=help_text)


def _add_output(p, what, suffix):
    p.add_argument("--output", "-o", metavar="PATH",
                   help=f"where to write {what}: a .blend path (one input file) or a folder "
                        "(created if missing; each file keeps its name). Default: next to "
                        f"the input as NAME{suffix}.blend")
    p.add_argument("--in-place", action="store_true",
                   help="overwrite the input files (no backup .blend1 is written)")


def add_subcommands(parser):
    """Add ``bake``, ``age``, ``render-years``, ``export-aged`` and ``info`` to ``parser``.

    Each sub-parser sets ``args.action`` to its name; :func:`..batch.run` runs it.
    """
    sub = parser.add_subparsers(dest="action", metavar="SUBCOMMAND")
    sub.required = True

    p = sub.add_parser("bake", help="bake exposure maps with the file's settings and save",
                       description="Bake the exposure maps of every mesh whose materials "
                                   "have LightFade enabled, and save.")
    _add_files(p)
    _add_bake_flags(p)
    _add_output(p, "the baked file", "_baked")

    p = sub.add_parser("age", help="bake if needed, age to --years and save",
                       description="Bake the exposure maps that are missing, age the "
                                   "enabled materials to --years, and save.")
    _add_files(p)
    p.add_argument("--years", type=_years, required=True, metavar="N",
                   help="years of light exposure to show (>= 0)")
    p.add_argument("--rebake", action="store_true",
                   help="bake every exposure map again, even those already in the file")
    _add_bake_flags(p)
    _add_output(p, "the aged file", "_aged")

    p = sub.add_parser("render-years", help="one still per years value from the file's camera",
                       description="Age the scene and render one still per --years value "
                                   "with the file's camera and render settings, written as "
                                   "DIR/NAME_<years>y.<ext>. The .blend files are not changed.")
    _add_files(p)
    p.add_argument("--years", type=_years, nargs="+", required=True, metavar="N",
                   help="years values, one still each (e.g. 0 5 10 25)")
    p.add_argument("--output", "-o", required=True, metavar="DIR",
                   help="folder for the stills (created if missing)")
    p.add_argument("--rebake", action="store_true",
                   help="bake every exposure map again, even those already in the file")
    _add_bake_flags(p)

    p = sub.add_parser("export-aged", help="write each aged material's aged texture as "
                                           "an image file",
                       description="Age the scene (baking what is missing) and write each "
                                   "aged material's texture at --years as "
                                   "DIR/NAME_<material>_<object>_<years>y.png (8-bit sRGB) "
                                   "or .exr (float, linear): for other engines, glTF/USD "
                                   "export and texture painting. The .blend files are not "
                                   "changed.")
    _add_files(p)
    p.add_argument("--years", type=_years, required=True, metavar="N",
                   help="years of light exposure (>= 0)")
    p.add_argument("--output", "-o", required=True, metavar="DIR",
                   help="folder for the images (created if missing)")
    p.add_argument("--format", choices=("png", "exr"), default="png",
                   help="png: 8-bit sRGB (default); exr: float, linear Rec.709")
    p.add_argument("--rebake", action="store_true",
                   help="bake every exposure map again, even those already in the file")
    _add_bake_flags(p)

    p = sub.add_parser("info", help="what would age, material paths, emitters and doses, "
                                    "what is stale",
                       description="Describe a file's LightFade state without changing it.")
    _add_files(p)
    p.add_argument("--json", nargs="?", const="-", metavar="FILE",
                   help="print one JSON document instead of text (stdout then carries "
                        "only the JSON), or write it to FILE")
    return sub


def make_parser(prog):
    """A stand-alone parser (``prog`` as shown in messages), e.g. for ``blender -c lightfade``."""
    parser = Parser(prog=prog, description="LightFade scene commands: bake, age, render and "
                                           "describe .blend files from a pipeline.")
    add_subcommands(parser)
    return parser


def check(args):
    """Usage problems argparse cannot express, as a message (None if none)."""
    output = getattr(args, "output", None)
    if getattr(args, "in_place", False) and output:
        return "--in-place and --output exclude each other"
    if (getattr(args, "samples", None) is not None
            and str(getattr(args, "quality", None)).lower() != "custom"):
        return "--samples applies with --quality custom (the presets set their own samples)"
    if (args.action in ("bake", "age") and output and len(args.files) > 1
            and output.lower().endswith(".blend")):
        return f"--output {output}: several input files need a folder, not a .blend path"
    return None
