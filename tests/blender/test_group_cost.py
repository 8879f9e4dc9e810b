"""The aging group's shape where it costs render time: every node reaches the output,
and no float feeds a vector input (Cycles would add a conversion instruction)."""

import pytest

bpy = pytest.importorskip("bpy")

from tests.blender.test_material_aging import _bake_and_age, textured  # noqa: E402,F401


@pytest.fixture
def group(textured, lf):  # noqa: F811
    """The group of two spectra (a sun and an incandescent lamp: the light-mix stage)."""
    from lightfade_addon.blender.aging.copies import GROUP_NODE, copies_of

    lamp = lf.add_point(power=400.0, location=(-0.5, -0.5, 1.0))
    lamp.data.lightfade.spectrum = "INCANDESCENT"
    _bake_and_age(years=5)
    (copy,) = copies_of(bpy.data.materials["Carpet"])
    return copy.node_tree.nodes[GROUP_NODE].node_tree


def _trees(group):
    """The copy's group and the table's evaluation group inside it."""
    inner = [n.node_tree for n in group.nodes if n.type == "GROUP"]
    assert len(inner) == 1
    return [group, inner[0]]


def test_every_node_of_the_group_reaches_its_output(group):
    dead = [n.name for tree in _trees(group) for n in tree.nodes if n.type != "GROUP_OUTPUT"
            and not any(o.is_linked for o in n.outputs)]
    assert dead == []


def test_no_float_feeds_a_vector_input(group):
    converted = [(l.from_node.name, l.to_node.name) for tree in _trees(group)
                 for l in tree.links
                 if l.from_socket.type == "VALUE" and l.to_socket.type in ("VECTOR", "RGBA")]
    assert converted == []


def test_copies_of_one_table_share_its_evaluation(group):
    """A second material aged with the same recipe under the same lights reads the same
    evaluation group: the file keeps the table's nodes once."""
    from lightfade_addon.blender.aging.copies import GROUP_NODE, copies_of
    from lightfade_addon.blender.aging.group import EVAL_PREFIX

    floor = bpy.data.objects["Floor"]
    second = bpy.data.materials["Carpet"].copy()
    second.name = "Carpet 2"
    floor.data.materials.append(second)
    for poly in list(floor.data.polygons)[: len(floor.data.polygons) // 2]:
        poly.material_index = 1
    assert bpy.ops.lightfade.age(years=5) == {"FINISHED"}
    trees = [copies_of(m)[0].node_tree.nodes[GROUP_NODE].node_tree
             for m in (bpy.data.materials["Carpet"], second)]
    assert trees[0] != trees[1]
    assert _trees(trees[0])[1] == _trees(trees[1])[1]
    assert len([g for g in bpy.data.node_groups if g.name.startswith(EVAL_PREFIX)]) == 1
