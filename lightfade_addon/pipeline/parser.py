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
    """Add ``bake``, ``age``, ``render-years``, ``export-aged``, ``info`` and the farm
    commands (:func:`add_farm_subcommands`) to ``parser``.

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
    add_farm_subcommands(sub)
    return sub


def _frames(text):
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"a frame must be a whole number, got {text!r}") from None
    return value


def _positive(kind, what):
    def parse(text):
        try:
            value = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{what} must be a number, got {text!r}") from None
        if not value > 0 or not math.isfinite(value):
            raise argparse.ArgumentTypeError(f"{what} must be > 0, got {text!r}")
        return value
    return parse


def add_farm_subcommands(sub):
    """``farm-job`` and the commands its OpenJD steps run (``docs/farm.md``)."""
    p = sub.add_parser("farm-job", help="write an OpenJD job bundle: the bake split into "
                                        "tasks, merge, aging and the years time-lapse",
                       description="Write an Open Job Description job bundle (OUT/template."
                                   "yaml) for a render farm: Bake tasks of one light group x "
                                   "a chunk of objects (sized from the bake's estimate), "
                                   "Merge, and with --years Age and a Render step over the "
                                   "frames of the years time-lapse. The .blend is not changed.")
    p.add_argument("files", nargs=1, metavar="FILE.blend", help="the scene to bake")
    p.add_argument("--out", required=True, metavar="DIR",
                   help="the bundle's folder (created if missing)")
    p.add_argument("--task-minutes", type=_positive(float, "--task-minutes"), default=5.0,
                   metavar="M", help="about how long one Bake task should run (default 5)")
    p.add_argument("--years", type=_years, metavar="N",
                   help="add Age and Render: a time-lapse from 0 to N years")
    p.add_argument("--frames", type=_positive(int, "--frames"), metavar="COUNT",
                   help="frames of the time-lapse from the scene's start frame (default: "
                        "one per year and one for 0 years)")
    _add_bake_flags(p)

    p = sub.add_parser("farm-bake", help="(a farm-job task) bake one light group for one "
                                         "chunk of objects",
                       description="Bake one light group for one chunk of the job's objects "
                                   "and write their maps to MAPS (atomically). The .blend is "
                                   "only read.")
    p.add_argument("files", nargs=1, metavar="FILE.blend", help="the job's scene")
    p.add_argument("--plan", required=True, metavar="PLAN.json", help="the job's plan")
    p.add_argument("--group", required=True, metavar="NAME", help="the light group")
    p.add_argument("--chunk", required=True, type=int, metavar="K", help="the chunk (0...)")
    p.add_argument("--maps", required=True, metavar="DIR", help="the job's maps folder")

    p = sub.add_parser("farm-merge", help="(a farm-job task) check every Bake task's maps "
                                          "and save the scene with them",
                       description="Check the maps of every Bake task of the plan (a missing "
                                   "or mismatched map is refused, naming the task to rerun) "
                                   "and save the scene with them as --output.")
    p.add_argument("files", nargs=1, metavar="FILE.blend", help="the job's scene")
    p.add_argument("--plan", required=True, metavar="PLAN.json", help="the job's plan")
    p.add_argument("--maps", required=True, metavar="DIR", help="the job's maps folder")
    p.add_argument("--output", "-o", required=True, metavar="PATH.blend",
                   help="the merged file (the scene stays read-only)")

    p = sub.add_parser("farm-age", help="(a farm-job task) age and key the years over frames",
                       description="Age the enabled materials to --years, key the years from "
                                   "0 at the first frame to --years at the last, and save as "
                                   "--output.")
    p.add_argument("files", nargs=1, metavar="FILE.blend", help="the merged file")
    p.add_argument("--years", type=_years, required=True, metavar="N", help="years at the end")
    p.add_argument("--frames", type=_frames, nargs=2, required=True, metavar=("FIRST", "LAST"),
                   help="the time-lapse's first and last frame")
    p.add_argument("--output", "-o", required=True, metavar="PATH.blend", help="the aged file")


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
