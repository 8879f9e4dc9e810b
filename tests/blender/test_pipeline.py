"""The scene commands for pipelines, driven the way a pipeline calls them.

Every command runs in a subprocess through the ``bpy`` module, by two entry points:

* ``blender -c lightfade ARGS`` — there is no Blender binary here, so :data:`BLENDER_C`
  enables the add-on, catches the callback its ``register()`` hands to
  ``bpy.utils.register_cli_command`` and calls it with ``ARGS`` as a list of strings,
  which is what Blender's ``-c`` does (``bpy_cli_command_exec``), and exits with the int
  it returns;
* ``python -m lightfade_addon scene ARGS``.

Scenes are tiny (an 8x8 albedo, 64 px maps, 2 samples, 16x16 renders).
"""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
bpy = pytest.importorskip("bpy")

#: ``blender -c lightfade ARGS`` through the bpy module: the registered callback, called
#: with the arguments after the command name, its int return value the exit status.
BLENDER_C = r"""
import os
import sys
import bpy
import addon_utils  # importable once bpy is

caught = {}
real = bpy.utils.register_cli_command

def spy(command, execute):
    caught[command] = execute
    return real(command, execute)

bpy.utils.register_cli_command = spy
addon_utils.enable("lightfade_addon", default_set=False)
bpy.utils.register_cli_command = real
try:
    status = caught["lightfade"](sys.argv[1:])
except SystemExit as exc:       # Blender turns SystemExit into the exit status too
    status = exc.code
assert isinstance(status, int), f"the command must return an int, got {status!r}"
# Blender exits through WM_exit; the bpy module of 4.2 segfaults at interpreter exit
# once an add-on is registered, so end here the way Blender would, with the status.
sys.stdout.flush()
sys.stderr.flush()
os._exit(status)
"""

#: Builds good.blend (an aging floor, a sun, a camera), empty.blend (nothing enabled)
#: and nocam.blend (like good.blend without a camera) into argv[1].
BUILD = r"""
import math, os, sys
import bpy
import addon_utils  # importable once bpy is
import numpy as np

out = sys.argv[1]


def scene(enabled=True, camera=True):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    addon_utils.enable("lightfade_addon", default_set=False)
    bpy.ops.mesh.primitive_plane_add(size=2.0)
    floor = bpy.context.active_object
    floor.name = "Floor"
    mat = bpy.data.materials.new("Carpet")
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    albedo = bpy.data.images.new("CarpetAlbedo", 8, 8)
    albedo.pixels.foreach_set(np.linspace(0.2, 0.9, 8 * 8 * 4, dtype=np.float32))
    albedo.pack()
    tex = mat.node_tree.nodes.new("ShaderNodeTexImage")
    tex.image = albedo
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    mat.node_tree.links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])
    mat.lightfade.enabled = enabled
    mat.lightfade.blue_wool = 1
    floor.data.materials.append(mat)
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    sun.rotation_euler = (math.radians(30), 0, 0)
    s = bpy.context.scene
    s.collection.objects.link(sun)
    if camera:
        cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
        cam.location = (0.0, 0.0, 3.0)
        s.collection.objects.link(cam)
        s.camera = cam
    s.lightfade_bake.quality = "CUSTOM"
    s.lightfade_bake.denoise = False
    s.lightfade_bake.texels_per_metre = 32.0      # the 2 m floor: 64 px
    s.lightfade.bake_resolution = 64
    s.lightfade.bake_samples = 2
    s.lightfade.bake_margin = 1
    s.render.engine = "CYCLES"
    s.cycles.samples = 2
    s.render.resolution_x = s.render.resolution_y = 16
    s.render.resolution_percentage = 100
    s.render.image_settings.file_format = "PNG"


for name, kw in (("good", {}), ("empty", {"enabled": False}), ("nocam", {"camera": False})):
    scene(**kw)
    bpy.ops.wm.save_as_mainfile(filepath=os.path.join(out, name + ".blend"))
sys.stdout.flush()
os._exit(0)     # past the bpy 4.2 module's segfault at interpreter exit
"""

#: Prints a JSON summary of a .blend file's LightFade state.
PROBE = r"""
import json, os, sys
import bpy
import addon_utils  # importable once bpy is

addon_utils.enable("lightfade_addon", default_set=False)
bpy.ops.wm.open_mainfile(filepath=sys.argv[1])
s = bpy.context.scene
floor = s.objects["Floor"]
maps = {m.name: list(m.image.size) for m in floor.lightfade.exposure_maps}
copies = [m for m in bpy.data.materials if m.lightfade.source is not None]
aged = copies[0].lightfade.aged_image if copies else None
print("PROBE" + json.dumps({
    "maps": maps, "years": s.lightfade.years, "density": s.lightfade_bake.texels_per_metre,
    "aged": aged.name if aged else None, "aged_packed": bool(aged and aged.packed_file),
    "grids": len(s.get("lightfade_grids", {})),
}), flush=True)
os._exit(0)     # past the bpy 4.2 module's segfault at interpreter exit
"""


def _env():
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")])
    return env


def _python(*args, cwd):
    return subprocess.run([sys.executable, *map(str, args)], cwd=cwd, env=_env(),
                          capture_output=True, text=True, timeout=300)


ENTRIES = {
    "blender -c": lambda *a, cwd: _python("-c", BLENDER_C, *a, cwd=cwd),
    "python -m": lambda *a, cwd: _python("-m", "lightfade_addon", "scene", *a, cwd=cwd),
}


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    src = tmp_path_factory.mktemp("scenes")
    proc = _python("-c", BUILD, src, cwd=src)
    assert proc.returncode == 0, proc.stderr[-2000:]
    (src / "bad.blend").write_text("this is not a blend file\n")
    return src


@pytest.fixture
def work(files, tmp_path):
    """A fresh folder with copies of the scenes (the tests may overwrite them)."""
    for p in files.iterdir():
        (tmp_path / p.name).write_bytes(p.read_bytes())
    return tmp_path


def probe(path):
    proc = _python("-c", PROBE, path, cwd=path.parent)
    assert proc.returncode == 0, proc.stderr[-2000:]
    line = next(x for x in proc.stdout.splitlines() if x.startswith("PROBE"))
    return json.loads(line[len("PROBE"):])


def leftovers(folder):
    """Temporary or backup files a run must not leave behind."""
    return sorted(p.name for p in folder.rglob("*")
                  if p.name.startswith(".") or p.suffix in (".blend1", ".blend@")
                  or p.name.endswith("@"))


def refusals(stderr):
    return [x for x in stderr.splitlines() if x.startswith("lightfade: ")]


# ------------------------------------------------------------------------- registration


class TestRegistration:
    def test_register_adds_the_command_and_unregister_removes_it(self, blender, monkeypatch):
        import addon_utils

        calls = []
        real_add, real_remove = bpy.utils.register_cli_command, bpy.utils.unregister_cli_command

        def add(command, execute):
            handle = real_add(command, execute)
            calls.append(("add", command, execute, handle))
            return handle

        def remove(handle):
            calls.append(("remove", handle))
            return real_remove(handle)

        monkeypatch.setattr(bpy.utils, "register_cli_command", add)
        monkeypatch.setattr(bpy.utils, "unregister_cli_command", remove)
        addon_utils.disable("lightfade_addon", default_set=True)
        calls.clear()
        addon_utils.enable("lightfade_addon", default_set=True)
        addon_utils.disable("lightfade_addon", default_set=True)
        from lightfade_addon.blender import cli_command

        assert [c[:3] for c in calls[:1]] == [("add", "lightfade", cli_command.execute)]
        assert calls[1:] == [("remove", calls[0][3])]
        addon_utils.enable("lightfade_addon", default_set=True)


# --------------------------------------------------------------------------------- info


@pytest.mark.parametrize("entry", sorted(ENTRIES))
def test_info_json_names_paths_emitters_and_stale(work, entry):
    proc = ENTRIES[entry]("info", "good.blend", "missing.blend", "--json", cwd=work)
    assert proc.returncode == 1, proc.stderr[-2000:]
    report, missing = json.loads(proc.stdout)["files"]      # stdout is the JSON only
    assert missing == {"file": str(work / "missing.blend"), "error": "no such file"}
    assert report["file"] == str(work / "good.blend")
    assert [(e["object"], e["material"], e["status"]) for e in report["would_age"]] == [
        ("Floor", "Carpet", "not aged")]
    problem, = report["would_age"][0]["problems"]
    assert problem.startswith("Object 'Floor' has no exposure maps") and "Bake" in problem
    assert [(g["name"], g["emitters"], g["spectrum"]) for g in report["light_groups"]] == [
        ("Sun", [["Sun", "sun"]], "daylight-glass")]
    assert report["doses"] == []
    assert report["stale"] == ["Object 'Floor' has no exposure maps (bake; age bakes them)"]
    assert leftovers(work) == []


def test_info_json_to_a_file(work):
    proc = ENTRIES["blender -c"]("info", "empty.blend", "--json", "reports/info.json", cwd=work)
    assert proc.returncode == 0, proc.stderr[-2000:]
    report, = json.loads((work / "reports" / "info.json").read_text())["files"]
    assert report["file"] == str(work / "empty.blend") and report["would_age"] == []
    assert "lightfade info: 1 file(s): 1 done" in proc.stdout
    assert leftovers(work) == []


def test_info_text_of_an_aged_file_shows_doses(work):
    assert ENTRIES["python -m"]("age", "good.blend", "--years", "5", cwd=work).returncode == 0
    proc = ENTRIES["blender -c"]("info", "good_aged.blend", "empty.blend", cwd=work)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert "Floor / Carpet: direct (printed-paper, Blue Wool 1; aged)" in proc.stdout
    assert "Floor <- Sun: brightest texel" in proc.stdout
    assert "would age: nothing" in proc.stdout          # empty.blend
    assert "stale: nothing" in proc.stdout


# ------------------------------------------------------------------------- bake and age


def test_bake_writes_a_new_file_with_the_override(work):
    before = (work / "good.blend").read_bytes()
    proc = ENTRIES["blender -c"]("bake", "good.blend", "--density", "20", cwd=work)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert (work / "good.blend").read_bytes() == before
    state = probe(work / "good_baked.blend")
    assert state["maps"] == {"Sun": [40, 40]} and state["density"] == 20.0
    assert state["aged"] is None
    assert leftovers(work) == []


@pytest.mark.parametrize("entry", sorted(ENTRIES))
def test_age_bakes_ages_and_saves_to_output(work, entry):
    before = (work / "good.blend").read_bytes()
    proc = ENTRIES[entry]("age", "good.blend", "--years", "12.5", "--output", "out/shot.blend",
                          cwd=work)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert (work / "good.blend").read_bytes() == before
    state = probe(work / "out" / "shot.blend")
    assert state["maps"] == {"Sun": [64, 64]}
    assert state["years"] == 12.5 and state["aged"].startswith("LF_Aged_Carpet") and state["aged_packed"]
    assert state["grids"] >= 1                           # render nodes never simulate
    assert "lightfade age: 1 file(s): 1 done" in proc.stdout
    assert leftovers(work) == []


def test_age_never_overwrites_the_input_unless_in_place(work):
    before = (work / "good.blend").read_bytes()
    proc = ENTRIES["python -m"]("age", "good.blend", "--years", "3", "--output", "good.blend",
                                cwd=work)
    assert proc.returncode == 1
    assert (work / "good.blend").read_bytes() == before
    assert refusals(proc.stderr) == [
        f"lightfade: good.blend: the output {work / 'good.blend'} is the input file: give "
        "another --output, or --in-place to overwrite it"]
    proc = ENTRIES["python -m"]("age", "good.blend", "--years", "3", "--in-place", cwd=work)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert probe(work / "good.blend")["years"] == 3.0
    assert leftovers(work) == []                         # no good.blend1 backup


def test_a_failed_save_leaves_the_target_untouched(blender, tmp_path, monkeypatch):
    from lightfade_addon.pipeline import files

    target = tmp_path / "shot.blend"
    target.write_bytes(b"previous")

    def crash(src, dst):
        raise OSError("disk full")

    monkeypatch.setattr(files.os, "replace", crash)
    with pytest.raises(files.Refused, match="could not write .*shot.blend \\(disk full\\)"):
        files.save_blend(str(target))
    assert target.read_bytes() == b"previous"
    assert leftovers(tmp_path) == []


# ------------------------------------------------------------------------------- render


def _pixels(path):
    image = bpy.data.images.load(str(path))
    try:
        a = np.empty(len(image.pixels), dtype=np.float32)
        image.pixels.foreach_get(a)
        return a
    finally:
        bpy.data.images.remove(image)


def test_render_years_writes_one_still_per_value(work, blender):
    proc = ENTRIES["blender -c"]("render-years", "good.blend", "--years", "0", "40",
                                 "--output", "stills", cwd=work)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert sorted(p.name for p in (work / "stills").iterdir()) == ["good_0y.png", "good_40y.png"]
    young, old = _pixels(work / "stills" / "good_0y.png"), _pixels(work / "stills" / "good_40y.png")
    assert young.max() > 0.05                            # the floor is lit
    assert np.abs(young - old).max() > 0.02              # and it faded
    assert not (work / "good_aged.blend").exists() and leftovers(work) == []


def test_render_years_without_camera_is_refused(work):
    proc = ENTRIES["python -m"]("render-years", "nocam.blend", "--years", "1",
                                "--output", "stills", cwd=work)
    assert proc.returncode == 1
    assert refusals(proc.stderr) == [
        "lightfade: nocam.blend: scene 'Scene' has no camera: set one (Scene Properties > "
        "Camera) to render from"]


# -------------------------------------------------------------------------------- batch


@pytest.mark.parametrize("entry", sorted(ENTRIES))
def test_batch_names_the_failures_and_finishes_the_rest(work, entry):
    (work / "again.blend").write_bytes((work / "good.blend").read_bytes())
    names = ["good.blend", "missing.blend", "bad.blend", "empty.blend", "again.blend"]
    proc = ENTRIES[entry]("age", *names, "--years", "10", "--output", "aged", cwd=work)
    assert proc.returncode == 1
    assert sorted(p.name for p in (work / "aged").iterdir()) == ["again.blend", "good.blend"]
    assert probe(work / "aged" / "again.blend")["years"] == 10.0
    lines = refusals(proc.stderr)
    assert len(lines) == 3
    assert lines[0] == "lightfade: missing.blend: no such file"
    assert lines[1].startswith("lightfade: bad.blend: not a .blend file (")
    assert lines[2].startswith("lightfade: empty.blend: nothing to age: no material")
    table = proc.stdout[proc.stdout.index("lightfade age: 5 file(s): 2 done, 3 refused"):]
    rows = [x.split()[:3] for x in table.splitlines()[2:]]
    assert [r[0] for r in rows] == ["done", "refused", "refused", "refused", "done"]
    assert [r[2] for r in rows] == names
    assert leftovers(work) == []


# -------------------------------------------------------------------------------- usage


@pytest.mark.parametrize("args, message", [
    ((), "the following arguments are required"),
    (("age", "good.blend"), "the following arguments are required: --years"),
    (("age", "good.blend", "--years", "-1"), "years must be a number >= 0"),
    (("age", "good.blend", "--years", "1", "--in-place", "--output", "x"), "exclude each other"),
    (("bake", "good.blend", "empty.blend", "--output", "x.blend"), "need a folder"),
    (("bake", "good.blend", "--resolution", "3"), "--resolution 3: must be between 64 and 8192"),
    (("bake", "good.blend", "--quality", "best"), "--quality best: must be one of preview, "),
    (("bake", "good.blend", "--samples", "4"), "--samples applies with --quality custom"),
    (("frobnicate", "good.blend"), "invalid choice"),
])
def test_usage_errors_exit_2_with_one_line(work, args, message):
    proc = ENTRIES["blender -c"](*args, cwd=work)
    assert proc.returncode == 2, proc.stdout[-1000:] + proc.stderr[-1000:]
    errors = [x for x in proc.stderr.splitlines() if x.startswith("lightfade: error:")]
    assert len(errors) == 1 and message in errors[0]
    assert sorted(p.name for p in work.iterdir()) == sorted(
        ["good.blend", "empty.blend", "nocam.blend", "bad.blend"])


def test_help_exits_0(work):
    proc = ENTRIES["python -m"]("age", "--help", cwd=work)
    assert proc.returncode == 0
    assert "--years N" in proc.stdout and "--in-place" in proc.stdout


def test_a_blend_this_blender_cannot_read_is_named_as_such(blender, tmp_path):
    from lightfade_addon.pipeline import files

    future = tmp_path / "future.blend"
    future.write_bytes(b"BLENDER-v999" + bytes(200))
    with pytest.raises(files.Refused, match=f"^Blender {bpy.app.version_string} cannot read "
                                            "this .blend file .*saved by a newer Blender\\?$"):
        files.open_blend(str(future))
