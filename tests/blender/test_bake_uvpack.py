"""LightFadeUV for many islands (bake/uvpack.py): the islands folded onto themselves
found all at once, the overlap test that stops early, and a scatter of stacked copies
packed whole without overlaps at one texel density."""

import bpy
import numpy as np

from lightfade_addon.blender.bake import raster, uvmaps, uvpack


def _one_island_at_a_time(tri, island, size):
    """The former test: each island rasterised alone on the whole map."""
    bad = []
    for label in np.unique(island):
        count, _ = raster.rasterise(tri[island == label], size)
        if np.count_nonzero(count > 1) > max(2, 1e-3 * np.count_nonzero(count)):
            bad.append(int(label))
    return bad


def _random_islands(rng, count):
    """Islands of two triangles each (a quad), some folded: the second triangle turned
    back over the first; all of them overlapping each other."""
    tris, labels = [], []
    for k in range(count):
        centre = rng.uniform(0.2, 0.8, 2)
        half = rng.uniform(0.01, 0.2)
        a, b, c, d = (centre + half * np.array(p) for p in ((-1, -1), (1, -1), (1, 1), (-1, 1)))
        folded = k % 3 == 0
        second = (a, c, b + (0.4 * (c - a) if folded else 0)) if folded else (a, c, d)
        tris += [(a, b, c), second]
        labels += [k, k]
    return np.array(tris), np.array(labels)


def test_folded_islands_are_those_rasterised_one_at_a_time():
    rng = np.random.default_rng(7)
    tri, island = _random_islands(rng, 60)
    for size in (64, 512):
        expected = _one_island_at_a_time(tri, island, size)
        assert expected and len(expected) < 60           # some folded, not all
        assert uvpack.self_overlapping_islands(tri, island, size) == expected


def test_overlap_found_early_and_late():
    quad = np.array([[(0.1, 0.1), (0.9, 0.1), (0.9, 0.9)], [(0.1, 0.1), (0.9, 0.9), (0.1, 0.9)]])
    stacked = np.concatenate([quad] * 50)                 # 50 copies: surely overlapping
    assert uvpack.surely_overlapping(stacked, 256)
    assert uvpack.overlaps(stacked, 256)
    assert not uvpack.surely_overlapping(np.concatenate([quad] * 1), 256)
    assert not uvpack.overlaps(quad, 256)
    small = quad * 0.4                                     # two copies, one moved a little
    assert not uvpack.surely_overlapping(np.concatenate([small, small + 0.1]), 256)
    assert uvpack.overlaps(np.concatenate([small, small + 0.1]), 256)
    assert not uvpack.overlaps(np.concatenate([small, small + 0.5]), 256)


def _stacked_cubes(count):
    """One mesh of ``count`` 0.12 m cubes side by side sharing one UV layout."""
    bpy.ops.mesh.primitive_cube_add(size=0.12)
    template = bpy.context.active_object
    co = np.array([v.co for v in template.data.vertices])
    polys = [list(p.vertices) for p in template.data.polygons]
    uvs = np.array([loop.uv for loop in template.data.uv_layers[0].data])
    bpy.data.objects.remove(template)
    verts, faces = [], []
    for i in range(count):
        base = len(verts)
        verts += list(co + (0.3 * (i % 20), 0.3 * (i // 20), 0.06))
        faces += [[base + j for j in p] for p in polys]
    mesh = bpy.data.meshes.new("Scatter")
    mesh.from_pydata(verts, [], faces)
    mesh.uv_layers.new(name="UVMap").data.foreach_set("uv", np.tile(uvs, (count, 1)).ravel())
    obj = bpy.data.objects.new("Scatter", mesh)
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.update()
    return obj


def test_a_scatter_of_stacked_copies_is_packed_whole(blender):
    obj = _stacked_cubes(300)
    size = 512
    uvmaps.make_unique_uv(obj, bpy.context.view_layer, size)
    tri, poly = uvmaps.triangle_uvs(obj.data, "LightFadeUV")
    count, _ = raster.rasterise(tri, size)
    assert np.count_nonzero(count > 1) <= 2                # no texel shared
    assert raster.outside_unit_square(tri) == 0
    island = uvmaps.polygon_islands(obj.data, "LightFadeUV")
    assert island.max() + 1 == 300                         # each copy one island, whole
    e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    uv_area = np.bincount(island[poly], 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]))
    assert uv_area.std() / uv_area.mean() < 0.02           # one texel density (same cubes)
    assert np.count_nonzero(count) / size ** 2 > 0.25      # used (a cross in its box: ~half)
