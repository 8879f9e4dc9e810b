"""The UV map exposure is baked on: a made ``LightFadeUV`` keeps the artist's islands and
uses the map; a re-bake keeps it and its size; the estimate sizes what the bake makes."""

import math

import bpy
import numpy as np
import pytest

from lightfade_addon.blender.bake import BakeSettings, bake_exposure
from lightfade_addon.blender.bake import raster, uvmaps
from lightfade_addon.blender.bake.sizing import planned_map

from conftest import add_sun

#: Density-sized maps (no fixed resolution), 4 samples, no denoising: quick.
SIZED = BakeSettings(resolution=None, samples=4, margin=2, denoise=False,
                     texels_per_metre=48.0, max_size=256)


def folded_cloth(name="Cloth", nx=24, ny=12, width=2.0, height=1.2, two_sided=True,
                 mirrored=False):
    """A curtain-like sheet with folds along x (hanging in the xz plane, folds in y).

    Its UV map is the flat grid in 0-1.  ``two_sided``: a back layer 1 cm behind with the
    same UVs (islands overlapping each other, as a glTF curtain has).  ``mirrored``: u
    folded at the middle (``u = |2x - 1|``), one island covering itself twice.
    """
    xs, zs = np.linspace(0, 1, nx + 1), np.linspace(0, 1, ny + 1)
    gx, gz = np.meshgrid(xs, zs, indexing="ij")
    y = 0.08 * np.sin(gx * 2 * math.pi * 5)
    layers = [0.0, 0.01] if two_sided else [0.0]
    verts, faces, uvs = [], [], []
    for k, dy in enumerate(layers):
        base = len(verts)
        verts += [((gx[i, j] - 0.5) * width, y[i, j] + dy, gz[i, j] * height)
                  for i in range(nx + 1) for j in range(ny + 1)]
        for i in range(nx):
            for j in range(ny):
                a = base + i * (ny + 1) + j
                quad = (a, a + ny + 1, a + ny + 2, a + 1)
                face = quad if k == 0 else quad[::-1]
                faces.append(face)
                for v in face:
                    u, w = xs[(v - base) // (ny + 1)], zs[(v - base) % (ny + 1)]
                    uvs.append((abs(2 * u - 1) if mirrored else u, w))
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts, [], faces)
    layer = mesh.uv_layers.new(name="UVMap")
    # from_pydata keeps the face corner order given, so the loops follow ``uvs``
    layer.data.foreach_set("uv", np.asarray(uvs, dtype=np.float32).ravel())
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    obj.location.z = 0.2
    return obj


def uv_array(obj, name):
    data = obj.data.uv_layers[name].data
    uv = np.empty(len(data) * 2, dtype=np.float32)
    data.foreach_get("uv", uv)
    return uv


def fill_and_overlap(obj, name, size=256):
    tri, _ = uvmaps.triangle_uvs(obj.data, name)
    count, _ = raster.rasterise(tri, size)
    return np.count_nonzero(count) / size ** 2, np.count_nonzero(count > 1)


@pytest.fixture
def cloth_scene(blender):
    add_sun(theta_deg=30.0)
    return folded_cloth()


class TestMadeMap:
    def test_islands_overlapping_each_other_are_packed_whole(self, cloth_scene):
        cloth = cloth_scene
        uvmaps.make_unique_uv(cloth, bpy.context.view_layer, 256)
        islands = uvmaps.polygon_islands(cloth.data, "LightFadeUV")
        assert islands.max() + 1 == 2              # front and back, each one island
        fill, overlap = fill_and_overlap(cloth, "LightFadeUV")
        assert overlap == 0 and fill > 0.45        # packed: the map is used
        assert cloth.data.uv_layers.active.name == "UVMap"
        assert raster.outside_unit_square(uvmaps.triangle_uvs(cloth.data, "LightFadeUV")[0]) == 0

    def test_an_island_folded_onto_itself_is_unwrapped_anew(self, blender):
        cloth = folded_cloth(two_sided=False, mirrored=True)
        assert fill_and_overlap(cloth, "UVMap")[1] > 1000
        uvmaps.make_unique_uv(cloth, bpy.context.view_layer, 256)
        fill, overlap = fill_and_overlap(cloth, "LightFadeUV")
        assert overlap == 0 and fill > 0.3

    def test_tiled_uvs_are_fitted_into_the_square(self, blender):
        cloth = folded_cloth(two_sided=False)
        data = cloth.data.uv_layers["UVMap"].data
        data.foreach_set("uv", uv_array(cloth, "UVMap") * 3.0 + 1.0)   # 1..4: tiled
        uvmaps.make_unique_uv(cloth, bpy.context.view_layer, 256)
        tri, _ = uvmaps.triangle_uvs(cloth.data, "LightFadeUV")
        assert raster.outside_unit_square(tri) == 0 and fill_and_overlap(cloth, "LightFadeUV")[0] > 0.4


class TestRebake:
    def test_a_rebake_keeps_the_made_map_and_its_size(self, cloth_scene):
        cloth = cloth_scene
        depsgraph = bpy.context.evaluated_depsgraph_get()
        planned, plan = planned_map(cloth, depsgraph, SIZED)
        assert plan.make and plan.uv_name == "LightFadeUV"
        first = bake_exposure(bpy.context.scene, [cloth], SIZED)
        size = tuple(first["maps"]["Cloth"]["Sun"].size)
        assert size == (planned, planned)               # the estimate's size, made
        made = uv_array(cloth, "LightFadeUV").copy()
        depsgraph = bpy.context.evaluated_depsgraph_get()
        again, plan = planned_map(cloth, depsgraph, SIZED)
        assert not plan.make and again == planned
        second = bake_exposure(bpy.context.scene, [cloth], SIZED)
        assert second["notes"] == []
        assert tuple(second["maps"]["Cloth"]["Sun"].size) == size
        np.testing.assert_array_equal(uv_array(cloth, "LightFadeUV"), made)
        assert cloth.lightfade.uv_map == "LightFadeUV" and cloth.data.uv_layers.active.name == "UVMap"

    def test_estimate_sizes_are_the_bake_sizes(self, cloth_scene):
        """A mesh with its own unique UVs, one whose map will be made, one without UVs."""
        bpy.ops.mesh.primitive_plane_add(size=3.0, location=(0, -1, 0))
        floor = bpy.context.active_object
        bpy.ops.mesh.primitive_uv_sphere_add(radius=0.3, location=(1.5, -1, 0.3))
        ball = bpy.context.active_object
        ball.data.uv_layers.remove(ball.data.uv_layers[0])
        objects = [cloth_scene, floor, ball]
        settings = BakeSettings(**{**SIZED.__dict__, "unwrap": True})
        depsgraph = bpy.context.evaluated_depsgraph_get()
        planned = {o.name: planned_map(o, depsgraph, settings)[0] for o in objects}
        maps = bake_exposure(bpy.context.scene, objects, settings)["maps"]
        made = {name: maps[name]["Sun"].size[0] for name in planned}
        assert made == planned
        assert len(set(made.values())) == 3             # three different sizes


def polygon_centre_lux(obj, image):
    """Lux of ``image`` at the centroid of each polygon's first triangle (bilinear), and
    those centroids' world positions."""
    from scipy.ndimage import map_coordinates

    mesh = obj.data
    tri, poly = uvmaps.triangle_uvs(mesh, obj.lightfade.uv_map)
    first = np.unique(poly, return_index=True)[1]
    uv = tri[first].mean(axis=1)
    w, h = image.size
    px = np.empty(w * h * 4, np.float32)
    image.pixels.foreach_get(px)
    lux = px.reshape(h, w, 4)[..., 0]
    return map_coordinates(lux, [uv[:, 1] * h - 0.5, uv[:, 0] * w - 0.5], order=1)


class TestSmoothOnFolds:
    @pytest.mark.slow
    def test_default_bake_of_a_folded_cloth_in_strips_is_close_to_many_samples(
            self, cloth_scene, monkeypatch):
        """A two-sided folded cloth without UVs (Smart UV Project, packed) under a sun and
        a wide area lamp: the default 8-sample bake against 256 samples at the polygon
        centres.  Smoothing over 3D neighbours across islands takes the 95th percentile
        of the error down (measured: sun 6.3 % -> 5.6 %, lamp 17.1 % -> 15.3 %).  A study
        (~15 s): the filter's own behaviour is tested in test_denoise.py."""
        from lightfade_addon.blender.bake import filter3d

        cloth = cloth_scene
        cloth.data.uv_layers.remove(cloth.data.uv_layers[0])
        lamp = bpy.data.objects.new("Lamp", bpy.data.lights.new("Lamp", "AREA"))
        lamp.data.energy, lamp.data.size = 200.0, 3.0        # a wide soft light: noisy
        lamp.location = (0.0, -0.8, 2.2)
        bpy.context.scene.collection.objects.link(lamp)
        base = dict(SIZED.__dict__, unwrap=True, texels_per_metre=40.0)
        reference = {group: polygon_centre_lux(cloth, image) for group, image in bake_exposure(
            bpy.context.scene, [cloth], BakeSettings(**dict(base, samples=256)))["maps"]["Cloth"].items()}
        default = BakeSettings(**dict(base, samples=8, denoise=True))

        def errors():
            maps = bake_exposure(bpy.context.scene, [cloth], default)["maps"]["Cloth"]
            out = {}
            for group, image in maps.items():
                ref = reference[group]
                got = polygon_centre_lux(cloth, image)
                lit = ref > 0.05 * np.percentile(ref, 99)
                out[group] = np.percentile(np.abs(got - ref)[lit] / ref[lit], 95)
            return out

        with_filter = errors()
        monkeypatch.setattr(filter3d, "smooth_on_surface", lambda raw, guide, *a, **k: guide)
        without = errors()
        assert with_filter["Sun"] < 0.08 and with_filter["Lamp"] < 0.2
        assert all(with_filter[g] < 0.95 * without[g] for g in with_filter)
