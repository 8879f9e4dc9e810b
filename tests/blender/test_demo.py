"""The demo (``python -m scenes.demo``) end to end, in its ``--quick`` form: the room is
built, tagged, baked, aged and rendered at a tiny size, and every output is written.

The end-to-end run is a study (``-m slow``, ~30 s): what it finds in the add-on is
tested on small scenes elsewhere (baking, aging, saving aged pixels: test_aging.py,
test_state.py; the scenes themselves: test_scenes.py).  Here, in the default run: the
demo's tags become LightFade settings, and its labels.
"""

import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

bpy = pytest.importorskip("bpy")
import addon_utils  # noqa: E402
from PIL import Image  # noqa: E402

from scenes import demo, demo_figures, tags as demo_tags  # noqa: E402

pytestmark = pytest.mark.blender


@pytest.fixture(scope="module")
def quick_room(tmp_path_factory):
    out = tmp_path_factory.mktemp("demo")
    result = demo.main(["--quick", "--scenes", "room", "--out", str(out)])
    yield out, result
    addon_utils.disable(demo.ADDON, default_set=True)
    bpy.ops.wm.read_factory_settings(use_empty=True)


def pixels(path):
    return np.asarray(Image.open(path).convert("RGB"), dtype=np.float32) / 255.0


@pytest.mark.slow
def test_writes_frames_contact_sheet_gif_and_blend(quick_room):
    out, result = quick_room
    years = demo.SCENES["room"]["quick_years"]
    for y in years:
        assert (out / f"room_{demo_figures.years_slug(y)}.png").is_file()
    assert (out / f"room_reveal_{demo_figures.years_slug(years[-1])}.png").is_file()
    assert (out / "room_dresser_reveal_25y.png").is_file()
    assert (out / "contact_room.png").is_file()
    gif = Image.open(out / "room.gif")
    assert gif.n_frames == len(years) + 1  # the years and the reveal
    assert (out / "room.blend").is_file()
    assert result["out"] == str(out)


@pytest.mark.slow
def test_aged_frame_differs_from_the_new_one(quick_room):
    out, _ = quick_room
    new, aged = pixels(out / "room_0y.png"), pixels(out / "room_25y.png")
    assert new.shape == aged.shape
    assert np.abs(aged - new).mean() > 0.005


@pytest.mark.slow
def test_reveal_frame_differs_from_the_aged_one(quick_room):
    out, _ = quick_room
    aged, reveal = pixels(out / "room_25y.png"), pixels(out / "room_reveal_25y.png")
    assert np.abs(reveal - aged).mean() > 0.005  # the rug and lamp are gone


@pytest.mark.slow
def test_tags_became_lightfade_settings(quick_room):
    _, result = quick_room
    tags = result["results"]["room"]["tags"]
    assert tags["materials"]["Rug_Wool"] == {"recipe": "dyed-fabric", "blue_wool": 4}
    assert tags["materials"]["Floor_Oak"]["recipe"] == "bare-wood"
    assert tags["emitters"]["Sun"]["spectrum"] == "daylight-glass"
    assert tags["emitters"]["Lamp"]["spectrum"] == "incandescent"
    assert tags["emitters"]["World"]["hours_per_day"] == 10.0


@pytest.mark.slow
def test_saved_blend_keeps_the_aging(quick_room):
    """The saved room carries each aged material's table image (packed) and group, and
    the years it was saved at."""
    out, _ = quick_room
    bpy.ops.wm.open_mainfile(filepath=str(out / "room.blend"))
    copies = [m for m in bpy.data.materials if m.lightfade.source is not None]
    assert len(copies) == 5
    for copy in copies:
        props = copy.lightfade
        for im in (props.table_image,):
            assert im is not None and im.packed_file is not None, copy.name
            assert tuple(im.size) != (0, 0), im.name
        assert "LightFade Aging" in copy.node_tree.nodes or any(
            n.type == "GROUP" and "LightFade Aging" in n.node_tree.nodes
            for n in copy.node_tree.nodes if n.node_tree is not None), copy.name
    rug = bpy.data.materials["Rug_Wool"]
    assert len([m for m in copies if m.lightfade.source == rug]) == 1
    assert bpy.context.scene["lightfade_years"] == pytest.approx(25.0)


def test_tags_become_lightfade_settings_on_a_small_room(blender):
    """The room's tags, applied as the demo applies them (without a bake)."""
    from scenes import room

    addon_utils.disable(demo.ADDON, default_set=True)     # as demo.run_scene: build
    room.build(resolution=32)                             # (a factory reset), then enable
    addon_utils.enable(demo.ADDON, default_set=True)
    tags = demo_tags.apply_tags(bpy.context.scene)
    assert tags["materials"]["Rug_Wool"] == {"recipe": "dyed-fabric", "blue_wool": 4}
    assert tags["materials"]["Floor_Oak"]["recipe"] == "bare-wood"
    assert tags["emitters"]["Sun"]["spectrum"] == "daylight-glass"
    assert tags["emitters"]["Lamp"]["spectrum"] == "incandescent"
    assert tags["emitters"]["World"]["hours_per_day"] == 10.0
    rug = bpy.data.materials["Rug_Wool"].lightfade
    assert rug.enabled and rug.recipe == "DYED_FABRIC" and rug.blue_wool == 4
    lamp = bpy.data.lights["Lamp"].lightfade
    assert lamp.enabled and lamp.spectrum == "INCANDESCENT"
    assert bpy.context.scene.world.lightfade.hours_per_day == 10.0
    # the room stands at 52° N, its window (x = -2 wall) facing south: annual daylight
    assert tags["daylight"] == room.PLACE
    day = bpy.context.scene.lightfade_daylight
    assert (day.latitude, day.north) == (52.0, -90.0) and day.enabled
    from lightfade_addon.blender.bake import find_groups

    bpy.context.view_layer.update()
    assert {g.name for g in find_groups(bpy.context.scene)} == {"Lamp", "Daylight"}


def test_the_summary_counts_every_frame_rendered():
    """The room renders 5 years, the reveal, 3 dresser and 2 floor views: 11 frames."""
    outputs = dict(frames=[f"room_{y}y.png" for y in (0, 1, 3, 10, 25)],
                   reveal=["room_reveal_25y.png"],
                   extra={"Camera.Dresser": ["d0.png", "d25.png", "dr.png"],
                          "Camera.Floor": ["f0.png", "f25.png"]},
                   contact="/o/contact_room.png", gif="/o/room.gif", blend="/o/room.blend")
    assert demo.outputs_line("room", outputs) == (
        "room: 11 frames rendered (5 of the years, 1 reveal, 5 from Camera.Dresser and "
        "Camera.Floor), contact_room.png, room.gif, room.blend")
    one = dict(frames=["g0.png"], reveal=[], extra={}, contact="/o/c.png", blend="/o/g.blend")
    assert demo.outputs_line("gallery", one) == (
        "gallery: 1 frame rendered (1 of the years), c.png, g.blend")


def test_labels():
    assert demo_figures.years_label(0) == "0 years"
    assert demo_figures.years_label(1) == "1 year"
    assert demo_figures.years_label(7 / 365) == "7 days"
    assert demo_figures.years_label(0.25) == "3 months"
    assert demo_figures.years_slug(25) == "25y"
    assert demo_figures.years_slug(1 / 12) == "1mo"
