"""The Blender adapter of the progress protocol: the window's indicator, or lines headless."""

import types

import pytest

bpy = pytest.importorskip("bpy")

from lightfade_addon.blender import progress as adapter  # noqa: E402


class FakeWindowManager:
    def __init__(self):
        self.calls = []

    def progress_begin(self, low, high):
        self.calls.append(("begin", low, high))

    def progress_update(self, value):
        self.calls.append(("update", value))

    def progress_end(self):
        self.calls.append(("end",))


class FakeWorkspace:
    def __init__(self):
        self.status = []

    def status_text_set(self, text):
        self.status.append(text)


def ui_context(monkeypatch):
    monkeypatch.setattr(adapter, "bpy", types.SimpleNamespace(
        app=types.SimpleNamespace(background=False)))
    return types.SimpleNamespace(window=object(), window_manager=FakeWindowManager(),
                                 workspace=FakeWorkspace())


def test_headless_prints_one_line_per_step(blender, capsys):
    with adapter.window_progress(bpy.context, "LightFade") as progress:
        progress(0.0, "baking Floor <- Sun")
        progress(0.25, "baking Floor <- Sun")
        progress(0.5, "baking Floor <- Lamp")
    err = capsys.readouterr().err.splitlines()
    assert err == ["LightFade:   0%  baking Floor <- Sun", "LightFade:  50%  baking Floor <- Lamp"]


def test_in_the_ui_it_drives_the_window_manager(monkeypatch):
    context = ui_context(monkeypatch)
    with adapter.window_progress(context) as progress:
        progress(0.5, "half")
        progress(2.0, "beyond")
    assert context.window_manager.calls == [("begin", 0, 1000), ("update", 500),
                                            ("update", 1000), ("end",)]
    assert context.workspace.status == ["LightFade: half", "LightFade: beyond", None]


def test_a_modal_operator_ends_it_itself(monkeypatch):
    context = ui_context(monkeypatch)
    progress = adapter.WindowProgress(context, "Bake")
    progress(0.25, "Floor <- Sun")                 # one timer tick
    progress(0.75, "Floor <- Lamp")                # the next
    progress.end()                                 # finish or cancel
    assert [c[0] for c in context.window_manager.calls] == ["begin", "update", "update", "end"]
    assert context.workspace.status[-1] is None


def test_the_indicator_ends_on_error(monkeypatch):
    context = ui_context(monkeypatch)
    with pytest.raises(RuntimeError):
        with adapter.window_progress(context) as progress:
            progress(0.1, "start")
            raise RuntimeError("bake failed")
    assert context.window_manager.calls[-1] == ("end",)
    assert context.workspace.status[-1] is None


def test_a_long_age_says_what_it_does_on_the_console(floor_scene, monkeypatch, capsys):
    """Age through the API (no progress of the caller's) prints its steps once it has
    run two seconds (asked for two, here made zero): each material's step and the end."""
    from lightfade_addon import api
    from lightfade_addon import progress as core_progress
    from lightfade_addon.blender.aging import prepare

    real = core_progress.console_after
    asked = []

    def after(progress, seconds, label):
        asked.append(seconds)
        return real(progress, 0.0, label)

    monkeypatch.setattr(prepare, "console_after", after)
    api.bake(bpy.context.scene)
    capsys.readouterr()
    api.age_scene(bpy.context.scene, years=3)
    err = capsys.readouterr().err.splitlines()
    assert asked == [2.0]                       # past two seconds
    assert any(line.startswith("LightFade Age:") and "aged 1 material" in line for line in err)
    assert any(line.startswith("LightFade Age:") and "aging group" in line for line in err)


def test_age_builds_the_tables_ahead_and_uses_them(floor_scene, monkeypatch):
    """The colour tables Age needs are built before its per-material steps (together,
    core.aging.tablebuild.build_tables) and each step takes its table from there, not
    from a build of its own; nothing is kept once Age is over."""
    from lightfade_addon import api
    from lightfade_addon.blender.aging import data

    def no_build(*args, **kwargs):
        raise AssertionError("a step built its own table")

    api.bake(bpy.context.scene)
    monkeypatch.setattr(data, "load_or_build", no_build)
    api.age_scene(bpy.context.scene, years=3)
    assert any(i.name.startswith(data.TABLE_PREFIX) for i in bpy.data.images)
    assert data._BUILT == {}
