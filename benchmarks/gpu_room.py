"""The ten-material room of :mod:`benchmarks.live_room` baked and rendered on a GPU.

    ./run py -m benchmarks.gpu_room --device OPTIX        # or CUDA, HIP, ONEAPI, METAL

Where a machine has a GPU, this checks the aged material and the bakes on Cycles GPU
and prints, side by side in one process:

* **bake** — wall time of Bake Exposure on the GPU and on the CPU (every core), and
  how far the two bakes' maps differ (they are the same estimate of the same light);
* **render** — wall time of the aged room at 25 years on the GPU, of the same render
  after Reset, and their ratio; the GPU's aged render against the CPU's (ΔE00 p50 /
  p99 of the pixels): the node group computes the same on both devices.

The first GPU render or bake includes the kernels' compile (OptiX and CUDA compile
for a GPU that Blender ships no binary for), reported apart as a warm-up render.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import bpy  # noqa: E402  (first: it puts Blender's modules on the path)

from benchmarks.live_room import build, render  # noqa: E402


def use_gpu(scene, backend):
    """Cycles on every ``backend`` GPU (Preferences > System); the device names."""
    if backend == "CPU":                 # a dry run of this script where there is no GPU
        return ["none (CPU)"]
    prefs = bpy.context.preferences.addons["cycles"].preferences
    prefs.compute_device_type = backend
    prefs.refresh_devices()
    names = []
    for dev in prefs.devices:
        dev.use = dev.type == backend
        if dev.use:
            names.append(dev.name)
    if not names:
        raise SystemExit(f"no {backend} device: Cycles sees "
                         f"{[(d.type, d.name) for d in prefs.devices]}")
    scene.cycles.device = "GPU"
    return names


def timed_bake(scene, samples):
    from lightfade_addon import api

    t0 = time.perf_counter()
    api.bake(scene, quality="CUSTOM", samples=samples)
    return time.perf_counter() - t0


def map_pixels(scene):
    """{image name: pixels} of every exposure map."""
    out = {}
    for o in scene.objects:
        if o.type != "MESH":
            continue
        for m in o.lightfade.exposure_maps:
            img = m.image
            px = np.empty(len(img.pixels), np.float32)
            img.pixels.foreach_get(px)
            out[img.name] = px.reshape(-1, 4)[:, 0]
    return out


def gpu_render(scene, samples, res, folder, name):
    """Wall seconds and pixels of a GPU render (:func:`live_room.render` forces CPU)."""
    scene.render.engine = "CYCLES"
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False
    scene.cycles.device = "GPU"
    scene.render.resolution_x, scene.render.resolution_y = res
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "OPEN_EXR"
    path = os.path.join(folder, name + ".exr")
    scene.render.filepath = path
    t0 = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    wall = time.perf_counter() - t0
    image = bpy.data.images.load(path)
    px = np.empty(len(image.pixels), np.float32)
    image.pixels.foreach_get(px)
    bpy.data.images.remove(image)
    return wall, px.reshape(res[1], res[0], 4)


def delta_E(a, b):
    from lightfade_addon.core.colour.colorimetry import XYZ_to_Lab, delta_E_2000, linear_srgb_to_XYZ

    def lab(p):
        return XYZ_to_Lab(linear_srgb_to_XYZ(np.clip(p[..., :3], 0, None).reshape(-1, 3)))

    return delta_E_2000(lab(a), lab(b))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--device", default="OPTIX", help="OPTIX, CUDA, HIP, ONEAPI, METAL (CPU: a dry run)")
    parser.add_argument("--size", type=int, default=1024, help="texture side (px)")
    parser.add_argument("--density", type=float, default=48.0, help="exposure texels per metre")
    parser.add_argument("--bake-samples", type=int, default=64)
    parser.add_argument("--samples", type=int, default=128, help="render samples")
    parser.add_argument("--res", type=int, nargs=2, default=(960, 540))
    args = parser.parse_args(argv)
    from lightfade_addon import api

    folder = tempfile.mkdtemp(prefix="lf_gpu_")
    scene = build(args.size)
    scene.lightfade_bake.texels_per_metre = args.density
    names = use_gpu(scene, args.device)
    print(f"Cycles {args.device}: {', '.join(names)}; CPU threads {os.cpu_count()}", flush=True)
    res = tuple(args.res)

    t_first = timed_bake(scene, args.bake_samples)             # includes the kernels' compile
    t_gpu = timed_bake(scene, args.bake_samples)
    gpu_maps = map_pixels(scene)
    scene.cycles.device = "CPU"
    t_cpu = timed_bake(scene, args.bake_samples)
    cpu_maps = map_pixels(scene)
    rel = np.concatenate([np.abs(gpu_maps[k] - cpu_maps[k]) / max(float(cpu_maps[k].max()), 1e-9)
                          for k in cpu_maps])
    print(f"bake {args.bake_samples} spp, {len(cpu_maps)} maps: GPU {t_gpu:.1f} s "
          f"(first {t_first:.1f} s with the kernels' compile), CPU {t_cpu:.1f} s: "
          f"{t_cpu / t_gpu:.1f}x faster on the GPU; GPU vs CPU maps differ by "
          f"p50 {np.percentile(rel, 50):.3f} / p99 {np.percentile(rel, 99):.3f} of each map's "
          f"peak (sampling noise)", flush=True)

    scene.cycles.device = "GPU"
    api.age_scene(scene, years=25.0)
    warm, _ = gpu_render(scene, 4, (64, 36), folder, "warm")
    aged_gpu, reset_gpu = [], []
    for k in range(2):
        w, px_gpu = gpu_render(scene, args.samples, res, folder, f"aged{k}")
        aged_gpu.append(w)
        api.reset(scene)
        reset_gpu.append(gpu_render(scene, args.samples, res, folder, f"reset{k}")[0])
        api.age_scene(scene, years=25.0)
    _cpu_s, cpu_wall, px_cpu = render(scene, "CYCLES", args.samples, res, folder, "aged_cpu")
    dE = delta_E(px_gpu, px_cpu)
    print(f"render {res[0]}x{res[1]}, {args.samples} spp, wall: GPU aged at 25 years "
          f"{min(aged_gpu):.2f} s, after Reset {min(reset_gpu):.2f} s: "
          f"{min(aged_gpu) / min(reset_gpu):.2f}x (warm-up {warm:.1f} s); the same aged render "
          f"on the CPU {cpu_wall:.2f} s", flush=True)
    print(f"aged render GPU vs CPU: ΔE00 p50 {np.percentile(dE, 50):.3f} / p99 "
          f"{np.percentile(dE, 99):.3f} / max {dE.max():.3f}", flush=True)


if __name__ == "__main__":
    main()
