"""Fixtures for the Blender tests: a fresh factory file with LightFade enabled, and
small scenes to bake (64 px, 8 samples: a bake takes a fraction of a second)."""

import contextlib
import math
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

bpy = pytest.importorskip("bpy")
import addon_utils  # noqa: E402  (Blender's module, importable once bpy is)
import numpy as np  # noqa: E402

from lightfade_addon.core.fading.grid import GridSettings  # noqa: E402
from lightfade_addon.core.aging.tablebuild import TableSettings  # noqa: E402

ADDON = "lightfade_addon"


def pytest_collection_modifyitems(config, items):
    here = Path(__file__).parent
    for item in items:
        if here in Path(str(item.fspath)).parents:
            item.add_marker(pytest.mark.blender)


#: The grid of the Blender tests: they check the shell (what is read, stored, shown,
#: restored), not the grid's accuracy, which tests/core/test_grid.py checks at the
#: shipped settings (so do the processes the extension-install and pipeline tests run).
#: A coarse grid builds in 0.06 s instead of 0.5 s.
COARSE_GRID = GridSettings(points=5, doses=17, mix=2)
#: The colour table of the Blender tests (the shell, not the table's accuracy, which
#: tests/core/test_colourtable.py and benchmarks/colour_table.py check).
COARSE_TABLE = TableSettings(side=9, per_decade=4, grid=GridSettings(points=5))


@pytest.fixture(scope="session", autouse=True)
def coarse_grid():
    """Every preparation in this process uses :data:`COARSE_GRID` (a process a test starts
    uses the shipped grid unless the test passes it this one)."""
    from lightfade_addon.blender.aging import data as agingdata, runtime

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(runtime, "GRID_SETTINGS", COARSE_GRID)
        patch.setattr(agingdata, "TABLE_SETTINGS", COARSE_TABLE)
        yield


_PREFERENCES_RESET = []


def reset_file():
    """An empty file from Blender's factory startup file.

    The first call in a process also resets the preferences to the factory's
    (``read_factory_settings``, ~90 ms); later calls reset the file only
    (``read_homefile`` of the factory startup file, ~10 ms, twice per Blender test):
    the tests change no preference but the enabled add-ons, and :func:`fresh_file`
    disables the add-on it enabled.
    """
    if _PREFERENCES_RESET:
        bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    else:
        bpy.ops.wm.read_factory_settings(use_empty=True)
        _PREFERENCES_RESET.append(True)


@contextlib.contextmanager
def fresh_file():
    """An empty factory-settings file with the add-on enabled; disabled and reset afterwards
    (for fixtures wider than one test, e.g. building files to save)."""
    reset_file()
    addon_utils.enable(ADDON, default_set=True)
    try:
        yield bpy
    finally:
        addon_utils.disable(ADDON, default_set=True)
        reset_file()


@pytest.fixture
def blender():
    """An empty factory-settings file with the add-on enabled; disabled afterwards."""
    with fresh_file():
        yield bpy


def add_sun(strength=2.0, theta_deg=40.0, name="Sun"):
    """A hard sun (angle 0) tilted ``theta_deg`` from the zenith toward -y (shadows fall to +y)."""
    scene = bpy.context.scene
    data = bpy.data.lights.new(name, "SUN")
    data.energy = strength
    data.angle = 0.0
    obj = bpy.data.objects.new(name, data)
    scene.collection.objects.link(obj)
    obj.rotation_euler = (math.radians(theta_deg), 0.0, 0.0)
    return obj


def add_point(power=100.0, location=(0.0, 0.0, 2.0), name="Lamp"):
    data = bpy.data.lights.new(name, "POINT")
    data.energy = power
    data.shadow_soft_size = 0.0
    obj = bpy.data.objects.new(name, data)
    bpy.context.scene.collection.objects.link(obj)
    obj.location = location
    return obj


@pytest.fixture
def floor_scene(blender):
    """A 2 m UV'd plane "Floor" with a 0.6 m box "Box" lying on it at (0.4, 0.4) and a sun.

    The floor has a material "Carpet" with LightFade enabled whose Base Color is an
    8×8 image "CarpetAlbedo".
    """
    return build_floor_scene()


def build_floor_scene():
    """Build :func:`floor_scene`'s scene into the current file; returns its parts."""
    bpy.ops.mesh.primitive_plane_add(size=2.0)
    floor = bpy.context.active_object
    floor.name = "Floor"
    mat = bpy.data.materials.new("Carpet")
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    albedo = bpy.data.images.new("CarpetAlbedo", 8, 8)
    albedo.pixels.foreach_set(np.linspace(0.0, 1.0, 8 * 8 * 4, dtype=np.float32))
    albedo.pack()
    tex = mat.node_tree.nodes.new("ShaderNodeTexImage")
    tex.image = albedo
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    mat.node_tree.links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])
    mat.lightfade.enabled = True
    floor.data.materials.append(mat)
    bpy.ops.mesh.primitive_cube_add(size=0.6, location=(0.4, 0.4, 0.3))
    box = bpy.context.active_object
    box.name = "Box"
    sun = add_sun()
    for o in bpy.context.view_layer.objects:
        o.select_set(False)
    scene = bpy.context.scene
    scene.lightfade.bake_resolution = 64
    scene.lightfade.bake_samples = 8
    scene.lightfade.bake_margin = 2
    return {"floor": floor, "box": box, "sun": sun, "material": mat, "albedo": albedo}


def wrap_bsdf_in_group(material, colour):
    """Route ``colour`` (an output socket in ``material``) into a Principled BSDF inside a
    new node group feeding the Material Output (a BSDF inside a group); the group node."""
    tree = material.node_tree
    group = bpy.data.node_groups.new("Wrapped", "ShaderNodeTree")
    group.interface.new_socket("Color", in_out="INPUT", socket_type="NodeSocketColor")
    group.interface.new_socket("Shader", in_out="OUTPUT", socket_type="NodeSocketShader")
    gin, gout = group.nodes.new("NodeGroupInput"), group.nodes.new("NodeGroupOutput")
    inner = group.nodes.new("ShaderNodeBsdfPrincipled")
    group.links.new(gin.outputs["Color"], inner.inputs["Base Color"])
    group.links.new(inner.outputs["BSDF"], gout.inputs["Shader"])
    node = tree.nodes.new("ShaderNodeGroup")
    node.node_tree = group
    tree.links.new(colour, node.inputs["Color"])
    tree.links.new(node.outputs["Shader"], tree.nodes["Material Output"].inputs["Surface"])
    return node


@pytest.fixture(scope="session")
def lf():
    """Helpers for the tests: ``lf.add_sun``, ``lf.add_point``, ``lf.pixels``, ``lf.ROOT``,
    ``lf.ADDON``, ``lf.reset_file``, ``lf.fresh_file``, ``lf.build_floor_scene`` (the
    scene of :func:`floor_scene`, for fixtures wider than one test) and
    ``lf.wrap_bsdf_in_group``."""
    from types import SimpleNamespace

    return SimpleNamespace(add_sun=add_sun, add_point=add_point, pixels=pixels, ROOT=ROOT,
                           ADDON=ADDON, reset_file=reset_file, fresh_file=fresh_file,
                           build_floor_scene=build_floor_scene,
                           wrap_bsdf_in_group=wrap_bsdf_in_group)


def pixels(image):
    """(H, W) R channel of ``image`` as float32."""
    a = np.empty(len(image.pixels), dtype=np.float32)
    image.pixels.foreach_get(a)
    w, h = image.size
    return a.reshape(h, w, image.channels)[..., 0]
