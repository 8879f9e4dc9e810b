"""The scene commands for pipelines, driven the way a pipeline calls them.

Most commands run in this process (bpy is imported already) through the callback the
add-on registers for ``blender -c lightfade`` (:func:`..blender.cli_command.execute`,
see :class:`TestRegistration`), with stdout and stderr written to the real file
descriptors as in a process of their own; the ``blender`` fixture resets the file the
commands leave open.  Each entry point also runs in a real process of its own (started
as soon as the scene files exist, beside the module's tests; checked last):

* ``blender -c lightfade ARGS`` — there is no Blender binary here, so :data:`BLENDER_C`
  enables the add-on, catches the callback its ``register()`` hands to
  ``bpy.utils.register_cli_command`` and calls it with ``ARGS`` as a list of strings,
  which is what Blender's ``-c`` does (``bpy_cli_command_exec``), and exits with the int
  it returns (:func:`test_usage_error_in_a_real_process`);
* ``python -m lightfade_addon scene ARGS`` (:func:`test_info_json_in_a_real_process`,
  :func:`test_a_denoised_bake_in_a_real_process_prints_only_its_own_lines`).

What Blender prints from C (EGL, the compositor's status lines, a save's report) goes
straight to the file descriptors: only a process of its own shows all of it.

Scenes are tiny: the floor scene of conftest.py (an 8x8 albedo) with 64 px maps,
2 samples and 16x16 renders.
"""

import contextlib
import functools
import io
import json
import os
import re
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from types import SimpleNamespace

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


def _env():
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")])
    return env


def _python(*args, cwd, run):
    return run([sys.executable, *map(str, args)], cwd=cwd, env=_env(), timeout=300)


#: The real processes: ``blender -c lightfade ARGS`` and ``python -m lightfade_addon scene ARGS``
#: (``run``: :meth:`EarlyJobs.run`, tests/conftest.py).
PROCESSES = {
    "blender -c": lambda *a, cwd, run: _python("-c", BLENDER_C, *a, cwd=cwd, run=run),
    "python -m": lambda *a, cwd, run: _python("-m", "lightfade_addon", "scene", *a, cwd=cwd,
                                              run=run),
}


def _scene(lf, enabled=True, camera=True):
    """conftest's floor scene, set up for the commands: printed paper's own Blue Wool
    class (its recipe then is the core's, whose unmixing table other tests have built),
    64 px maps with 2 samples, a camera 3 m above the floor rendering 16x16 PNGs with
    2 samples."""
    parts = lf.build_floor_scene()
    mat = parts["material"]
    mat.lightfade.enabled = enabled
    mat.lightfade.blue_wool = 2
    s = bpy.context.scene
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


@pytest.fixture(scope="module")
def files(tmp_path_factory, lf, early_jobs):
    """good.blend (an aging floor, a sun, a camera), empty.blend (nothing enabled),
    nocam.blend (like good.blend without a camera) and bad.blend (not a .blend).

    Then starts :func:`real_processes` on copies of them (it runs beside the tests)."""
    src = tmp_path_factory.mktemp("scenes")
    for name, kw in (("good", {}), ("empty", {"enabled": False}), ("nocam", {"camera": False})):
        with lf.fresh_file():
            _scene(lf, **kw)
            bpy.ops.wm.save_as_mainfile(filepath=str(src / f"{name}.blend"), copy=True)
    (src / "bad.blend").write_text("this is not a blend file\n")
    early_jobs.start(REAL, functools.partial(real_processes, src), soon=True)
    return src


def copy_scenes(src, folder):
    folder.mkdir(parents=True, exist_ok=True)
    for p in src.iterdir():
        (folder / p.name).write_bytes(p.read_bytes())
    return folder


@pytest.fixture
def work(files, tmp_path):
    """A fresh folder with copies of the scenes (the tests may overwrite them)."""
    return copy_scenes(files, tmp_path)


REAL = "pipeline: real processes"


def real_processes(src, jobs, folder):
    """Each entry point in a real process, each in a fresh copy of the scenes:
    ``python -m lightfade_addon scene info good.blend missing.blend --json``, a denoised
    bake (``--quality preview``) and a usage error through ``blender -c lightfade``.
    ``{name: (folder, process)}``."""
    runs = {"info --json": ("python -m", ("info", "good.blend", "missing.blend", "--json")),
            "bake denoised": ("python -m", ("bake", "good.blend", "--quality", "preview")),
            "usage error": ("blender -c", ("bake", "good.blend", "--resolution", "3"))}

    def one(name):
        entry, args = runs[name]
        work = copy_scenes(src, folder / name.split()[0])
        return work, PROCESSES[entry](*args, cwd=work, run=jobs.run)

    with ThreadPoolExecutor(len(runs)) as pool:                 # side by side
        return dict(zip(runs, pool.map(one, runs)))


@contextlib.contextmanager
def _real_streams():
    """sys.stdout and sys.stderr writing straight to file descriptors 1 and 2, as in a
    process of its own (``info --json`` points descriptor 1 at 2 meanwhile)."""
    out = io.TextIOWrapper(io.FileIO(1, "w", closefd=False), encoding="utf-8",
                           write_through=True)
    err = io.TextIOWrapper(io.FileIO(2, "w", closefd=False), encoding="utf-8",
                           write_through=True)
    saved = sys.stdout, sys.stderr
    sys.stdout, sys.stderr = out, err
    try:
        yield
    finally:
        sys.stdout, sys.stderr = saved
        out.detach()
        err.detach()


@pytest.fixture
def lightfade(blender, work, capfd, monkeypatch):
    """``lightfade(*ARGS)``: ``blender -c lightfade ARGS`` in this process, in ``work``;
    returns ``.returncode``, ``.stdout`` and ``.stderr`` like ``subprocess.run``."""
    from lightfade_addon.blender import cli_command

    monkeypatch.chdir(work)

    def run(*args):
        capfd.readouterr()
        with _real_streams():
            status = cli_command.execute([str(a) for a in args])
        out, err = capfd.readouterr()
        assert isinstance(status, int)
        return SimpleNamespace(returncode=status, stdout=out, stderr=err)

    return run


def probe(path):
    """A summary of a .blend file's LightFade state (opens it: the ``blender`` fixture
    resets the file after the test)."""
    bpy.ops.wm.open_mainfile(filepath=str(path), load_ui=False)
    s = bpy.context.scene
    floor = s.objects["Floor"]
    maps = {m.name: list(m.image.size) for m in floor.lightfade.exposure_maps}
    copies = [m for m in bpy.data.materials if m.lightfade.source is not None]
    aged = copies[0] if copies else None
    data = [aged.lightfade.table_image] if aged else []
    return {
        "maps": maps, "years": s.lightfade.years, "density": s.lightfade_bake.texels_per_metre,
        "aged": aged.name if aged else None,
        "aged_packed": bool(data) and all(i is not None and i.packed_file for i in data),
        "grids": len(s.get("lightfade_grids", {})),
    }


def leftovers(folder):
    """Temporary or backup files a run must not leave behind."""
    return sorted(p.name for p in folder.rglob("*")
                  if p.name.startswith(".") or p.suffix in (".blend1", ".blend@")
                  or p.name.endswith("@"))


def refusals(stderr):
    return [x for x in stderr.splitlines() if x.startswith("lightfade: ")]


#: A line LightFade writes: progress ("lightfade [1/2] a.blend: start", "LightFade: baked
#: Floor <- Sun ..."), a refusal, the summary and its table's rows.
OURS = re.compile(r"(lightfade[ :]|LightFade: |  (status|done|refused|failed) ).*")


def not_ours(text):
    """The lines of ``text`` that LightFade did not write (Blender's, a library's)."""
    return [x for x in text.splitlines() if not OURS.fullmatch(x)]


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


def _check_info_json(report, missing, work):
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


def test_info_json_names_paths_emitters_and_stale(lightfade, work):
    proc = lightfade("info", "good.blend", "missing.blend", "--json")
    assert proc.returncode == 1, proc.stderr[-2000:]
    report, missing = json.loads(proc.stdout)["files"]      # stdout is the JSON only
    _check_info_json(report, missing, work)


def test_info_json_to_a_file(lightfade, work):
    proc = lightfade("info", "empty.blend", "--json", "reports/info.json")
    assert proc.returncode == 0, proc.stderr[-2000:]
    report, = json.loads((work / "reports" / "info.json").read_text())["files"]
    assert report["file"] == str(work / "empty.blend") and report["would_age"] == []
    assert "lightfade info: 1 file: 1 done" in proc.stdout
    assert leftovers(work) == []


def test_info_text_of_an_aged_file_shows_doses(lightfade):
    assert lightfade("age", "good.blend", "--years", "5").returncode == 0
    proc = lightfade("info", "good_aged.blend", "empty.blend")
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert "Floor / Carpet: direct (printed-paper, Blue Wool 2; aged)" in proc.stdout
    assert "Floor <- Sun: brightest texel" in proc.stdout
    assert "would age: nothing" in proc.stdout          # empty.blend
    assert "stale: nothing" in proc.stdout


def test_info_doses_are_the_brightest_texel_times_the_schedule(floor_scene):
    from lightfade_addon.pipeline.info import doses

    sun = floor_scene["sun"].data.lightfade
    sun.hours_per_day, sun.days_per_year = 6.0, 200.0
    assert bpy.ops.lightfade.bake_exposure() == {"FINISHED"}
    (entry,) = doses(bpy.context.scene)
    assert entry["max_lux"] > 100
    assert entry["max_annual_Mlxh"] == pytest.approx(entry["max_lux"] * 6.0 * 200.0 / 1e6)


# ------------------------------------------------------------------------- bake and age


def test_bake_writes_a_new_file_with_the_override(lightfade, work):
    before = (work / "good.blend").read_bytes()
    proc = lightfade("bake", "good.blend", "--density", "20")
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert (work / "good.blend").read_bytes() == before
    state = probe(work / "good_baked.blend")
    assert state["maps"] == {"Sun": [40, 40]} and state["density"] == 20.0
    assert state["aged"] is None
    assert leftovers(work) == []


def test_age_bakes_ages_and_saves_to_output(lightfade, work):
    before = (work / "good.blend").read_bytes()
    proc = lightfade("age", "good.blend", "--years", "12.5", "--output", "out/shot.blend")
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert (work / "good.blend").read_bytes() == before
    state = probe(work / "out" / "shot.blend")
    assert state["maps"] == {"Sun": [64, 64]}
    assert state["years"] == 12.5 and state["aged"].startswith("LF_Aged_Carpet") and state["aged_packed"]
    assert state["grids"] == 0        # the packed table carries the aging: nothing to simulate
    assert "lightfade age: 1 file: 1 done" in proc.stdout
    assert "good.blend: aged 1 material to 12.5 years" in proc.stdout
    assert not_ours(proc.stdout + proc.stderr) == []     # no 'Info: Saved copy as ".good...'
    assert leftovers(work) == []


def test_age_never_overwrites_the_input_unless_in_place(lightfade, work):
    before = (work / "good.blend").read_bytes()
    proc = lightfade("age", "good.blend", "--years", "3", "--output", "good.blend")
    assert proc.returncode == 1
    assert (work / "good.blend").read_bytes() == before
    assert refusals(proc.stderr) == [
        f"lightfade: good.blend: the output {work / 'good.blend'} is the input file: give "
        "another --output, or --in-place to overwrite it"]
    proc = lightfade("age", "good.blend", "--years", "3", "--in-place")
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


def test_render_years_writes_one_still_per_value(lightfade, work):
    proc = lightfade("render-years", "good.blend", "--years", "0", "40", "--output", "stills")
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert sorted(p.name for p in (work / "stills").iterdir()) == ["good_0y.png", "good_40y.png"]
    young, old = _pixels(work / "stills" / "good_0y.png"), _pixels(work / "stills" / "good_40y.png")
    assert young.max() > 0.05                            # the floor is lit
    assert np.abs(young - old).max() > 0.02              # and it faded
    assert not (work / "good_aged.blend").exists() and leftovers(work) == []
    assert not_ours(proc.stdout + proc.stderr) == []     # 4.x: no "Fra:1 Mem:..." per step
    assert "good.blend: 40 years -> " in proc.stdout


def test_export_aged_writes_one_image_per_material(lightfade, work):
    """PNG (8-bit sRGB) and EXR (float linear) files of the aged textures, the same
    colours as the numpy evaluator in Blender, and the .blend left unchanged."""
    before = (work / "good.blend").read_bytes()
    proc = lightfade("export-aged", "good.blend", "--years", "40", "--output", "tex")
    assert proc.returncode == 0, proc.stderr[-2000:]
    proc = lightfade("export-aged", "good.blend", "--years", "40", "--output", "tex",
                     "--format", "exr")
    assert proc.returncode == 0, proc.stderr[-2000:]
    names = sorted(p.name for p in (work / "tex").iterdir())
    assert names == ["good_Carpet_Floor_40y.exr", "good_Carpet_Floor_40y.png"]
    png, exr = (bpy.data.images.load(str(work / "tex" / n)) for n in names[::-1])
    a, b = _rgba(png)[..., :3], _rgba(exr)[..., :3]
    assert exr.is_float and not png.is_float
    from lightfade_addon.core.colour.colorimetry import srgb_encode
    assert np.abs(srgb_encode(np.clip(b, 0, 1)) - a).max() <= 1 / 255 + 1e-6
    assert (work / "good.blend").read_bytes() == before and leftovers(work) == []
    assert not_ours(proc.stdout + proc.stderr) == []
    assert proc.stdout.count(" -> ") >= 2


def _rgba(image):
    a = np.empty(len(image.pixels), np.float32)
    image.pixels.foreach_get(a)
    return a.reshape(image.size[1], image.size[0], image.channels)


def test_render_years_without_camera_is_refused(lightfade):
    proc = lightfade("render-years", "nocam.blend", "--years", "1", "--output", "stills")
    assert proc.returncode == 1
    assert refusals(proc.stderr) == [
        "lightfade: nocam.blend: scene 'Scene' has no camera: set one (Scene Properties > "
        "Camera) to render from"]


# -------------------------------------------------------------------------------- batch


def test_batch_names_the_failures_and_finishes_the_rest(lightfade, work):
    (work / "again.blend").write_bytes((work / "good.blend").read_bytes())
    names = ["good.blend", "missing.blend", "bad.blend", "empty.blend", "again.blend"]
    proc = lightfade("age", *names, "--years", "10", "--output", "aged")
    assert proc.returncode == 1
    assert sorted(p.name for p in (work / "aged").iterdir()) == ["again.blend", "good.blend"]
    lines = refusals(proc.stderr)
    assert len(lines) == 3
    assert lines[0] == "lightfade: missing.blend: no such file"
    assert lines[1].startswith("lightfade: bad.blend: not a .blend file (")
    assert lines[2].startswith("lightfade: empty.blend: nothing to age: no material")
    assert not_ours(proc.stdout + proc.stderr) == []     # Blender's "Error: ..." is in ours
    table = proc.stdout[proc.stdout.index("lightfade age: 5 files: 2 done, 3 refused"):]
    rows = [x.split()[:3] for x in table.splitlines()[2:]]
    assert [r[0] for r in rows] == ["done", "refused", "refused", "refused", "done"]
    assert [r[2] for r in rows] == names
    assert leftovers(work) == []
    assert probe(work / "aged" / "again.blend")["years"] == 10.0


@pytest.mark.parametrize("case", ["truncated", "missing"])
def test_an_image_that_cannot_be_read_is_one_line_naming_it(lightfade, lf, work, case):
    """A truncated PNG: the refusal names the image, the file and libpng's reason, and
    nothing else is printed (libpng writes from C, before any line of ours); a missing
    one is said to be missing."""
    from PIL import Image

    Image.fromarray(np.full((32, 32, 3), 128, np.uint8)).save(work / "whole.png")
    data = (work / "whole.png").read_bytes()
    (work / "cut.png").write_bytes(data[:len(data) // 2])
    _scene(lf)
    node = bpy.data.materials["Carpet"].node_tree.nodes["Image Texture"]
    node.image = bpy.data.images.load(str(work / "cut.png"))
    bpy.ops.wm.save_as_mainfile(filepath=str(work / "cut.blend"), copy=True)
    if case == "missing":
        (work / "cut.png").unlink()
    proc = lightfade("age", "cut.blend", "--years", "5")
    assert proc.returncode == 1
    assert not_ours(proc.stdout) == [] and not_ours(proc.stderr) == []
    [line] = refusals(proc.stderr)
    image = "lightfade: cut.blend: Image 'cut.png' of material 'Carpet'"
    if case == "missing":
        assert line.startswith(f"{image} has no pixels: the file is missing? Relink it")
    else:
        assert line.startswith(f"{image} cannot be read from {work / 'cut.png'} (libpng error: ")


# -------------------------------------------------------------------------------- usage


def _untouched(work):
    return sorted(p.name for p in work.iterdir()) == sorted(
        ["good.blend", "empty.blend", "nocam.blend", "bad.blend"])


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
def test_usage_errors_exit_2_with_one_line(lightfade, work, args, message):
    proc = lightfade(*args)
    assert proc.returncode == 2, proc.stdout[-1000:] + proc.stderr[-1000:]
    errors = [x for x in proc.stderr.splitlines() if x.startswith("lightfade: error:")]
    assert len(errors) == 1 and message in errors[0]
    assert _untouched(work)


def test_help_exits_0(blender, capsys):
    from lightfade_addon import cli

    assert cli.main(["scene", "age", "--help"]) == 0
    out = capsys.readouterr().out
    assert "--years N" in out and "--in-place" in out


def test_a_blend_this_blender_cannot_read_is_named_as_such(blender, tmp_path):
    from lightfade_addon.pipeline import files

    future = tmp_path / "future.blend"
    future.write_bytes(b"BLENDER-v999" + bytes(200))
    with pytest.raises(files.Refused, match=f"^Blender {bpy.app.version_string} cannot read "
                                            "this .blend file .*saved by a newer Blender\\?$"):
        files.open_blend(str(future))


# ------------------------------------------------------------------- the real processes
# Last in the module: they ran beside the tests above (started by the files fixture).


def test_info_json_in_a_real_process(files, early_jobs):
    """``python -m lightfade_addon scene``: the exit status and a stdout of JSON only."""
    work, proc = early_jobs.result(REAL, None)["info --json"]
    assert proc.returncode == 1, proc.stderr[-2000:]
    report, missing = json.loads(proc.stdout)["files"]      # stdout is the JSON only
    _check_info_json(report, missing, work)
    # no "module changed on disk: '.../__init__.py' reloading...", no "Read blend: ...",
    # no traceback, no "Error: ..." of Blender's beside our refusal
    assert not_ours(proc.stderr) == []
    assert refusals(proc.stderr) == ["lightfade: missing.blend: no such file"]


def test_a_denoised_bake_in_a_real_process_prints_only_its_own_lines(blender, files, early_jobs):
    """No "EGL Error (0x3009): EGL_BAD_MATCH" (5.x: the compositor that denoises tried
    the GPU), no "Fra:1 Mem: ... | Compositing" (4.x), no 'Info: Saved copy as
    ".good_baked.lightfade-1.tmp.blend"'; the counts say what was made."""
    work, proc = early_jobs.result(REAL, None)["bake denoised"]
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    assert proc.stderr == ""
    assert not_ours(proc.stdout) == []
    assert "good.blend: baking 1 object (quality PREVIEW," in proc.stdout
    assert "good.blend: baked 1 map (1 object x 1 light group)" in proc.stdout
    assert "lightfade bake: 1 file: 1 done" in proc.stdout
    assert probe(work / "good_baked.blend")["maps"] == {"Sun": [64, 64]}


def test_usage_error_in_a_real_process(files, early_jobs):
    """``blender -c lightfade``: the command's status is the process's (a range that
    only the registered add-on knows)."""
    work, proc = early_jobs.result(REAL, None)["usage error"]
    assert proc.returncode == 2, proc.stdout[-1000:] + proc.stderr[-1000:]
    errors = [x for x in proc.stderr.splitlines() if x.startswith("lightfade: error:")]
    assert errors == ["lightfade: error: --resolution 3: must be between 64 and 8192"]
    assert _untouched(work)
