"""The farm job end to end: ``farm-job`` writes an OpenJD bundle for a small scene,
``openjd check`` validates it and ``openjd run`` runs every step on this machine, each
task a process of its own; the merged maps and the time-lapse's frames are compared
with a one-machine bake (``bake`` then ``render-years``) of the same scene.  A Bake task
killed midway (its maps written, not yet synced to disk) leaves nothing Merge takes, and its rerun
writes the same maps; Merge refuses a missing or mismatched map in one line naming the
task to rerun.

There is no Blender binary here: :data:`STAND_IN` is the job's ``Blender`` parameter, a
``blender`` that does what the template asks of it through the bpy module
(``-c lightfade ARGS``: the add-on's registered command, as in test_pipeline.py;
``-b FILE -o PATTERN -f FRAME``: open and render one frame without enabling LightFade,
as a farm's plain Blender would).  The processes age with the Blender tests' coarse
grid and table (the shell, not the grid, is under test; both sides use it).

The processes run as an early job (tests/conftest.py) beside the tests before them:
the scene is the floor scene of conftest.py with a second light group (a lamp on 4 h a
day), 64 px maps at 2 samples, 16x16 frames; tasks of ~0 minutes, so each object is a
chunk: 2 groups x 2 chunks.
"""

import functools
import json
import signal
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from test_pipeline import _env  # the environment a real process needs to import the add-on

ROOT = Path(__file__).resolve().parents[2]
bpy = pytest.importorskip("bpy")
yaml = pytest.importorskip("yaml")

OPENJD = Path(sys.executable).with_name("openjd")
if not OPENJD.exists():
    pytest.skip("openjd-cli is not installed (requirements.txt)", allow_module_level=True)

#: ``blender`` on this machine: the bpy module in this Python.
STAND_IN = r"""#!{python}
import os
import sys
import time
sys.path.insert(0, {root!r})
import bpy
argv = sys.argv[1:]
if argv[:2] == ["-c", "lightfade"]:
    import addon_utils
    from tests.blender.conftest import COARSE_GRID, COARSE_TABLE
    from lightfade_addon.blender.aging import data, runtime
    runtime.GRID_SETTINGS, data.TABLE_SETTINGS = COARSE_GRID, COARSE_TABLE
    if os.environ.get("LIGHTFADE_TEST_HANG_AT_SYNC"):
        from lightfade_addon.pipeline import taskmaps
        def hang(fd):
            print("test: maps written, syncing", flush=True)
            time.sleep(600)
        taskmaps.os.fsync = hang
    caught = {{}}
    real = bpy.utils.register_cli_command
    def spy(command, execute):
        caught[command] = execute
        return real(command, execute)
    bpy.utils.register_cli_command = spy
    addon_utils.enable("lightfade_addon", default_set=False)
    bpy.utils.register_cli_command = real
    status = caught["lightfade"](argv[2:])
elif argv[0] == "-b" and argv[2] == "-o" and argv[4] == "-f" and len(argv) == 6:
    bpy.ops.wm.open_mainfile(filepath=argv[1], load_ui=False)
    scene = bpy.context.scene
    frame = int(argv[5])
    scene.render.filepath = argv[3]
    scene.frame_set(frame)
    bpy.ops.render.render(write_still=False)
    path = scene.render.frame_path(frame=frame)
    bpy.data.images["Render Result"].save_render(filepath=path, scene=scene)
    print("Saved:", path)
    status = 0
else:
    print("blender stand-in: not what the job runs:", argv, file=sys.stderr)
    status = 2
sys.stdout.flush()
sys.stderr.flush()
os._exit(status)
"""


def build_scene(lf, path):
    """conftest's floor scene with a lamp on 4 h a day (a second light group), the box
    aging too with UVs that overlap (the bake makes it a ``LightFadeUV`` map, each Bake
    task in its own process and Merge again), a camera, tiny bakes and renders."""
    with lf.fresh_file():
        parts = lf.build_floor_scene()
        parts["material"].lightfade.blue_wool = 2
        parts["box"].data.materials.append(parts["material"])
        uv = parts["box"].data.uv_layers.active.data    # every face on one square: the
        square = np.array([[0.1, 0.1], [0.9, 0.1], [0.9, 0.9], [0.1, 0.9]], np.float32)
        uv.foreach_set("uv", np.tile(square, (len(uv) // 4, 1)).ravel())   # bake makes LightFadeUV
        lamp = lf.add_point(power=60.0, location=(-0.5, -0.5, 1.5))
        lamp.data.lightfade.hours_per_day = 4.0
        s = bpy.context.scene
        cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
        cam.location = (0.0, 0.0, 3.0)
        s.collection.objects.link(cam)
        s.camera = cam
        s.lightfade_bake.quality = "CUSTOM"
        s.lightfade_bake.denoise = False
        s.lightfade_bake.texels_per_metre = 32.0
        s.lightfade.bake_resolution = 64
        s.lightfade.bake_samples = 2
        s.lightfade.bake_margin = 1
        s.render.engine = "CYCLES"
        s.cycles.samples = 2
        s.render.resolution_x = s.render.resolution_y = 16
        s.render.resolution_percentage = 100
        s.render.image_settings.file_format = "PNG"
        bpy.ops.wm.save_as_mainfile(filepath=str(path), copy=True)


def plan_of(bundle):
    """The task plan embedded in the bundle's Merge step."""
    template = yaml.safe_load((bundle / "template.yaml").read_text())
    merge = next(s for s in template["steps"] if s["name"] == "Merge")
    return merge["script"]["embeddedFiles"][0]["data"]


def run_the_job(src, jobs, folder):
    """Generate, check and run the job; the one-machine bake; a killed Bake task and its
    rerun.  Returns what the tests check."""
    blender = folder / "blender"
    blender.write_text(STAND_IN.format(python=sys.executable, root=str(ROOT)))
    blender.chmod(0o755)
    scene = folder / "scene.blend"
    scene.write_bytes(src.read_bytes())
    before = scene.stat().st_mtime_ns
    env = _env()

    def run(*args, **kw):
        return jobs.run([str(a) for a in args], cwd=folder, env=kw.pop("env", env), **kw)

    def openjd_run(step, *more):
        return run(OPENJD, "run", "job/template.yaml", "--step", step, "-p", f"Blender={blender}",
                   "-p", f"SceneFile={scene}", *more)

    r = SimpleNamespace(folder=folder, scene=scene)
    r.job = run(sys.executable, "-m", "lightfade_addon", "scene", "farm-job", "scene.blend",
                "--out", "job", "--task-minutes", "0.001", "--years", "25", "--frames", "2")
    r.check = run(OPENJD, "check", "job/template.yaml")
    r.steps = {step: openjd_run(step) for step in ("Bake", "Merge", "Age", "Render")}
    r.reference = [run(blender, "-c", "lightfade", "bake", "scene.blend", "--output", "ref/"),
                   run(blender, "-c", "lightfade", "render-years", "ref/scene.blend", "--years",
                       "0", "25", "--output", "ref/renders")]
    r.scene_untouched = scene.stat().st_mtime_ns == before
    # a Bake task killed once its maps are written, while they are synced to disk
    (folder / "plan.json").write_text(plan_of(folder / "job"))
    killed = folder / "killed"
    proc = subprocess.Popen([str(blender), "-c", "lightfade", "farm-bake", str(scene), "--plan",
                             str(folder / "plan.json"), "--group", "Sun", "--chunk", "0",
                             "--maps", str(killed / "maps")], cwd=folder, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True,
                            env=dict(env, LIGHTFADE_TEST_HANG_AT_SYNC="1"))
    try:
        r.killed_said = None
        for line in iter(proc.stdout.readline, ""):    # "" once the process ended
            if line.startswith("test: maps written"):
                r.killed_said = line
                break
    finally:
        r.killed_left = sorted(p.name for p in (killed / "maps").glob("*")) \
            if (killed / "maps").exists() else []
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        proc.stdout.close()
    r.after_kill = sorted(p.name for p in (killed / "maps").glob("*"))
    r.rerun = openjd_run("Bake", "-p", f"WorkDir={killed}", "-tp", "Group=Sun", "-tp", "Chunk=0")
    return r


@pytest.fixture(scope="module")
def job(tmp_path_factory, lf, early_jobs):
    """The job's results (an early job started as soon as the scene file exists)."""
    src = tmp_path_factory.mktemp("farm") / "scene.blend"
    build_scene(lf, src)
    return early_jobs.start("farm job", functools.partial(run_the_job, src), soon=True).result()


def _ok(proc):
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    return proc


def exposure(path):
    """``{(object, group): (lux, uv map)}`` of a .blend file (opens it)."""
    bpy.ops.wm.open_mainfile(filepath=str(path), load_ui=False)
    found = {}
    for obj in bpy.context.scene.objects:
        for item in obj.lightfade.exposure_maps if obj.type == "MESH" else ():
            w, h = item.image.size
            px = np.empty(w * h * 4, dtype=np.float32)
            item.image.pixels.foreach_get(px)
            found[obj.name, item.name] = (px.reshape(h, w, 4)[..., 0], obj.lightfade.uv_map,
                                          item.image.packed_file is not None,
                                          obj.lightfade.uv_created)
    return found


# ------------------------------------------------------------------------------- the job


def test_the_job_is_valid_openjd_with_one_task_per_group_and_chunk(job):
    _ok(job.job)
    assert "4 Bake tasks (2 light groups x 2 chunks of 2 objects" in job.job.stdout
    assert "passes validation checks" in _ok(job.check).stdout
    template = yaml.safe_load((job.folder / "job" / "template.yaml").read_text())
    assert [s["name"] for s in template["steps"]] == ["Bake", "Merge", "Age", "Render"]
    plan = json.loads(plan_of(job.folder / "job"))
    assert [g for g, _members in plan["groups"]] == ["Sun", "Lamp"]
    assert sorted(n for chunk in plan["chunks"] for n in chunk) == ["Box", "Floor"]
    values = yaml.safe_load((job.folder / "job" / "parameter_values.yaml").read_text())
    assert values["parameterValues"] == [{"name": "SceneFile", "value": str(job.scene)}]


def test_every_step_runs_through_openjd(job):
    for step, proc in job.steps.items():
        _ok(proc)
        assert "Session ended successfully" in proc.stdout, step
    assert "Chunks run: 4" in job.steps["Bake"].stdout
    maps = sorted(p.name for p in (job.folder / "job" / "work" / "maps").iterdir())
    assert maps == ["g000_c0000.npz", "g000_c0001.npz", "g001_c0000.npz", "g001_c0001.npz"]
    assert job.scene_untouched            # the tasks read the scene, never write it


def test_merged_maps_match_a_one_machine_bake(blender, job):
    for proc in job.reference:
        _ok(proc)
    farm = exposure(job.folder / "job" / "output" / "scene_baked.blend")
    one = exposure(job.folder / "ref" / "scene.blend")
    assert sorted(farm) == sorted(one) == [("Box", "Lamp"), ("Box", "Sun"),
                                           ("Floor", "Lamp"), ("Floor", "Sun")]
    for key, (lux, uv_map, packed, _made) in farm.items():
        ref, ref_uv, _packed, _made = one[key]
        assert lux.shape == ref.shape and uv_map == ref_uv and packed, key
        assert lux.mean() == pytest.approx(ref.mean(), rel=0.01), key
        assert ref.mean() > 10.0, key                       # lit: a real comparison
        np.testing.assert_allclose(lux, ref, rtol=1e-5, atol=1e-3)   # the same seeds
    assert farm["Box", "Sun"][1] == "LightFadeUV" and farm["Floor", "Sun"][1] == "UVMap"
    assert farm["Box", "Sun"][3] and not farm["Floor", "Sun"][3]   # Reset removes it, as after a bake


def test_the_time_lapse_frames_match_one_machine_stills(job):
    from PIL import Image

    renders = job.folder / "job" / "output" / "renders"
    frames = sorted(p.name for p in renders.iterdir())
    assert frames == ["scene_0001.png", "scene_0002.png"]
    pixels = {}
    for frame, years in (("scene_0001.png", "0"), ("scene_0002.png", "25")):
        farm = np.asarray(Image.open(renders / frame), dtype=float)
        one = np.asarray(Image.open(job.folder / "ref" / "renders" / f"scene_{years}y.png"),
                         dtype=float)
        # the farm renders the live material (no LightFade), one machine the box from
        # its frame images (blender/aging/frames.py): the same colours by two evaluators
        tolerance = 2.0 if years == "0" else 6.0
        assert np.abs(farm - one).max() <= tolerance, frame
        assert np.abs(farm - one).mean() <= 1.0, frame
        pixels[years] = farm
    assert np.abs(pixels["25"] - pixels["0"]).mean() > 5.0      # the frames differ: it aged


def test_the_render_step_runs_plain_blender(job):
    template = yaml.safe_load((job.folder / "job" / "template.yaml").read_text())
    render = next(s for s in template["steps"] if s["name"] == "Render")
    args = render["script"]["actions"]["onRun"]["args"]
    assert args[0] == "-b" and "lightfade" not in args and "-c" not in args


# ---------------------------------------------------------------------- trust in tasks


def test_a_task_killed_midway_leaves_nothing_merge_takes_and_its_rerun_is_the_same(job):
    assert job.killed_said, "the task never wrote its maps"
    assert len(job.killed_left) == 1 and job.killed_left[0].startswith(".g000_c0000.npz.")
    assert "g000_c0000.npz" not in job.after_kill
    _ok(job.rerun)
    from lightfade_addon.pipeline import taskmaps

    again = taskmaps.read(job.folder / "killed" / "maps" / "g000_c0000.npz")
    first = taskmaps.read(job.folder / "job" / "work" / "maps" / "g000_c0000.npz")
    assert again[0] == first[0]
    for name in first[1]:
        np.testing.assert_array_equal(again[1][name], first[1][name])


@pytest.fixture
def farm_merge(blender, job, tmp_path, capfd):
    """``farm-merge`` in this process (the add-on's command callback) with a copy of the
    job's maps in ``tmp_path/maps``: ``(returncode, stderr lines of ours)``."""
    from lightfade_addon.blender import cli_command

    maps = tmp_path / "maps"
    maps.mkdir()
    for p in (job.folder / "job" / "work" / "maps").iterdir():
        (maps / p.name).write_bytes(p.read_bytes())

    def run():
        capfd.readouterr()
        status = cli_command.execute(["farm-merge", str(job.scene), "--plan",
                                      str(job.folder / "plan.json"), "--maps", str(maps),
                                      "--output", str(tmp_path / "merged.blend")])
        _out, err = capfd.readouterr()
        return status, [x for x in err.splitlines() if x.startswith("lightfade: ")]

    return SimpleNamespace(run=run, maps=maps, out=tmp_path / "merged.blend")


def test_merge_takes_the_maps(farm_merge):
    status, lines = farm_merge.run()
    assert (status, lines) == (0, [])
    assert farm_merge.out.exists()


def test_merge_refuses_a_missing_map_naming_the_task(farm_merge, job):
    (farm_merge.maps / "g001_c0001.npz").unlink()
    status, lines = farm_merge.run()
    assert status == 1 and len(lines) == 1
    assert lines[0].startswith(f"lightfade: {job.scene}: no maps from Bake task Group=Lamp "
                               "Chunk=1 (")
    assert lines[0].endswith("is missing): rerun Bake task Group=Lamp Chunk=1")
    assert not farm_merge.out.exists()


@pytest.mark.parametrize("change, says", [
    ({"scene": "0" * 64}, "was baked from another scene"),
    ({"settings": "0" * 16}, "was baked with other settings"),
])
def test_merge_refuses_a_map_of_another_scene_or_settings(farm_merge, change, says):
    from lightfade_addon.pipeline import taskmaps

    path = farm_merge.maps / "g000_c0001.npz"
    header, maps = taskmaps.read(path)
    about = {o["name"]: o for o in header["objects"]}
    taskmaps.write(str(path), dict(header, **change), maps, about)
    status, lines = farm_merge.run()
    assert status == 1 and len(lines) == 1
    assert says in lines[0] and lines[0].endswith(": rerun Bake task Group=Sun Chunk=1")
    assert not farm_merge.out.exists()


def test_a_task_on_a_changed_scene_fails_in_one_line(blender, job, tmp_path, capfd):
    from lightfade_addon.blender import cli_command

    changed = tmp_path / "scene.blend"
    changed.write_bytes(job.scene.read_bytes() + b"\0")
    capfd.readouterr()
    status = cli_command.execute(["farm-bake", str(changed), "--plan", str(job.folder / "plan.json"),
                                  "--group", "Sun", "--chunk", "0", "--maps", str(tmp_path)])
    err = [x for x in capfd.readouterr()[1].splitlines() if x.startswith("lightfade: ")]
    assert status == 1
    assert len(err) == 1 and "the scene file changed since the job was made" in err[0]
    assert list(tmp_path.glob("*.npz")) == []


#: Flamenco's ``author`` and ``path`` for its job type's ``compileJob``: prints the tasks
#: it makes as JSON (name, dependencies, command, arguments).
FLAMENCO = r"""
const fs = require("fs");
const nodePath = require("path");
global.path = { join: (...a) => nodePath.posix.join(...a) };
const tasks = [];
global.author = {
  Task: (name, type) => ({ name, type, commands: [], deps: [],
    addCommand(c) { this.commands.push(c); }, addDependency(d) { this.deps.push(d.name); } }),
  Command: (name, params) => ({ name, params }),
};
eval(fs.readFileSync(process.argv[2], "utf8") + "\nglobal.compileJob = compileJob;");
compileJob({ settings: JSON.parse(fs.readFileSync(process.argv[3], "utf8")),
             addTask(t) { tasks.push(t); } });
console.log(JSON.stringify(tasks.map((t) => ({ name: t.name, deps: t.deps,
  command: t.commands[0].name, args: t.commands[0].params.args }))));
"""


def test_the_flamenco_job_type_runs_the_openjd_steps(job, tmp_path):
    import shutil

    node = shutil.which("node")
    if node is None:
        pytest.skip("no node to run the Flamenco job type with")
    bundle = job.folder / "job"
    harness = tmp_path / "harness.js"
    harness.write_text(FLAMENCO)
    proc = subprocess.run([node, str(harness), str(ROOT / "tools" / "flamenco" / "lightfade_farm.js"),
                           str(bundle / "flamenco_settings.json")], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    tasks = {t["name"]: t for t in json.loads(proc.stdout)}
    assert (bundle / "plan.json").read_text() == plan_of(bundle)
    template = yaml.safe_load((bundle / "template.yaml").read_text())
    steps = {s["name"]: s["script"]["actions"]["onRun"]["args"] for s in template["steps"]}
    values = {"{{Param.SceneFile}}": str(job.scene), "{{Task.File.Plan}}": str(bundle / "plan.json"),
              "{{Param.WorkDir}}": str(bundle / "work"), "{{Param.OutputDir}}": str(bundle / "output")}

    def openjd(step, **task):
        out = []
        for arg in steps[step]:
            for k, v in dict(values, **{f"{{{{Task.Param.{n}}}}}": str(x)
                                        for n, x in task.items()}).items():
                arg = arg.replace(k, v)
            out.append(arg)
        return out

    bakes = [f"bake {g} {c}" for g in ("Sun", "Lamp") for c in (0, 1)]
    assert sorted(tasks) == sorted(bakes + ["merge", "age", "render 1", "render 2"])
    for name in bakes:
        _, group, chunk = name.split()
        assert tasks[name]["args"] == openjd("Bake", Group=group, Chunk=chunk)
    assert sorted(tasks["merge"]["deps"]) == sorted(bakes)
    assert tasks["merge"]["args"] == openjd("Merge")
    assert tasks["age"]["args"] == openjd("Age") and tasks["age"]["deps"] == ["merge"]
    assert tasks["render 2"]["deps"] == ["age"] and tasks["render 2"]["command"] == "blender-render"
    assert "lightfade" not in tasks["render 2"]["args"]
