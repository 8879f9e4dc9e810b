"""Small objects baked together (bake/batch.py): one temporary mesh and atlas per batch,
cut into each object's own map; the same light as baking each alone."""

import bpy
import numpy as np
import pytest

from lightfade_addon.blender.bake import BakeSettings, ExposureBake, bake_exposure, batch
from lightfade_addon.blender.bake.common import TEMP_PREFIX

from test_bake_uvmaps import polygon_centre_lux

SETTINGS = BakeSettings(resolution=None, samples=16, margin=2, denoise=True,
                        texels_per_metre=200.0, max_size=64)


def test_cells_are_apart_and_inside():
    rng = np.random.default_rng(3)
    sizes = {f"o{k}": int(s) for k, s in enumerate(rng.choice([16, 24, 64, 128], 300))}
    atlases = batch.pack_cells(sizes, 3, max_size=512)
    assert len(atlases) > 1                                  # too many for one 512² atlas
    placed = {}
    for side, cells in atlases:
        assert side <= 512 and side % 8 == 0
        grid = np.zeros((side + 3, side + 3), int)
        for name, (x, y, n) in cells.items():
            assert n == sizes[name] and x + n <= side and y + n <= side
            grid[y:y + n + 3, x:x + n + 3] += 1              # the cell and its gap
        assert grid.max() == 1
        placed.update(cells)
    assert sorted(placed) == sorted(sizes)


@pytest.fixture
def cubes(blender, lf):
    """Seven 0.3 m cubes on a floor under a sun; every map 64² (the cap): eight objects
    to batch (:data:`.batch.MIN_BATCH`)."""
    bpy.ops.mesh.primitive_plane_add(size=3.0)
    floor = bpy.context.active_object
    floor.name = "Floor"
    mat = bpy.data.materials.new("Paint")
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    mat.lightfade.enabled = True
    objects = []
    for k in range(7):
        bpy.ops.mesh.primitive_cube_add(size=0.3, location=(0.5 * (k % 3) - 0.5,
                                                            0.5 * (k // 3) - 0.25, 0.17))
        cube = bpy.context.active_object
        cube.name = f"Cube{k}"
        cube.rotation_euler.z = 0.3 * k
        cube.data.materials.append(mat)
        objects.append(cube)
    objects[5].scale.x = -1.0                                # mirrored: winding kept
    lf.add_sun(strength=3.0, theta_deg=35.0)
    bpy.context.view_layer.update()
    return [floor] + objects


def _bake(objects, use_batch, seed=0):
    settings = BakeSettings(**{**SETTINGS.__dict__, "seed": seed})
    maps = bake_exposure(bpy.context.scene, objects, settings, report=lambda m: None,
                         progress=lambda f, m: None, batch=use_batch)["maps"]
    return {o.name: polygon_centre_lux(o, maps[o.name]["Sun"]) for o in objects}


def test_batched_maps_are_the_maps_baked_alone(cubes):
    job = ExposureBake(bpy.context.scene, cubes, SETTINGS, report=lambda m: None).plan()
    assert len(job.batches.atlases) == 1 and sorted(job.batches.of) == sorted(o.name for o in cubes)
    together = _bake(cubes, True)
    alone = _bake(cubes, False, seed=1)
    ratios = []
    for obj in cubes:
        faces_together, faces_alone = together[obj.name], alone[obj.name]
        lit = faces_alone > 0.2 * faces_alone.max()
        assert lit.any()
        # per face within the noise of 16 samples (measured between seeds: up to 8 %)
        np.testing.assert_allclose(faces_together[lit], faces_alone[lit], rtol=0.15)
        ratios += list(faces_together[lit] / faces_alone[lit])
        assert obj.lightfade.exposure_maps["Sun"].image.size[0] == job.sizes[obj.name]
    assert abs(np.mean(ratios) - 1.0) < 0.02                 # no bias over 31 faces


def test_batching_leaves_nothing_behind(cubes):
    meshes, objects = len(bpy.data.meshes), len(bpy.data.objects)
    hidden = {o.name: o.hide_render for o in cubes}
    _bake(cubes, True)
    assert len(bpy.data.meshes) == meshes and len(bpy.data.objects) == objects
    assert {o.name: o.hide_render for o in cubes} == hidden
    assert not [i for i in bpy.data.images if i.name.startswith(TEMP_PREFIX)]
    assert not [m for m in bpy.data.materials if m.name.startswith(TEMP_PREFIX)]


def test_materials_that_read_the_object_are_baked_alone(cubes):
    mat = cubes[1].material_slots[0].material
    assert batch.material_batch_safe(mat)
    info = mat.node_tree.nodes.new("ShaderNodeObjectInfo")
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    mat.node_tree.links.new(info.outputs["Random"], bsdf.inputs["Roughness"])
    assert not batch.material_batch_safe(mat)
    job = ExposureBake(bpy.context.scene, cubes, SETTINGS, report=lambda m: None).plan()
    assert job.batches.atlases == []


def test_the_widest_map_batched_is_a_choice(cubes):
    scene = bpy.context.scene
    assert ExposureBake(scene, cubes, SETTINGS, report=print, batch=64).plan().batches.atlases
    assert not ExposureBake(scene, cubes, SETTINGS, report=print, batch=32).plan().batches.atlases
    assert not ExposureBake(scene, cubes, SETTINGS, report=print, batch=False).plan().batches.atlases


def test_an_adaptive_bake_measures_and_reports_each_batched_object(cubes):
    """Passes and their noise are the atlas's; the report, the records and the maps are
    each object's (the noise of the atlas given to each object baked in it)."""
    settings = BakeSettings(**{**SETTINGS.__dict__, "samples": 4, "pass_samples": 2,
                               "noise_target": 0.15, "mean_target": 0.03, "max_samples": 8})
    notes = []
    result = bake_exposure(bpy.context.scene, cubes, settings, report=notes.append,
                           progress=lambda f, m: None)
    noise = result["noise"]
    assert sorted(name for name, _ in noise) == sorted(o.name for o in cubes)
    assert not any(name.startswith(TEMP_PREFIX) for name, _ in noise)
    assert all(found.samples >= 4 for found in noise.values())
    assert f'"{cubes[3].name}" <- Sun' in notes[-1]
    for obj in cubes:
        assert obj.lightfade.exposure_maps["Sun"].samples == noise[obj.name, "Sun"].samples
    together = {o.name: polygon_centre_lux(o, result["maps"][o.name]["Sun"]) for o in cubes}
    alone = _bake(cubes, False, seed=1)
    for obj in cubes:
        lit = alone[obj.name] > 0.2 * alone[obj.name].max()
        assert abs(np.mean(together[obj.name][lit] / alone[obj.name][lit]) - 1.0) < 0.15
