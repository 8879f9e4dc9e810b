"""Rendering and saving a built demo scene: Cycles settings, colour management, stills
and the saved ``.blend``."""

from __future__ import annotations

import os
import time

import bpy


def denoiser_available():
    """True if this build's Cycles has OpenImageDenoise (CPU denoising)."""
    try:
        import _cycles
    except ImportError:
        return False
    return bool(getattr(_cycles, "with_openimagedenoise", False))


#: Cycles settings of every demo render: CPU, a fixed seed (reproducible renders),
#: adaptive sampling and light paths tuned for the demo interiors.
CYCLES_SETTINGS = dict(
    device="CPU", use_adaptive_sampling=True, adaptive_threshold=0.02,
    adaptive_min_samples=0, seed=0, use_animated_seed=False,
    max_bounces=4, diffuse_bounces=3, glossy_bounces=1, transmission_bounces=2,
    transparent_max_bounces=4, volume_bounces=0,
    caustics_reflective=False, caustics_refractive=False, blur_glossy=1.0,
    sample_clamp_direct=0.0, sample_clamp_indirect=10.0, use_light_tree=True,
)


def configure_render(scene, width=640, height=400, samples=32, engine="CYCLES", *,
                     denoise=True, view_transform="AgX"):
    """Set resolution, engine and CPU Cycles light paths tuned for the demo interiors.

    Denoising (OpenImageDenoise) is used if the build has it; the seed is fixed so that
    renders are reproducible. Exposure and look are scene-specific and left as each scene
    sets them; ``view_transform`` is set (AgX by default; the swatches use Standard).
    """
    scene.render.engine = engine
    scene.render.resolution_x = width
    scene.render.resolution_y = height
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_mode = "RGB"
    scene.render.image_settings.color_depth = "8"
    scene.render.film_transparent = False
    if engine == "CYCLES":
        cy = scene.cycles
        for name, value in {**CYCLES_SETTINGS, "samples": samples}.items():
            setattr(cy, name, value)
        use_dn = denoise and denoiser_available()
        cy.use_denoising = use_dn
        if use_dn:
            cy.denoiser = "OPENIMAGEDENOISE"
            cy.denoising_input_passes = "RGB_ALBEDO_NORMAL"
            cy.denoising_prefilter = "ACCURATE"
    elif "EEVEE" in engine:
        scene.eevee.taa_render_samples = samples
    scene.view_settings.view_transform = view_transform
    scene.display_settings.display_device = "sRGB"
    return scene


def view_settings(scene):
    """The scene's colour management as a dict (``view_transform``, ``look``, ``exposure``),
    so that a caller that re-runs :func:`configure_render` can put the scene's own back
    with :func:`apply_view_settings`."""
    v = scene.view_settings
    return dict(view_transform=v.view_transform, look=v.look, exposure=round(v.exposure, 3))


def apply_view_settings(scene, view):
    """Set ``view_transform``, ``look`` and ``exposure`` from a :func:`view_settings` dict."""
    v = scene.view_settings
    v.view_transform = view["view_transform"]
    v.look = view["look"]
    v.exposure = view["exposure"]


def render_still(path, camera=None, scene=None):
    """Render the scene (optionally through ``camera``, an object or its name) to a PNG.

    Returns the elapsed render time in seconds.
    """
    scene = scene or bpy.context.scene
    if camera is not None:
        scene.camera = bpy.data.objects[camera] if isinstance(camera, str) else camera
    scene.render.filepath = os.path.abspath(path)
    t0 = time.perf_counter()
    bpy.ops.render.render(write_still=True, scene=scene.name)
    return time.perf_counter() - t0


def save_blend(path):
    """Pack every image into the file and save it as ``path``."""
    for img in bpy.data.images:
        if img.source in {"GENERATED", "FILE"} and img.packed_file is None and img.has_data:
            img.pack()
    bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(path), compress=True)
