"""The farm job's pure parts: chunks sized from estimates, the task map files (atomic,
checked by Merge), the OpenJD template and its YAML.  No bpy; the job run through
``openjd run`` is tests/blender/test_farm.py."""

import hashlib
import json
import os

import numpy as np
import pytest

from lightfade_addon.pipeline import openjd, taskmaps
from lightfade_addon.pipeline.chunks import chunk_count, chunk_objects, split

yaml = pytest.importorskip("yaml")


# --------------------------------------------------------------------------------- chunks


class TestChunks:
    def test_tasks_of_about_the_target_time(self):
        # 10 objects of 60 s for one group, tasks of 5 min paying 20 s to start:
        # 600 s / 280 s -> 3 chunks of 3-4 objects
        assert chunk_count([60.0] * 10, 300.0, 20.0) == 3
        assert chunk_count([60.0] * 10, 300.0, 0.0) == 2
        assert chunk_count([60.0] * 10, 1e6) == 1
        assert chunk_count([60.0] * 10, 1e-3) == 10         # never more than one per object
        assert chunk_count([], 300.0) == 0

    def test_chunks_are_alike_in_time_and_keep_the_order(self):
        names = list("abcdefg")
        seconds = [50, 10, 40, 30, 20, 30, 20]
        chunks = split(names, seconds, 2)
        loads = [sum(seconds[names.index(n)] for n in c) for c in chunks]
        assert sorted(loads) == [100, 100]
        assert sorted(n for c in chunks for n in c) == names      # each object once
        assert all(c == sorted(c) for c in chunks)                # in the scene's order
        assert split(names, seconds, 2) == chunks                 # the same on every run

    def test_a_big_object_gets_a_chunk_of_its_own(self):
        chunks = chunk_objects(["sofa", "cup", "plate", "fork"], [600, 5, 5, 5], 300.0)
        assert ["sofa"] in chunks and len(chunks) == 2


# ------------------------------------------------------------------------------ task maps


def _maps():
    rng = np.random.default_rng(1)
    return {"Floor": rng.random((8, 8), dtype=np.float32) * 900,
            "Box": rng.random((16, 16), dtype=np.float32) * 100}


HEADER = {"scene": "ab" * 32, "settings": "0123456789abcdef", "group": "Sun", "chunk": 0}
ABOUT = {"Floor": {"uv_map": "UVMap", "uv_hash": "x"}, "Box": {"uv_map": "UVMap", "uv_hash": "y"}}
WANT = {"Floor": {"shape": [8, 8], "uv_map": "UVMap"}, "Box": {"shape": [16, 16], "uv_map": "UVMap"}}
LABEL = taskmaps.task_label("Sun", 0)


def _check(path, **kw):
    args = dict(scene=HEADER["scene"], settings=HEADER["settings"], group="Sun", objects=WANT)
    args.update(kw)
    return taskmaps.check(str(path), LABEL, **args)


class TestTaskMaps:
    def test_written_maps_read_back(self, tmp_path):
        path = taskmaps.write(str(tmp_path / "g000_c0000.npz"), HEADER, _maps(), ABOUT)
        header = _check(path)
        assert [o["name"] for o in header["objects"]] == ["Floor", "Box"]
        assert header["objects"][0]["uv_hash"] == "x"
        _header, maps = taskmaps.read(path)
        for name, lux in _maps().items():
            np.testing.assert_array_equal(maps[name], lux)
        assert os.listdir(tmp_path) == ["g000_c0000.npz"]        # no temporary file left

    def test_a_write_that_dies_midway_leaves_the_previous_file(self, tmp_path, monkeypatch):
        path = str(tmp_path / "g000_c0000.npz")
        taskmaps.write(path, HEADER, _maps(), ABOUT)
        before = open(path, "rb").read()

        def dies(f, **arrays):
            f.write(b"PK\x03\x04 half a file")
            raise OSError("No space left on device")

        monkeypatch.setattr(taskmaps.np, "savez", dies)
        with pytest.raises(OSError):
            taskmaps.write(path, dict(HEADER, group="Lamp"), _maps(), ABOUT)
        assert open(path, "rb").read() == before
        assert os.listdir(tmp_path) == ["g000_c0000.npz"]
        monkeypatch.undo()
        with pytest.raises(OSError):                             # nothing was there before
            monkeypatch.setattr(taskmaps.np, "savez", dies)
            taskmaps.write(str(tmp_path / "g001_c0000.npz"), HEADER, _maps(), ABOUT)
        assert os.listdir(tmp_path) == ["g000_c0000.npz"]

    @pytest.mark.parametrize("change, says", [
        (dict(scene="cd" * 32), "was baked from another scene"),
        (dict(settings="fedcba9876543210"), "was baked with other settings"),
        (dict(group="Lamp"), "holds light group 'Sun', not 'Lamp'"),
        (dict(objects={"Floor": WANT["Floor"]}), "holds maps of ['Box', 'Floor'], not ['Floor']"),
        (dict(objects=dict(WANT, Box={"shape": [32, 32], "uv_map": "UVMap"})),
         "the map of 'Box' is [16, 16] on UV map 'UVMap', the job needs [32, 32]"),
        (dict(objects=dict(WANT, Box={"shape": [16, 16], "uv_map": "LightFadeUV"})),
         "the job needs [16, 16] on 'LightFadeUV'"),
    ])
    def test_merge_refuses_a_mismatch_naming_the_task(self, tmp_path, change, says):
        path = taskmaps.write(str(tmp_path / "g000_c0000.npz"), HEADER, _maps(), ABOUT)
        with pytest.raises(taskmaps.MapProblem) as err:
            _check(path, **change)
        message = str(err.value)
        assert says in message and "\n" not in message
        assert message.endswith(": rerun Bake task Group=Sun Chunk=0")

    def test_missing_damaged_or_not_finite(self, tmp_path):
        with pytest.raises(taskmaps.MapProblem, match=r"^no maps from Bake task Group=Sun "
                                                      r"Chunk=0 \(.* is missing\): rerun"):
            _check(tmp_path / "g000_c0000.npz")
        bad = tmp_path / "g000_c0001.npz"
        bad.write_bytes(b"PK\x03\x04 half a file")
        with pytest.raises(taskmaps.MapProblem, match="cannot be read.*: rerun Bake task"):
            _check(bad)
        maps = _maps()
        maps["Box"][3, 3] = np.nan
        path = taskmaps.write(str(tmp_path / "g000_c0002.npz"), HEADER, maps, ABOUT)
        with pytest.raises(taskmaps.MapProblem, match="'Box' holds NaN"):
            _check(path)

    def test_hashes(self, tmp_path):
        a = {"settings": {"samples": 8}, "groups": [["Sun", ["Sun"]]]}
        assert taskmaps.settings_hash(a) == taskmaps.settings_hash(json.loads(json.dumps(a)))
        assert taskmaps.settings_hash(a) != taskmaps.settings_hash(dict(a, settings={"samples": 9}))
        uv = np.linspace(0, 1, 12, dtype=np.float32)
        assert taskmaps.uv_hash(uv) == taskmaps.uv_hash(uv + 1e-8)
        assert taskmaps.uv_hash(uv) != taskmaps.uv_hash(uv[::-1])
        f = tmp_path / "scene.blend"
        f.write_bytes(b"BLENDER-v402")
        assert taskmaps.file_sha256(f, block=5) == hashlib.sha256(b"BLENDER-v402").hexdigest()


# -------------------------------------------------------------------------------- template


def _spec(**kw):
    plan = json.dumps({"format": 1, "groups": [["Sun", ["Sun"]]], "chunks": [["Floor"]]},
                      indent=1) + "\n"
    args = dict(name="room.blend", scene=None, work="work", output="output", stem="room",
                plan=plan, groups=["Sun", "Ceiling +1"], chunks=3, years=25.0, frames=(1, 26))
    args.update(kw)
    return openjd.JobSpec(**args)


class TestTemplate:
    def test_the_yaml_reads_back_as_the_template(self):
        template = openjd.job_template(_spec(name='a "quoted": name\tand tab'))
        assert yaml.safe_load(openjd.to_yaml(template)) == template

    def test_it_is_a_valid_openjd_template(self):
        pytest.importorskip("openjd.model")
        assert openjd.validate(openjd.job_template(_spec())) is True
        broken = openjd.job_template(_spec())
        broken["steps"][1]["dependencies"] = [{"dependsOn": "Baking"}]
        with pytest.raises(ValueError, match="not valid"):
            openjd.validate(broken)

    def test_steps_tasks_and_paths(self):
        template = openjd.job_template(_spec())
        steps = {s["name"]: s for s in template["steps"]}
        assert list(steps) == ["Bake", "Merge", "Age", "Render"]
        space = steps["Bake"]["parameterSpace"]
        assert space["taskParameterDefinitions"][0]["range"] == ["Sun", "Ceiling +1"]
        assert space["taskParameterDefinitions"][1]["range"] == "0-2"
        assert space["combination"] == "Group * Chunk"
        assert steps["Render"]["parameterSpace"]["taskParameterDefinitions"][0]["range"] == "1-26"
        assert steps["Render"]["script"]["actions"]["onRun"]["args"][:1] == ["-b"]
        assert "lightfade" not in steps["Render"]["script"]["actions"]["onRun"]["args"]
        paths = {p["name"] for p in template["parameterDefinitions"] if p["type"] == "PATH"}
        assert paths == {"SceneFile", "WorkDir", "OutputDir"}
        for step in template["steps"]:           # every file goes through a PATH parameter
            for arg in step["script"]["actions"]["onRun"]["args"]:
                assert "/" not in arg or arg.startswith("{{Param."), arg
        plan = steps["Merge"]["script"]["embeddedFiles"][0]["data"]
        assert json.loads(plan)["chunks"] == [["Floor"]]

    def test_without_years_no_age_and_render(self):
        template = openjd.job_template(_spec(years=None))
        assert [s["name"] for s in template["steps"]] == ["Bake", "Merge"]
        scene = template["parameterDefinitions"][0]
        assert scene["name"] == "SceneFile" and "default" not in scene

    def test_parameter_values(self):
        doc = yaml.safe_load(openjd.to_yaml(openjd.parameter_values({"SceneFile": "/s/a b.blend"})))
        assert doc == {"parameterValues": [{"name": "SceneFile", "value": "/s/a b.blend"}]}
