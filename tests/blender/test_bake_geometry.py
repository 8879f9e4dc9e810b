"""Geometry a bake cannot take is refused in one line before any Cycles work
(bake/geometry.py): instance-only or empty geometry as rendered, a UV map the mesh as
rendered lacks, more UV islands than the capped map holds."""

import bpy
import pytest

from lightfade_addon.blender.bake import BakeSettings, BakeState, LightFadeBakeError, bake_exposure
from lightfade_addon.blender.bake.common import UV_MAP_NAME

from conftest import add_sun


def _nodes_modifier(obj, build):
    """A geometry-nodes modifier "Scatter" on ``obj``; ``build(tree, group_in, group_out)``."""
    tree = bpy.data.node_groups.new("Scatter", "GeometryNodeTree")
    tree.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    tree.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    build(tree, tree.nodes.new("NodeGroupInput"), tree.nodes.new("NodeGroupOutput"))
    mod = obj.modifiers.new("Scatter", "NODES")
    mod.node_group = tree
    return mod


def _instances(tree, gin, gout):
    points = tree.nodes.new("GeometryNodeMeshToPoints")
    inst = tree.nodes.new("GeometryNodeInstanceOnPoints")
    cube = tree.nodes.new("GeometryNodeMeshCube")
    tree.links.new(gin.outputs[0], points.inputs["Mesh"])
    tree.links.new(points.outputs[0], inst.inputs["Points"])
    tree.links.new(cube.outputs[0], inst.inputs["Instance"])
    tree.links.new(inst.outputs[0], gout.inputs[0])


def _new_cube(tree, gin, gout):
    """New geometry: a cube whose UVs are an anonymous attribute (no UV map by name)."""
    tree.links.new(tree.nodes.new("GeometryNodeMeshCube").outputs[0], gout.inputs[0])


def _nothing(tree, gin, gout):
    pass


@pytest.fixture
def plane(blender, monkeypatch):
    """A UV'd 2 m plane and a sun, tiny bake settings; Cycles must not be called."""
    bpy.ops.mesh.primitive_plane_add(size=2.0)
    obj = bpy.context.active_object
    add_sun()
    scene = bpy.context.scene
    scene.lightfade.bake_resolution = 32
    scene.lightfade.bake_samples = 1

    def no_cycles(self):
        raise AssertionError("Cycles was called for geometry that cannot be baked")

    monkeypatch.setattr(BakeState, "bake", no_cycles)
    return obj


def _refusal(obj):
    settings = BakeSettings.from_scene(bpy.context.scene, unwrap=True)
    with pytest.raises(LightFadeBakeError) as err:
        bake_exposure(bpy.context.scene, [obj], settings=settings, report=lambda m: None)
    message = str(err.value)
    assert "\n" not in message and message.startswith(f"\"{obj.name}\"")
    return message


def test_instance_only_geometry_is_refused_in_one_line(plane):
    _nodes_modifier(plane, _instances)
    message = _refusal(plane)
    assert "only instances (4 of them" in message and "\"Scatter\"" in message
    assert "Realize Instances" in message
    assert not any(i.name.startswith("LF_") for i in bpy.data.images)


def test_geometry_without_faces_is_refused(plane):
    _nodes_modifier(plane, _nothing)
    message = _refusal(plane)
    assert "has no faces" in message and "\"Scatter\"" in message


def test_a_uv_map_the_rendered_mesh_lacks_is_refused(plane):
    _nodes_modifier(plane, _new_cube)
    message = _refusal(plane)
    assert "no UV map \"UVMap\"" in message and "Store Named Attribute" in message


def test_a_made_map_the_rendered_mesh_drops_is_refused_and_removed(plane):
    plane.data.uv_layers.remove(plane.data.uv_layers[0])
    _nodes_modifier(plane, _new_cube)
    message = _refusal(plane)
    assert f"no UV map \"{UV_MAP_NAME}\"" in message
    assert UV_MAP_NAME not in plane.data.uv_layers and not plane.lightfade.uv_created


def _stacked_quads(count):
    """One mesh of ``count`` separate quads sharing the same UVs (overlapping islands)."""
    mesh = bpy.data.meshes.new("Quads")
    verts, faces = [], []
    for i in range(count):
        x = (i % 20) * 0.1
        y = (i // 20) * 0.1
        base = len(verts)
        verts += [(x, y, 0), (x + 0.08, y, 0), (x + 0.08, y + 0.08, 0), (x, y + 0.08, 0)]
        faces.append((base, base + 1, base + 2, base + 3))
    mesh.from_pydata(verts, [], faces)
    uv = mesh.uv_layers.new(name="UVMap")
    for loop, corner in zip(uv.data, [(0.1, 0.1), (0.9, 0.1), (0.9, 0.9), (0.1, 0.9)] * count):
        loop.uv = corner
    obj = bpy.data.objects.new("Quads", mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def test_more_islands_than_the_capped_map_holds_is_refused(plane):
    quads = _stacked_quads(200)
    bpy.context.scene.lightfade.bake_resolution = 64   # room for 90 islands
    message = _refusal(quads)
    assert "200 UV islands do not fit a 64² map" in message and "Max Size" in message


def test_islands_that_fit_are_planned(plane):
    from lightfade_addon.blender.bake import ExposureBake

    quads = _stacked_quads(200)
    bpy.context.scene.lightfade.bake_resolution = 256  # room for 1441 islands
    job = ExposureBake(bpy.context.scene, [quads], report=lambda m: None).plan()
    assert job.uv_plans["Quads"].make
