"""The command line shared by the scene builders (``python -m scenes.room out.blend``)."""

from __future__ import annotations

import argparse

import bpy

from .render import apply_view_settings, configure_render, render_still


def main(build, description, argv=None, default_resolution=1024):
    """CLI shared by the scene modules: build, save, optionally render previews."""
    p = argparse.ArgumentParser(description=description)
    p.add_argument("output", nargs="?", help="where to save the .blend (images packed)")
    p.add_argument("--resolution", type=int, default=default_resolution,
                   help="texture size of the largest albedo image (texels)")
    p.add_argument("--render", metavar="PNG", help="also render the main camera to this PNG")
    p.add_argument("--samples", type=int, default=32)
    p.add_argument("--size", type=int, nargs=2, default=(640, 400), metavar=("W", "H"))
    args = p.parse_args(argv)
    info = build(path=args.output, resolution=args.resolution)
    if args.render:
        scene = bpy.context.scene
        configure_render(scene, *args.size, samples=args.samples)
        apply_view_settings(scene, info["view"])
        t = render_still(args.render, camera=info["camera"])
        print(f"rendered {args.render} in {t:.1f} s")
    for k, v in info.items():
        print(f"{k}: {v}")
    return info
