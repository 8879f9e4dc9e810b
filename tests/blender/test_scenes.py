"""The scripted demo scenes (``scenes/``): roles, LightFade tags, image-fed albedo with
non-overlapping UVs, light calibration, the reveal state, saving, and one tiny render.

Scenes are built at small texture sizes so that the whole module runs in a few seconds.
"""

import math
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

bpy = pytest.importorskip("bpy")
from mathutils import Vector  # noqa: E402

from scenes import cli, meshes, render  # noqa: E402
from scenes import common as C  # noqa: E402
from scenes import gallery, room, swatches, textures as T  # noqa: E402

pytestmark = pytest.mark.blender

SCENES = {"room": room, "gallery": gallery, "swatches": swatches}
ROLES = {
    "room": ("floor", "rug", "dresser", "poster", "curtain"),
    "gallery": (),
    "swatches": ("chart", "card", "board"),
}


@pytest.fixture(autouse=True)
def quick_resets(monkeypatch, lf):
    """The builders start from an empty factory file (``scenes.common.reset``); conftest's
    ``reset_file`` gives the same file in a tenth of the time."""
    def reset():
        lf.reset_file()
        return bpy.context.scene

    monkeypatch.setattr(C, "reset", reset)
    yield
    lf.reset_file()


@pytest.fixture(params=sorted(SCENES))
def built(request):
    """(name, module, info) of a freshly built scene with 128-texel textures."""
    module = SCENES[request.param]
    info = module.build(resolution=128)
    return request.param, module, info


def _base_color_image(mat):
    bsdf = next(n for n in mat.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
    links = bsdf.inputs["Base Color"].links
    assert links, f"{mat.name}: Base Color is not linked"
    node = links[0].from_node
    assert node.type == "TEX_IMAGE", f"{mat.name}: Base Color fed by {node.type}"
    return node.image


def _cross2(a, b):
    """z of the cross product of two 2-D vectors (numpy 2 rejects 2-D ``np.cross``)."""
    return a[0] * b[1] - a[1] * b[0]


def _uv_coverage(mesh, n=256):
    """How many faces cover each of n x n texel centres (strictly inside, so shared edges count once)."""
    uv = np.empty(len(mesh.loops) * 2, dtype=np.float64)
    mesh.uv_layers.active.data.foreach_get("uv", uv)
    uv = uv.reshape(-1, 2)
    count = np.zeros((n, n), dtype=np.int32)
    centres = (np.arange(n) + 0.5) / n
    for poly in mesh.polygons:
        p = uv[list(poly.loop_indices)]
        if abs(_cross2(p[1] - p[0], p[-1] - p[0])) < 1e-12:
            continue
        sign = np.sign(sum(_cross2(p[i], p[(i + 1) % len(p)]) for i in range(len(p))))
        i0, i1 = np.searchsorted(centres, [p[:, 0].min(), p[:, 0].max()])
        j0, j1 = np.searchsorted(centres, [p[:, 1].min(), p[:, 1].max()])
        U, V = np.meshgrid(centres[i0:i1], centres[j0:j1])
        inside = np.ones(U.shape, dtype=bool)
        for a, b in zip(p, np.roll(p, -1, axis=0)):
            inside &= sign * ((b[0] - a[0]) * (V - a[1]) - (b[1] - a[1]) * (U - a[0])) > 1e-9
        count[j0:j1, i0:i1] += inside
    return count


class TestBuild:
    def test_returns_roles_that_exist(self, built):
        name, _, info = built
        for key in ("camera", "cameras", "lights", "materials") + ROLES[name]:
            assert key in info, f"{name}: no {key!r} in {sorted(info)}"
        for key in ("camera",) + ROLES[name]:
            assert info[key] in bpy.data.objects
        for cam in info["cameras"]:
            assert bpy.data.objects[cam].type == "CAMERA"
        assert bpy.context.scene.camera.name == info["camera"]
        assert info["materials"], f"{name}: no aging materials"

    def test_room_lamp_is_removable_with_its_light(self):
        info = room.build(resolution=64)
        assert set(info["lamp"]) | {info["rug"]} <= set(info["removable"])
        assert bpy.data.objects["Lamp"].type == "LIGHT"

    def test_gallery_prints_are_identical_but_separate(self):
        info = gallery.build(resolution=64)
        images = [_base_color_image(bpy.data.objects[p].active_material) for p in info["prints"]]
        assert len({img.name for img in images}) == 3
        px = []
        for img in images:
            a = np.empty(len(img.pixels), dtype=np.float32)
            img.pixels.foreach_get(a)
            px.append(a)
        assert np.array_equal(px[0], px[1]) and np.array_equal(px[0], px[2])


class TestMaterials:
    def test_tagged_materials_have_packed_srgb_albedo(self, built):
        name, _, info = built
        mats = C.tagged_materials()
        assert sorted(m.name for m in mats) == info["materials"]
        for mat in mats:
            assert mat["lightfade_recipe"] in C.RECIPES
            if "lightfade_blue_wool" in mat:
                assert 1 <= mat["lightfade_blue_wool"] <= 8
            img = _base_color_image(mat)
            assert img is not None and img.packed_file is not None, f"{mat.name}: image not packed"
            assert img.colorspace_settings.name == "sRGB"
            w, h = img.size
            assert w >= 16 and h >= 16
            a = np.empty(w * h * 4, dtype=np.float32)
            img.pixels.foreach_get(a)
            rgb = a.reshape(h, w, 4)[..., :3]
            assert rgb.std() > 0.005, f"{mat.name}: flat image"

    def test_aging_meshes_have_non_overlapping_uvs_in_unit_square(self, built):
        _, _, info = built
        users = [o for o in bpy.data.objects if o.type == "MESH" and o.active_material
                 and "lightfade_recipe" in o.active_material]
        assert users
        for ob in users:
            mesh = ob.data
            assert mesh.uv_layers.active is not None, f"{ob.name}: no UV map"
            uv = np.empty(len(mesh.loops) * 2, dtype=np.float32)
            mesh.uv_layers.active.data.foreach_get("uv", uv)
            assert uv.min() >= 0.0 and uv.max() <= 1.0, f"{ob.name}: UVs outside [0, 1]"
            count = _uv_coverage(mesh)
            assert count.max() == 1, f"{ob.name}: overlapping UV islands"
            assert (count > 0).mean() > 0.3, f"{ob.name}: UVs use little of the image"

    def test_uv_coverage_detects_overlap(self):
        """The checker above must see two faces stacked on the same UV island."""
        C.reset()
        quad = ((0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0))
        ob = meshes.mesh_from_quads("Two", [quad, quad])
        assert _uv_coverage(ob.data).max() == 1
        ob.data.uv_layers.active.data.foreach_set("uv", np.tile([0, 0, 1, 0, 1, 1, 0, 1], 2).astype(np.float32))
        assert _uv_coverage(ob.data).max() == 2

    def test_each_aging_material_has_one_object(self, built):
        """Per-texel aging needs one surface per image: no material shared by two objects."""
        for mat in C.tagged_materials():
            users = [o for o in bpy.data.objects if o.type == "MESH" and mat.name in o.data.materials]
            assert len(users) == 1, f"{mat.name}: used by {[o.name for o in users]}"


class TestLights:
    def test_every_light_is_tagged(self, built):
        _, _, info = built
        lights = [o for o in bpy.data.objects if o.type == "LIGHT"]
        assert sorted(o.name for o in lights) == sorted(info["lights"])
        for ob in lights:
            data = ob.data
            assert data["lightfade_spectrum"] in C.SPECTRA
            assert 0 < data["lightfade_hours_per_day"] <= 24
            assert isinstance(data["lightfade_uv_filter"], bool) or data["lightfade_uv_filter"] in (0, 1)

    def test_room_sun_gives_intended_floor_lux(self):
        room.build(resolution=64)
        sun = bpy.data.objects["Sun"]
        bpy.context.view_layer.update()
        d = sun.matrix_world.to_3x3() @ Vector((0, 0, -1))
        lux = C.lux_from_irradiance(sun.data.energy * -d.z)  # horizontal floor
        assert lux == pytest.approx(room.SUN_FLOOR_LUX, rel=1e-6)
        assert 10000 <= lux <= 30000
        assert sun.data["lightfade_spectrum"] == "daylight-glass"
        assert bpy.data.lights["Lamp"]["lightfade_spectrum"] == "incandescent"

    def test_gallery_spots_give_intended_lux_and_uv(self):
        info = gallery.build(resolution=64)
        bpy.context.view_layer.update()
        got = {}
        for spot_name, print_name in zip(info["spots"], info["prints"]):
            spot, pr = bpy.data.objects[spot_name], bpy.data.objects[print_name]
            centre = pr.matrix_world @ (sum((v.co for v in pr.data.vertices), Vector()) / len(pr.data.vertices))
            ray = centre - spot.matrix_world.translation
            axis = spot.matrix_world.to_3x3() @ Vector((0, 0, -1))
            assert axis.angle(ray) < math.radians(1), f"{spot_name} not aimed at {print_name}"
            cos_t = abs(ray.normalized().y)  # prints face -y
            E = spot.data.energy * cos_t / (4 * math.pi * ray.length_squared)
            got[print_name] = C.lux_from_irradiance(E)
        assert got == pytest.approx(info["lux"], rel=1e-3)
        assert list(info["lux"].values()) == [50.0, 150.0, 50.0]
        tags = [(bpy.data.lights[s]["lightfade_spectrum"], bool(bpy.data.lights[s]["lightfade_uv_filter"]))
                for s in info["spots"]]
        assert tags == [("led", True), ("led", True), ("daylight", False)]


class TestRoomSunPatch:
    def test_sun_through_window_reaches_rug_floor_dresser_top_lamp_and_poster(self):
        """Rays from the window opening along the sun direction hit what should fade."""
        room.build(resolution=64)
        bpy.context.view_layer.update()
        scene = bpy.context.scene
        dg = bpy.context.evaluated_depsgraph_get()
        d = bpy.data.objects["Sun"].matrix_world.to_3x3() @ Vector((0, 0, -1))
        x_out = room.ROOM["x"][0] - room.ROOM["wall"] - 0.05
        hits = {}
        (y0, y1), (z0, z1) = room.WINDOW["y"], room.WINDOW["z"]
        for y in np.linspace(y0 + 0.01, y1 - 0.01, 40):
            for z in np.linspace(z0 + 0.01, z1 - 0.01, 40):
                o = Vector((x_out, y, z))
                hit, loc, normal, _, ob, _ = scene.ray_cast(dg, o, d)
                if hit:
                    hits.setdefault(ob.name, []).append((loc.copy(), normal.copy()))
        for name in ("Rug", "Floor", "Dresser", "LampBase", "Poster"):
            assert len(hits.get(name, [])) >= 5, f"sun misses {name}: {sorted(hits)}"
        top = [loc for loc, n in hits["Dresser"] if n.z > 0.9]
        assert len(top) >= 20, "sun does not reach the dresser top"
        # the floor is lit both in front of the rug's back edge and behind it
        rug_back = room.RUG["center"][1] + room.RUG["size"][1] / 2
        floor_y = [loc.y for loc, _ in hits["Floor"]]
        assert max(floor_y) > rug_back
        assert any(loc.y < rug_back for loc, _ in hits["Rug"])


class TestReveal:
    @pytest.mark.parametrize("module", [room, swatches], ids=["room", "swatches"])
    def test_reveal_hides_only_the_removables_and_restores(self, module):
        info = module.build(resolution=64)
        removable = set(info["removable"])
        assert removable
        module.set_reveal(True)
        for ob in bpy.data.objects:
            hidden = ob.name in removable
            assert ob.hide_render is hidden and ob.hide_viewport is hidden, ob.name
        module.set_reveal(False)
        assert not any(ob.hide_render or ob.hide_viewport for ob in bpy.data.objects)


class TestSave:
    def test_saved_file_keeps_packed_images_and_tags(self, tmp_path):
        path = tmp_path / "swatches.blend"
        info = swatches.build(path=str(path), resolution=64)
        assert path.exists()
        C.reset()
        bpy.ops.wm.open_mainfile(filepath=str(path))
        mat = bpy.data.materials[info["materials"][0]]
        assert mat["lightfade_recipe"] == "printed-paper"
        img = _base_color_image(mat)
        assert img.packed_file is not None
        w, h = img.size  # loading the packed PNG
        a = np.empty(w * h * 4, dtype=np.float32)
        img.pixels.foreach_get(a)
        assert w == 64 and a.reshape(h, w, 4)[..., :3].std() > 0.01
        assert bpy.data.lights["Sun"]["lightfade_spectrum"] == "daylight"

    def test_cli_builds_and_saves(self, tmp_path):
        path = tmp_path / "gallery.blend"
        info = cli.main(gallery.build, "gallery", [str(path), "--resolution", "32"])
        assert path.exists() and info["prints"]


class TestRender:
    def test_tiny_room_render_is_not_black(self, tmp_path):
        from PIL import Image

        room.build(resolution=64)
        scene = bpy.context.scene
        render.configure_render(scene, 64, 40, samples=4)
        out = tmp_path / "room.png"
        render.render_still(str(out))
        px = np.asarray(Image.open(out).convert("RGB"), dtype=np.float32) / 255
        assert px.shape == (40, 64, 3)
        assert px.mean() > 0.05
        assert px.std() > 0.02  # not a flat frame


class TestTextures:
    def test_cmy_model_paper_and_solids(self):
        white = T.cmy_to_srgb(0, 0, 0)
        assert np.allclose(white, T.linear_to_srgb(T.PAPER_WHITE), atol=1e-6)
        c, m, y = T.cmy_to_srgb([1, 0, 0], [0, 1, 0], [0, 0, 1])
        assert c.argmin() == 0 and m.argmin() == 1 and y.argmin() == 2
        # coverage darkens monotonically
        ramp = T.cmy_to_srgb(np.linspace(0, 1, 11), 0, 0)[:, 0]
        assert np.all(np.diff(ramp) < 0)

    @pytest.mark.parametrize("fn", [
        lambda: T.wood_planks((64, 64)), lambda: T.rug((40, 64)), lambda: T.poster((64, 44)),
        lambda: T.painted_wood((32, 32), (0.1, 0.5, 0.5)), lambda: T.fabric((32, 16), (0.7, 0.3, 0.1)),
        lambda: T.colour_chart((40, 120)),
    ], ids=["planks", "rug", "poster", "painted", "fabric", "chart"])
    def test_generators_are_deterministic_rgb_in_range(self, fn):
        a, b = fn(), fn()
        assert a.dtype == np.float32 and a.ndim == 3 and a.shape[2] == 3
        assert np.array_equal(a, b)
        assert a.min() >= 0 and a.max() <= 1

    def test_pack_rectangles_do_not_overlap(self):
        sizes = [(1.2, 0.5), (0.5, 0.85), (0.05, 0.12), (1.2, 0.85), (0.3, 0.3)] * 3
        offsets, s = meshes.pack_rectangles(sizes, gap=0.01)
        rects = [(u, v, u + w * s, v + h * s) for (u, v), (w, h) in zip(offsets, sizes)]
        for i, a in enumerate(rects):
            assert a[0] >= 0 and a[1] >= 0 and a[2] <= 1 and a[3] <= 1
            for b in rects[i + 1:]:
                assert a[2] <= b[0] or b[2] <= a[0] or a[3] <= b[1] or b[3] <= a[1]
