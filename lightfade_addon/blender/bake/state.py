"""Everything a bake changes in the file, put back on exit (normal, error or cancel).

:class:`BakeState` records each change as an undo callable (run in reverse on exit) and
owns the temporary materials, images and node trees the bake makes.  The render, Cycles
and bake settings are set in one place, :meth:`BakeState.configure`: the Cycles bake
operator then takes all its options from the scene.
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import sys

import bpy

from ..undo import Undo
from .common import TEMP_PREFIX


def _snapshot_rna(struct, names):
    return {n: getattr(struct, n) for n in names if hasattr(struct, n)}


def _restore_rna(struct, values):
    for name, value in values.items():
        with contextlib.suppress(AttributeError, TypeError, ValueError):
            setattr(struct, name, value)


_RENDER_KEYS = ("engine", "use_lock_interface")
_BAKE_KEYS = ("margin", "margin_type", "use_clear", "use_selected_to_active", "target",
              "use_pass_direct", "use_pass_indirect", "use_pass_color", "use_cage",
              "cage_extrusion", "max_ray_distance", "normal_space", "save_mode")
_CYCLES_KEYS = ("device", "samples", "use_adaptive_sampling", "use_denoising", "bake_type",
                "time_limit", "seed", "use_animated_seed", "sample_clamp_direct",
                "sample_clamp_indirect")


class BakeState(Undo):
    """Record-and-restore scope of one bake.

    Covers render engine, Cycles and bake settings, the world, the view layer's material
    override, selection, active object, and every change made through :meth:`set` or
    :meth:`push`; deletes the temporary materials, images and node trees it made.
    """

    def __init__(self, scene, view_layer):
        super().__init__()
        self.scene = scene
        self.view_layer = view_layer
        self.temp_materials = []
        self.temp_images = []

    def new_image(self, name, width, height=None):
        """A temporary float image holding data (no view transform), removed on exit."""
        img = bpy.data.images.new(TEMP_PREFIX + name, width, height or width, alpha=False,
                                  float_buffer=True)
        img.colorspace_settings.is_data = True
        self.temp_images.append(img)
        return img

    def keep(self, image):
        """``image`` outlives the bake (it became an exposure map)."""
        self.temp_images.remove(image)

    def __enter__(self):
        scene, vl = self.scene, self.view_layer
        render = _snapshot_rna(scene.render, _RENDER_KEYS)
        bake = _snapshot_rna(scene.render.bake, _BAKE_KEYS)
        world = scene.world
        self.push(lambda: _restore_rna(scene.render, render))
        self.push(lambda: _restore_rna(scene.render.bake, bake))
        self.push(lambda: setattr(scene, "world", world))
        scene.render.engine = "CYCLES"  # creates scene.cycles settings if missing
        cycles = _snapshot_rna(scene.cycles, _CYCLES_KEYS)
        self.push(lambda: _restore_rna(scene.cycles, cycles))
        override = vl.material_override
        self.push(lambda: setattr(vl, "material_override", override))
        vl.material_override = None
        active = vl.objects.active
        selected = [o for o in vl.objects if o.select_get()]

        def restore_selection():
            for o in vl.objects:
                o.select_set(False)
            for o in selected:
                with contextlib.suppress(ReferenceError, RuntimeError):
                    o.select_set(True)
            with contextlib.suppress(ReferenceError):
                vl.objects.active = active

        self.push(restore_selection)
        return self

    def __exit__(self, exc_type, exc, tb):
        errors = self.unwind()
        for mat in self.temp_materials:
            with contextlib.suppress(ReferenceError):
                bpy.data.materials.remove(mat)
        for img in self.temp_images:
            with contextlib.suppress(ReferenceError):
                bpy.data.images.remove(img)
        self.temp_materials.clear()
        self.temp_images.clear()
        if errors and exc_type is None:
            raise errors[0]
        return False

    def configure(self, samples, margin, seed=0):
        """DIFFUSE pass with direct and indirect light and no colour, into the active
        Image Texture nodes, kept in memory: the one place bake options are set. Cycles
        bakes on the scene's own device (Render Properties > Device: *GPU Compute* bakes
        on the GPUs chosen in Preferences > System; Cycles falls back to the CPU where
        there is none).

        Sample clamping is off: Cycles clamps a path's contribution *before* the pass is
        divided by the baked texel's colour (:mod:`.surface`'s probe, which need not be
        the surface's: a dark one is at least 0.25), so the scene's clamp (Blender's
        default: 10 on indirect light) would cut the rare bright paths through a
        lampshade or glass where a plain bake would not; without a clamp both are the unbiased
        irradiance (``docs/bake.md``, "Light through shades").

        The bake operator does not take its pass filter from the scene, so the type and
        pass filter are also kept for :meth:`bake`."""
        scene = self.scene
        cycles, bake = scene.cycles, scene.render.bake
        for struct, name, value in (
            (cycles, "samples", int(samples)),
            (cycles, "use_adaptive_sampling", False),
            (cycles, "use_denoising", False),
            (cycles, "time_limit", 0.0),
            (cycles, "seed", int(seed)),
            (cycles, "use_animated_seed", False),
            (cycles, "sample_clamp_direct", 0.0),
            (cycles, "sample_clamp_indirect", 0.0),
            (cycles, "bake_type", "DIFFUSE"),
            (bake, "margin", int(margin)),
            (bake, "margin_type", "EXTEND"),
            (bake, "use_clear", True),
            (bake, "use_selected_to_active", False),
            (bake, "target", "IMAGE_TEXTURES"),
            (bake, "save_mode", "INTERNAL"),
            (bake, "use_pass_direct", True),
            (bake, "use_pass_indirect", True),
            (bake, "use_pass_color", False),
        ):
            self.set(struct, name, value)
        self.bake_args = {"type": "DIFFUSE", "pass_filter": {"DIRECT", "INDIRECT"}}

    def bake(self):
        """One Cycles bake of the selected objects, quietly; the operator's result set."""
        with quiet_stdout():
            return bpy.ops.object.bake(**self.bake_args)

    def select_only(self, objects):
        """Select exactly ``objects`` (the first one active); restored on exit."""
        vl = self.view_layer
        for o in vl.objects:
            if o.select_get():
                o.select_set(False)
        for o in objects:
            if o.hide_get(view_layer=vl):
                o.hide_set(False, view_layer=vl)
                self.push(lambda o=o: o.hide_set(True, view_layer=vl))
            self.set(o, "hide_render", False)
            o.select_set(True)
        vl.objects.active = objects[0]


@contextlib.contextmanager
def quiet_stdout():
    """Hide what C code prints to stdout meanwhile (POSIX; elsewhere nothing changes).

    Blender reports "Baking map saved to internal image, save it externally or pack it"
    after every bake into an image, whatever its settings (``object_bake_api.cc``), and
    prints the report in background mode.  Errors still reach Python as exceptions.
    """
    try:
        libc = ctypes.CDLL(None)
        fd = sys.stdout.fileno()
    except (OSError, AttributeError, ValueError):
        yield
        return
    sys.stdout.flush()
    libc.fflush(None)
    saved = os.dup(fd)
    null = os.open(os.devnull, os.O_WRONLY)
    os.dup2(null, fd)
    try:
        yield
    finally:
        libc.fflush(None)
        os.dup2(saved, fd)
        os.close(saved)
        os.close(null)
