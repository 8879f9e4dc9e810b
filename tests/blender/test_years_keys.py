"""Keyframed years are linear between keys: the api, the panel's Key Years button, keys
inserted with I (as ``scene.keyframe_insert``), and a fresh Blender without LightFade."""

import subprocess
import sys

import bpy
import pytest

PATH = '["lightfade_years"]'


def _years_at(scene, frame):
    scene.frame_set(frame)
    return float(scene["lightfade_years"])


def _curve(scene):
    from lightfade_addon.blender.aging.years import years_fcurve

    return years_fcurve(scene)


def test_api_keys_are_linear(blender):
    from lightfade_addon import api

    scene = bpy.context.scene
    api.keyframe_years(scene, [(1, 0.0), (101, 50.0)])
    assert _years_at(scene, 11) == pytest.approx(5.0, abs=1e-5)     # Bezier: 1.4
    assert _years_at(scene, 51) == pytest.approx(25.0, abs=1e-5)
    assert {p.interpolation for p in _curve(scene).keyframe_points} == {"LINEAR"}


def test_the_key_years_button_keys_linearly(blender):
    scene = bpy.context.scene
    for frame, years in ((1, 0.0), (101, 50.0)):
        scene.frame_set(frame)
        scene.lightfade.years = years
        assert bpy.ops.lightfade.key_years() == {"FINISHED"}
    assert _years_at(scene, 11) == pytest.approx(5.0, abs=1e-5)
    assert _years_at(scene, 51) == pytest.approx(25.0, abs=1e-5)


def test_keys_inserted_with_i_become_linear(blender):
    """I over the Years field inserts a Bezier key (Blender's default): the next depsgraph
    update makes it linear; a key the artist set to another interpolation stays."""
    scene = bpy.context.scene
    for frame, years in ((1, 0.0), (101, 50.0)):
        scene["lightfade_years"] = years
        assert scene.keyframe_insert(PATH, frame=frame)
    assert _curve(scene).keyframe_points[0].interpolation == "BEZIER"
    bpy.context.view_layer.update()                  # what the UI does after the key
    assert _years_at(scene, 11) == pytest.approx(5.0, abs=1e-5)
    assert _years_at(scene, 51) == pytest.approx(25.0, abs=1e-5)
    _curve(scene).keyframe_points[0].interpolation = "SINE"
    bpy.context.view_layer.update()
    assert _curve(scene).keyframe_points[0].interpolation == "SINE"
    assert _years_at(scene, 51) != pytest.approx(25.0, abs=0.1)


def test_saving_makes_keys_linear(blender, tmp_path):
    from lightfade_addon.blender import handlers

    scene = bpy.context.scene
    for frame, years in ((1, 0.0), (101, 50.0)):
        scene["lightfade_years"] = years
        scene.keyframe_insert(PATH, frame=frame)
    handlers.on_save()
    assert {p.interpolation for p in _curve(scene).keyframe_points} == {"LINEAR"}


FRESH = """
import sys, bpy
bpy.context.preferences.filepaths.use_scripts_auto_execute = False
bpy.ops.wm.open_mainfile(filepath={path!r}, load_ui=False)
assert not hasattr(bpy.types.Scene, "lightfade"), "LightFade must not be installed here"
scene = bpy.context.scene
for frame in (11, 51):
    scene.frame_set(frame)
    print("YEARS", frame, float(scene["lightfade_years"]))
"""


def test_linear_keys_play_without_lightfade(blender, tmp_path):
    """The saved linear F-curve is plain Blender data: 5.0 and 25.0 years there too."""
    from lightfade_addon import api

    api.keyframe_years(bpy.context.scene, [(1, 0.0), (101, 50.0)])
    path = tmp_path / "keys.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path), copy=True)
    env = {k: v for k, v in __import__("os").environ.items() if k != "PYTHONPATH"}
    proc = subprocess.run([sys.executable, "-c", FRESH.format(path=str(path))],
                          cwd=str(tmp_path), env=env, capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0, proc.stderr[-2000:]
    years = {int(f): float(y) for _w, f, y in
             (line.split() for line in proc.stdout.splitlines() if line.startswith("YEARS"))}
    assert years[11] == pytest.approx(5.0, abs=1e-5)
    assert years[51] == pytest.approx(25.0, abs=1e-5)
