"""Collection instances age where each one stands (issue 37): one atlas per source, a tile
per instance read through an Instancer attribute; nothing of the artist's data changed."""

import subprocess
import sys

import numpy as np
import pytest

bpy = pytest.importorskip("bpy")

from scenes import instanced_chairs  # noqa: E402


@pytest.fixture
def chairs(blender):
    parts = instanced_chairs.build()
    scene = bpy.context.scene
    scene.lightfade.bake_resolution = 32
    scene.lightfade.bake_samples = 8
    return parts


def _atlas(source):
    image = source.lightfade.exposure_maps[0].image
    w, h = image.size
    px = np.empty(w * h * 4, dtype=np.float32)
    image.pixels.foreach_get(px)
    return px.reshape(h, w, 4)[..., 0]


def _tile_mean(lux, rect):
    h, w = lux.shape
    u0, v0, s = rect
    n, x, y = int(round(s * w)), int(round(u0 * w)), int(round(v0 * h))
    tile = lux[y:y + n, x:x + n]
    return float(tile[tile > 0].mean())


def _tiles(chair):
    """Mean lux of each placement's tile of ``chair``'s first atlas."""
    lux = _atlas(chair)
    name = chair.lightfade.instance_tiles
    return {o.name: _tile_mean(lux, o[name]) for o in bpy.context.scene.objects
            if name in o.keys()}


def _book_tiles(book):
    """Mean lux of each book instance's tile (the LightFade modifier's data, in order)."""
    from lightfade_addon.blender.bake.instance_tiles import data_objects, data_tiles

    (data,) = data_objects()
    lux = _atlas(book)
    return [_tile_mean(lux, rect) for rect in data_tiles(data)[1]]


def test_each_instance_bakes_its_own_tile(chairs):
    """The four chairs get four tiles of one atlas: the two in the sun several times the
    lux of the two behind the wall; no stand-in is left, the mesh and collection as they were."""
    from lightfade_addon import api

    chair = chairs["chair"]
    mesh_before = (len(chair.data.vertices), [uv.name for uv in chair.data.uv_layers])
    result = api.bake(bpy.context.scene)
    assert sorted(result["maps"]) == ["Book", "Chair"]
    tiles = _tiles(chair)
    assert sorted(tiles) == ["Chair 1", "Chair 2", "Chair 3", "Chair 4"]
    sun = min(tiles["Chair 1"], tiles["Chair 2"])
    shade = max(tiles["Chair 3"], tiles["Chair 4"])
    assert sun > 3 * shade, tiles
    assert not [o for o in bpy.data.objects if o.name.startswith("LF_TMP_")]
    assert (len(chair.data.vertices), [uv.name for uv in chair.data.uv_layers]) == mesh_before
    assert all(e.instance_collection == chairs["collection"] for e in chairs["empties"])
    assert chair.name not in bpy.context.scene.objects          # never put in the scene


def _tree_state(tree):
    return (sorted(n.name for n in tree.nodes),
            sorted((l.from_node.name, l.from_socket.identifier, l.to_node.name,
                    l.to_socket.identifier) for l in tree.links))


def test_geometry_nodes_instances_bake_their_own_tiles(chairs):
    """Eight books scattered by geometry nodes from a hidden source: one tile each, the four
    in the sun several times the lux of the four in the shade; the artist's tree untouched,
    LightFade's modifier after it, the source still hidden."""
    from lightfade_addon import api

    books, book = chairs["books"], chairs["book"]
    tree = books.modifiers[0].node_group
    before = _tree_state(tree)
    api.bake(bpy.context.scene)
    lux = _book_tiles(book)
    assert len(lux) == instanced_chairs.BOOKS[2]
    assert min(lux[:4]) > 3 * max(lux[4:]), lux
    assert _tree_state(tree) == before
    assert [m.name for m in books.modifiers] == ["Book Line", "LightFade Tiles"]
    assert book.hide_viewport and book.hide_render


def test_the_source_itself_is_a_tile_when_it_renders(chairs):
    """A source standing in the scene gets its own tile (its own property), and hides from
    the bake while its stand-ins bake: it shadows nothing twice."""
    from lightfade_addon import api

    scene = bpy.context.scene
    chair = chairs["chair"]
    scene.collection.objects.link(chair)       # at the origin, inside the table
    api.bake(scene)
    name = chair.lightfade.instance_tiles
    tiles = _tiles(chair)
    assert name in chair.keys() and len(tiles) == 5
    assert tiles["Chair"] < 0.6 * tiles["Chair 1"], tiles      # half under the table top
    assert chair.visible_shadow and chair.visible_camera           # flags put back


RENDER = """
import sys, numpy as np, bpy
bpy.context.preferences.filepaths.use_scripts_auto_execute = False
bpy.ops.wm.open_mainfile(filepath={path!r}, load_ui=False)
assert not hasattr(bpy.types.Scene, "lightfade"), "LightFade must not be installed here"
scene = bpy.context.scene
scene.render.engine = {engine!r}
out = []
for years in (0.0, 30.0):
    scene["lightfade_years"] = years
    scene.render.filepath = {png!r}
    bpy.ops.render.render(write_still=True)
    image = bpy.data.images.load({png!r})
    out.append(np.array(image.pixels[:], dtype=np.float32).reshape(
        image.size[1], image.size[0], 4)[..., :3])
    bpy.data.images.remove(image)
np.save({npy!r}, np.stack(out))
"""


def _top_camera(scene):
    cam = bpy.data.objects.new("Top", bpy.data.cameras.new("Top"))
    scene.collection.objects.link(cam)
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = 6.0
    cam.location = (0.0, 0.0, 6.0)
    scene.camera = cam
    scene.render.resolution_x = scene.render.resolution_y = 192
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.view_settings.view_transform = "Standard"
    scene.cycles.samples = 4


def _seat(x, y):
    """Pixel (row, column) of a seat at world (x, y) in :func:`_top_camera`'s view."""
    return int((y + 3.0) / 6.0 * 192), int((x + 3.0) / 6.0 * 192)


def _fade_per_chair(tmp_path, engine):
    from lightfade_addon.core.colour.colorimetry import (XYZ_to_Lab, delta_E_2000,
                                                         linear_srgb_to_XYZ)

    def lab(rgb):
        return XYZ_to_Lab(linear_srgb_to_XYZ(np.asarray(rgb, float).reshape(-1, 3)))

    path, png, npy = tmp_path / "chairs.blend", tmp_path / "r.exr", tmp_path / "r.npy"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    code = RENDER.format(path=str(path), engine=engine, png=str(png), npy=str(npy))
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=600)
    assert run.returncode == 0, run.stderr[-2000:]
    frames = np.load(npy)

    def fade(x, y, dr, dc):
        r, c = _seat(x, y)
        before, after = (f[r - dr:r + dr + 1, c - dc:c + dc + 1].reshape(-1, 3) for f in frames)
        return float(np.median(delta_E_2000(lab(np.clip(before, 1e-6, None)),
                                            lab(np.clip(after, 1e-6, None)))))

    start, step, count = instanced_chairs.BOOKS
    return ([fade(x, y, 1, 1) for x, y, _rz in instanced_chairs.CHAIRS],
            [fade(start + k * step, instanced_chairs.BOOK_Y + 0.02, 2, 0)
             for k in range(count)])


def _big_books(chairs):
    """The books three times their size: their tops seen from above (the test's camera)."""
    tree = chairs["books"].modifiers[0].node_group
    place = next(n for n in tree.nodes if n.type == "INSTANCE_ON_POINTS")
    place.inputs["Scale"].default_value = (3.0, 3.0, 3.0)


def test_a_saved_file_renders_each_instance_aged_without_lightfade(chairs, tmp_path):
    """Cycles in a fresh process without LightFade: the seats in the sun fade, the seats
    in the wall's shadow barely change (one material, four tiles)."""
    from lightfade_addon import api

    scene = bpy.context.scene
    _top_camera(scene)
    _big_books(chairs)
    api.bake(scene)
    copies = api.age_scene(scene, years=0)
    assert sorted(c.name for c in copies) == ["LF_Aged_Book Cloth.Book",
                                              "LF_Aged_Chair Fabric.Chair"]
    chair_fades, book_fades = _fade_per_chair(tmp_path, "CYCLES")
    assert min(chair_fades[:2]) > 5 and max(chair_fades[2:]) < 0.4 * min(chair_fades[:2]), \
        chair_fades
    assert min(book_fades[:4]) > 5 and max(book_fades[4:]) < 0.4 * min(book_fades[:4]), \
        book_fades


@pytest.mark.slow
def test_eevee_renders_each_instance_aged(chairs, tmp_path):
    """EEVEE reads the same tiles (Attribute node, Instancer)."""
    from lightfade_addon import api

    scene = bpy.context.scene
    _top_camera(scene)
    _big_books(chairs)
    api.bake(scene)
    api.age_scene(scene, years=0)
    eevee = "BLENDER_EEVEE_NEXT" if bpy.app.version < (5, 0, 0) else "BLENDER_EEVEE"
    for fades, n in zip(_fade_per_chair(tmp_path, eevee), (2, 4)):
        assert min(fades[:n]) > 5 and max(fades[n:]) < 0.4 * min(fades[:n]), fades


def test_reset_restores_the_file(chairs):
    """Reset with the exposure removes the atlas, the tile properties and the aged copy:
    every object's custom properties, slots and the images are as before."""
    from lightfade_addon import api

    scene = bpy.context.scene
    chair = chairs["chair"]

    def state():      # custom properties (4.2 lists the registered groups once used)
        return ({o.name: sorted(k for k in o.keys() if not k.startswith("lightfade"))
                 for o in bpy.data.objects},
                [(s.link, s.material.name) for s in chair.material_slots],
                [m.name for m in chairs["books"].modifiers], sorted(bpy.data.node_groups.keys()),
                sorted(bpy.data.meshes.keys()),
                sorted(i.name for i in bpy.data.images),
                sorted(m.name for m in bpy.data.materials))

    before = state()
    api.bake(scene)
    api.age_scene(scene, years=10)
    assert chair.material_slots[0].material.name.startswith("LF_Aged_")
    api.reset(scene, exposure=True)
    assert state() == before
    assert chair.lightfade.instance_tiles == "" and not chair.lightfade.exposure_maps


def _chair_copy(copies):
    (copy,) = [c for c in copies if c.lightfade.aged_object.name == "Chair"]
    return copy


def test_a_moved_instance_is_stale_until_rebaked(chairs):
    """Moving an empty makes the aged copy stale ("bake exposure again"); a re-bake fixes it."""
    from lightfade_addon import api
    from lightfade_addon.blender.aging.apply import stale_message

    scene = bpy.context.scene
    api.bake(scene)
    copy = _chair_copy(api.age_scene(scene, years=10))
    assert stale_message(scene, copy) == ""
    chairs["empties"][2].location.x += 0.5
    bpy.context.view_layer.update()
    message = stale_message(scene, copy)
    assert "Chair 3" in message and message.endswith("bake exposure again")
    api.bake(scene)
    assert stale_message(scene, copy) == ""


def test_export_of_an_instanced_source_is_refused_in_one_line(chairs, tmp_path):
    from lightfade_addon import api
    from lightfade_addon.blender.aging.apply import apply_aging, write_aged_file
    from lightfade_addon.blender.errors import AgingError

    scene = bpy.context.scene
    api.bake(scene)
    copy = _chair_copy(api.age_scene(scene, years=10))
    with pytest.raises(AgingError, match="aged per instance") as err:
        write_aged_file(scene, copy, 10.0, str(tmp_path / "x.png"))
    assert "\n" not in str(err.value)
    assert apply_aging(scene) == {}             # the live aging stays; nothing applied
    assert copy.lightfade.aged_image is None


def test_cycles_renders_instanced_sources_live_not_from_frame_images(chairs):
    """A frame image holds one colour per texel of the source's UV map, not each
    instance's tile: the render handler leaves an instanced source's copy live (its
    switch stays 0 and no frame image is written) while the other copies switch."""
    from lightfade_addon import api
    from lightfade_addon.blender.aging import frames

    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    api.bake(scene)
    copy = _chair_copy(api.age_scene(scene, years=10))
    assert frames.frame_image(copy) is not None          # Age gave it a frame branch
    assert copy not in [c for c, _ in frames.switches(scene)]
    assert copy.name not in frames.write_frames(scene, 10.0)
    frames.on_render_pre(scene)
    try:
        for tree, _ in frames.frame_nodes(copy):
            assert tree.nodes[frames.FRAME_MIX].inputs["Fac"].default_value == 0.0
    finally:
        frames.on_render_end(scene)


def test_a_moved_book_is_stale(chairs):
    """A geometry-nodes instance that moves (the scatter changed) makes its copy stale."""
    from lightfade_addon import api
    from lightfade_addon.blender.aging.apply import stale_message

    scene = bpy.context.scene
    api.bake(scene)
    copies = api.age_scene(scene, years=10)
    (copy,) = [c for c in copies if c.lightfade.aged_object.name == "Book"]
    assert stale_message(scene, copy) == ""
    tree = chairs["books"].modifiers[0].node_group
    line = next(n for n in tree.nodes if n.bl_idname == "GeometryNodeMeshLine")
    line.inputs["Count"].default_value = 9
    bpy.context.view_layer.update()
    assert "Books" in stale_message(scene, copy)


def test_a_hidden_target_says_so_in_one_line(floor_scene):
    """A mesh disabled in viewports that nothing instances: skipped in one line; with
    nothing else to bake, the bake stops with that line, not Cycles' poll error."""
    from lightfade_addon import api
    from lightfade_addon.blender.bake import LightFadeBakeError

    floor_scene["floor"].hide_viewport = True
    with pytest.raises(LightFadeBakeError) as err:
        api.bake(bpy.context.scene)
    message = str(err.value)
    assert message.startswith("Nothing to bake: Skipped \"Floor\": hidden from the bake")
    assert "\n" not in message


def test_info_and_dose_view_know_instances(chairs):
    """``info`` lists each instanced source (placements by kind, atlas, stale instancers);
    the per-material doses count every tile; the dose view shows on the instances (the
    source's slots read each tile) and puts the source's slots back."""
    from lightfade_addon import api
    from lightfade_addon.blender.daylight.doses import material_labels
    from lightfade_addon.blender.daylight.view import clear_view, show_view
    from lightfade_addon.pipeline.info import instances

    scene = bpy.context.scene
    chair = chairs["chair"]
    api.bake(scene)
    api.age_scene(scene, years=10)
    rows = {r["object"]: r for r in instances(scene)}
    assert (rows["Chair"]["collection"], rows["Book"]["geometry_nodes"]) == (4, 8)
    assert rows["Chair"]["stale"] == [] and not rows["Book"]["itself"]
    from lightfade_addon.pipeline.info import as_text, gather

    text = as_text(gather(scene))
    assert "  instances of Chair: 4 (4 collection, 0 geometry-nodes), atlas" in text
    book = chairs["book"]                       # 8 books: tiles 0-7 of a 3 x 3 grid
    size = book.lightfade.exposure_maps[0].image.size[0]
    labels, w = material_labels(book, size), size // 3
    counts = [np.count_nonzero(labels[k // 3 * w:(k // 3 + 1) * w, k % 3 * w:(k % 3 + 1) * w]
                               >= 0) for k in range(9)]
    assert counts[:8] == [counts[0]] * 8 and counts[0] > 0 and counts[8] == 0, counts
    slots = [(s.link, s.material.name) for s in chair.material_slots]
    show_view(scene, chair, "DOSE")
    (mat,) = {s.material for s in chair.material_slots}
    assert any(n.type == "ATTRIBUTE" and n.attribute_name == chair.lightfade.instance_tiles
               for n in mat.node_tree.nodes)
    clear_view(scene)
    assert [(s.link, s.material.name) for s in chair.material_slots] == slots


def test_instances_of_a_linked_collection_are_skipped_in_one_line(blender, tmp_path):
    """A chair collection linked from another .blend: the bake names it and the library
    and bakes the rest; nothing of the library is made local."""
    from lightfade_addon import api
    from lightfade_addon.blender.bake import LightFadeBakeError

    instanced_chairs.build()
    library = tmp_path / "chairs.blend"
    bpy.data.libraries.write(str(library), {bpy.data.collections["Chair"]})
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    with bpy.data.libraries.load(str(library), link=True) as (src, dst):
        dst.collections = ["Chair"]
    empty = bpy.data.objects.new("Linked Chair", None)
    empty.instance_type, empty.instance_collection = "COLLECTION", dst.collections[0]
    scene = bpy.context.scene
    scene.collection.objects.link(empty)
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    scene.collection.objects.link(sun)
    with pytest.raises(LightFadeBakeError) as err:
        api.bake(scene)
    message = str(err.value)
    assert "Skipped \"Chair\" (1 instances): it is linked from" in message
    assert "chairs.blend" in message and "\n" not in message
    assert all(o.library is not None for o in bpy.data.objects if o.name == "Chair")


def test_instances_match_the_same_chairs_made_real(chairs):
    """Each chair's tile holds what the same chair made real (a linked duplicate at the
    instance's place) gets from the same bake: mean lux within 10 %."""
    from lightfade_addon import api

    scene = bpy.context.scene
    chair = chairs["chair"]
    api.bake(scene, objects=[chairs["empties"][0]])          # only the chairs' instances
    tiles = _tiles(chair)
    for empty in chairs["empties"]:
        real = bpy.data.objects.new(f"Real {empty.name}", chair.data)
        scene.collection.objects.link(real)
        real.matrix_world = empty.matrix_world
        empty.instance_type = "NONE"
    bpy.context.view_layer.update()
    result = api.bake(scene, objects=[o for o in scene.objects if o.name.startswith("Real")])
    for empty in chairs["empties"]:
        (image,) = result["maps"][f"Real {empty.name}"].values()
        lux = _atlas_of(image)
        real = float(lux[lux > 0].mean())
        assert abs(tiles[empty.name] - real) < 0.1 * real, (empty.name, tiles, real)


def _atlas_of(image):
    w, h = image.size
    px = np.empty(w * h * 4, dtype=np.float32)
    image.pixels.foreach_get(px)
    return px.reshape(h, w, 4)[..., 0]


def test_the_panel_lists_each_atlas_and_estimates_it(chairs):
    """Before any bake the Exposure Bake panel lists each instanced source with its
    placements and atlas, and its estimate counts the atlases' texels."""
    from types import SimpleNamespace

    from lightfade_addon.blender.bake import BakeSettings, ExposureBake
    from test_panels import draw_all

    scene = bpy.context.scene
    labels = [t for kind, t in draw_all(SimpleNamespace(scene=scene, object=None,
                                                        material=None)) if kind == "label"]
    job = ExposureBake(scene, settings=BakeSettings.from_scene(scene)).plan()
    sizes = {p.source.name: p.size for p in job.instance_plans}
    assert f"Chair: 4 instances, {sizes['Chair']}² atlas" in labels
    assert f"Book: 8 instances, {sizes['Book']}² atlas" in labels
    estimate = job.estimate()
    # one Cycles call for both atlases per pass (the adaptive bake's first passes)
    assert estimate.calls == job.settings.first_passes
    assert estimate.texels == sizes["Chair"] ** 2 + sizes["Book"] ** 2
    assert any(t.startswith(estimate.text().split(" (")[0]) for t in labels), labels
    assert f"{estimate.texel_samples / 1e6:,.1f}" in estimate.text()


def test_geometry_nodes_instances_of_a_collection(chairs):
    """The line instancing the chair collection (Collection Info) instead of the book:
    eight more chair placements, each with its own tile by its top-level instance."""
    from lightfade_addon import api
    from lightfade_addon.blender.bake.instance_tiles import data_objects, data_tiles

    tree = chairs["books"].modifiers[0].node_group
    collection = tree.nodes.new("GeometryNodeCollectionInfo")
    collection.inputs["Collection"].default_value = chairs["collection"]
    place = next(n for n in tree.nodes if n.bl_idname == "GeometryNodeInstanceOnPoints")
    tree.links.new(collection.outputs[0], place.inputs["Instance"])
    chairs["cloth"].lightfade.enabled = False                # the book is no longer used
    api.bake(bpy.context.scene)
    (data,) = data_objects()
    lux = _atlas(chairs["chair"])
    line = [_tile_mean(lux, rect) for rect in data_tiles(data)[1]]
    assert len(line) == 8 and len(_tiles(chairs["chair"])) == 4
    # a chair is wider than a book: the fifth (x = 0.4) straddles the shadow's edge
    assert min(line[:4]) > 3 * max(line[5:]) and line[5] < line[4] < line[3], line


def test_years_view_of_an_instanced_source_per_tile(chairs):
    """The years-to-noticeable view of the chair reads each tile with its own light: the
    chairs in the sun fade within fewer years than those in the shade."""
    from conftest import COARSE_GRID
    from lightfade_addon import api
    from lightfade_addon.blender.daylight.view import view_values

    scene = bpy.context.scene
    chair = chairs["chair"]
    api.bake(scene)
    years, _scale, _note = view_values(scene, chair, "YEARS", chairs["material"],
                                       settings=COARSE_GRID)
    name = chair.lightfade.instance_tiles
    n = years.shape[0] // 2

    def median(empty):
        u0, v0, _s = empty[name]
        tile = years[int(v0 * 2) * n:(int(v0 * 2) + 1) * n, int(u0 * 2) * n:(int(u0 * 2) + 1) * n]
        return float(np.median(tile[np.isfinite(tile)])) if np.isfinite(tile).any() else np.inf

    sun = [median(e) for e in chairs["empties"][:2]]
    shade = [median(e) for e in chairs["empties"][2:]]
    assert max(sun) < min(shade), (sun, shade)


def _scatter(book, density):
    """A 1 m² patch in the sun scattering ``book`` by Distribute Points on Faces (which
    gives each point an ``id``)."""
    bpy.ops.mesh.primitive_plane_add(size=1.0, location=(-2.0, 1.8, 0.0))
    patch = bpy.context.active_object
    patch.name = "Patch"
    tree = bpy.data.node_groups.new("Patch Scatter", "GeometryNodeTree")
    for side in ("INPUT", "OUTPUT"):
        tree.interface.new_socket("Geometry", in_out=side, socket_type="NodeSocketGeometry")
    nodes, links = tree.nodes, tree.links
    spread = nodes.new("GeometryNodeDistributePointsOnFaces")
    spread.inputs["Density"].default_value = density
    spread.inputs["Seed"].default_value = 7
    info = nodes.new("GeometryNodeObjectInfo")
    info.inputs["Object"].default_value = book
    info.inputs["As Instance"].default_value = True
    place = nodes.new("GeometryNodeInstanceOnPoints")
    links.new(nodes.new("NodeGroupInput").outputs[0], spread.inputs["Mesh"])
    links.new(spread.outputs["Points"], place.inputs["Points"])
    links.new(info.outputs["Geometry"], place.inputs["Instance"])
    links.new(place.outputs[0], nodes.new("NodeGroupOutput").inputs[0])
    patch.modifiers.new("Patch Scatter", "NODES").node_group = tree
    return patch, spread


def _read_tiles(instancer, name):
    """``{position: tile}`` each evaluated instance of ``instancer`` reads under ``name``."""
    from lightfade_addon.blender.bake.instance_tiles import evaluated_instances

    positions, attributes = evaluated_instances(instancer, (name,))
    return {tuple(np.round(p, 5)): tuple(np.round(t, 6))
            for p, t in zip(positions, attributes[name])}


def test_geometry_nodes_instances_keep_their_tiles_when_others_are_added(chairs):
    """Instances added before others (a book inserted at the line's start, a higher density
    of a Distribute Points scatter): every instance baked keeps its tile (found by its
    position, not by its index, which shifts), the same seed evaluated again gives the
    same tiles, the new ones read a neighbour's tile and are said stale until a re-bake."""
    from lightfade_addon import api
    from lightfade_addon.blender.aging.apply import stale_message

    scene = bpy.context.scene
    book, books = chairs["book"], chairs["books"]
    patch, spread = _scatter(book, 12.0)
    api.bake(scene)
    copies = api.age_scene(scene, years=10)
    (copy,) = [c for c in copies if c.lightfade.aged_object.name == "Book"]
    name = book.lightfade.instance_tiles
    line_before, patch_before = _read_tiles(books, name), _read_tiles(patch, name)
    assert len(line_before) == 8 and len(patch_before) >= 8
    assert len(set(line_before.values()) | set(patch_before.values())) == \
        len(line_before) + len(patch_before)                   # a tile each

    start, step, count = instanced_chairs.BOOKS
    line = next(n for n in books.modifiers[0].node_group.nodes
                if n.bl_idname == "GeometryNodeMeshLine")
    line.inputs["Count"].default_value = count + 1
    line.inputs["Start Location"].default_value[0] = start - step
    spread.inputs["Density"].default_value = 36.0
    spread.inputs["Seed"].default_value = 8                     # and back: the same points
    bpy.context.view_layer.update()
    spread.inputs["Seed"].default_value = 7
    bpy.context.view_layer.update()
    line_after, patch_after = _read_tiles(books, name), _read_tiles(patch, name)
    assert len(line_after) == 9 and len(patch_after) > 2 * len(patch_before)
    assert {p: line_after[p] for p in line_before} == line_before
    assert {p: patch_after[p] for p in patch_before} == patch_before
    first = min(line_before)                                    # the new book: its neighbour's
    assert line_after[min(line_after)] == line_before[first]
    message = stale_message(scene, copy)
    assert "Books" in message and "Patch" in message
    api.bake(scene)
    assert stale_message(scene, copy) == ""
    assert len(set(_read_tiles(books, name).values())) == 9


def test_instances_that_change_with_the_frame_are_said_once(chairs):
    """A scatter whose count is animated (8 books at frame 1, 12 at frame 10): the bake
    says once why it holds frame 1's instances, ``info`` repeats it, the frame is put
    back; instances that do not change say nothing."""
    from lightfade_addon import api
    from lightfade_addon.pipeline.info import as_text, gather

    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, 10
    scene.frame_set(1)
    result = api.bake(scene)
    assert not [n for n in result["notes"] if "change with the frame" in n]
    line = next(n for n in chairs["books"].modifiers[0].node_group.nodes
                if n.bl_idname == "GeometryNodeMeshLine")
    count = line.inputs["Count"]
    count.keyframe_insert("default_value", frame=1)
    count.default_value = 12
    count.keyframe_insert("default_value", frame=10)
    scene.frame_set(1)
    result = api.bake(scene)
    said = [n for n in result["notes"] if "change with the frame" in n]
    assert len(said) == 1 and "\n" not in said[0], result["notes"]
    assert said[0].startswith("\"Book\": ") and "12 at frame 10" in said[0] \
        and "8 at frame 1, baked" in said[0], said
    assert scene.frame_current == 1 and count.default_value == 8
    assert as_text(gather(scene)).count(said[0]) == 1


def _state():
    """What Reset must put back: objects (library, collection instanced, custom properties,
    slots), collections, meshes, materials, images, node groups."""
    return ({(o.name, o.library is not None): (
                o.instance_collection and (o.instance_collection.name,
                                           o.instance_collection.library is not None),
                sorted(k for k in o.keys() if not k.startswith("lightfade")),
                [(s.link, s.material and s.material.name) for s in o.material_slots])
             for o in bpy.data.objects},
            sorted((c.name, c.library is not None) for c in bpy.data.collections),
            sorted((m.name, m.library is not None) for m in bpy.data.meshes),
            sorted(m.name for m in bpy.data.materials), sorted(i.name for i in bpy.data.images),
            sorted(bpy.data.node_groups.keys()))


def _draw_panels(scene):
    from types import SimpleNamespace

    from test_panels import draw_all

    return draw_all(SimpleNamespace(scene=scene, object=None, material=None))


def test_linked_chairs_age_per_instance_when_the_artist_asks(chairs, tmp_path):
    """The four chairs instancing a collection linked from another .blend: skipped in one
    line until Age Linked Instances; then each chair bakes its own tile (sun > 3 × shade)
    through one local copy of the chair (its mesh the library's: no mesh copied), the
    library's objects untouched; the saved file renders the chairs in the sun faded and
    those in the shade not, without LightFade; reopened it keeps its aged material and tiles;
    Reset with the exposure puts the library's collection back exactly."""
    from lightfade_addon import api

    library = tmp_path / "library.blend"
    bpy.data.libraries.write(str(library), {chairs["collection"]})
    with bpy.data.libraries.load(str(library), link=True) as (_src, dst):
        dst.collections = ["Chair"]
    linked = dst.collections[0]
    for empty in chairs["empties"]:
        empty.instance_collection = linked
    mesh = chairs["chair"].data
    bpy.data.objects.remove(chairs["chair"])
    bpy.data.collections.remove(chairs["collection"])
    bpy.data.meshes.remove(mesh)
    bpy.data.materials.remove(chairs["material"])             # the library's from here on
    scene = bpy.context.scene
    _top_camera(scene)                          # rendered without LightFade, library linked
    before = _state()
    result = api.bake(scene)
    assert sorted(result["maps"]) == ["Book"]
    (line,) = [s for s in result["skipped"] if "linked from" in s]
    assert "Age Linked Instances" in line and "\n" not in line
    meshes = sorted((m.name, m.library is not None) for m in bpy.data.meshes)
    drawn = _draw_panels(scene)
    assert ("label", "4 instances of linked collections: not aged") in drawn
    assert ("operator", "lightfade.localize_linked") in drawn
    (said,) = api.localize_linked(scene)
    assert "4 instances now show \"LF Chair\"" in said
    assert not bpy.ops.lightfade.localize_linked.poll()          # nothing linked left
    assert ("operator", "lightfade.localize_linked") not in _draw_panels(scene)
    result = api.bake(scene)
    (chair,) = [o for o in bpy.data.objects if o.library is None and o.name.startswith("Chair")
                and o.type == "MESH"]
    assert chair.data.library is not None and sorted(result["maps"]) == ["Book", chair.name]
    assert not [m for m in bpy.data.meshes if m.library is None and
                (m.name, False) not in meshes and not m.name.startswith("LF_Tiles_")]
    tiles = _tiles(chair)
    assert min(tiles["Chair 1"], tiles["Chair 2"]) > 3 * max(tiles["Chair 3"], tiles["Chair 4"])
    api.age_scene(scene, years=0)
    chair_fades, _books = _fade_per_chair(tmp_path, "CYCLES")
    assert min(chair_fades[:2]) > 5 and max(chair_fades[2:]) < 0.4 * min(chair_fades[:2]), \
        chair_fades
    original = [o for o in bpy.data.objects if o.library is not None and o.type == "MESH"]
    assert [(s.link, s.material.name) for o in original for s in o.material_slots] == \
        [("DATA", "Chair Fabric")]
    path, name = tmp_path / "linked.blend", chair.name
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.open_mainfile(filepath=str(path))
    chair = bpy.data.objects[name, None]
    assert chair.material_slots[0].link == "OBJECT"
    assert chair.material_slots[0].material.name.startswith("LF_Aged_")
    assert all(bpy.data.objects[f"Chair {i}"].instance_collection.name == "LF Chair"
               and chair.lightfade.instance_tiles in bpy.data.objects[f"Chair {i}"].keys()
               for i in range(1, 5))
    api.reset(bpy.context.scene, exposure=True)
    assert _state() == before
