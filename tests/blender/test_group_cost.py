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


def test_every_node_of_the_group_reaches_its_output(group):
    dead = [n.name for n in group.nodes if n.type != "GROUP_OUTPUT"
            and not any(o.is_linked for o in n.outputs)]
    assert dead == []


def test_no_float_feeds_a_vector_input(group):
    converted = [(l.from_node.name, l.to_node.name) for l in group.links
                 if l.from_socket.type == "VALUE" and l.to_socket.type in ("VECTOR", "RGBA")]
    assert converted == []
