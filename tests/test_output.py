"""What LightFade prints: counts in words, and C-level output caught and filtered
(``lightfade_addon/output.py``)."""

import os
import re

import pytest

from lightfade_addon.output import NOISE, captured, maps_made, plural, quiet

#: Lines the libraries really print, as measured with bpy 5.2.3 and 4.2.23, by kind.
SEEN = {
    "render": ["Fra:1 Mem:10.54M (Peak 10.54M) | Time:00:00.00 | Compositing",
               "Fra:1 Mem:10.67M (Peak 10.67M) | Time:00:00.00 | Compositing | Operation 2-6",
               "Fra:1 Mem:13.72M (Peak 14.86M) | Time:00:00.00 | Remaining:00:00.00 | "
               "Mem:0.12M, Peak:0.12M | Scene, ViewLayer | Sample 1/2"],
    "gpu": ["EGL Error (0x3009): EGL_BAD_MATCH: Arguments are inconsistent (for example, a "
            "valid context requires buffers not supplied by a valid surface)."],
    "save": ['Info: Saved copy as ".good.lightfade-4957.tmp.blend"',
             'Info: Saved ".good.lightfade-5022.tmp.blend"',
             "Info: Total files 0 | Changed 0 | Failed 0"],
    "open": ['00:00.274  blend            | Read blend: "/tmp/scenes/good.blend"',
             'Read blend: "/tmp/scenes/good.blend"'],
}

#: Real messages that must get through.
REAL = ['Error: Cannot open file "/x/.a.lightfade-1.tmp.blend@" for writing: Permission denied',
        "EGL Error (0x3003): EGL_BAD_ALLOC: out of memory",
        "Info: Total files 3 | Changed 1 | Failed 2",
        "Fra:1 out of memory",
        'Error: File format is not supported in file "/tmp/bad.blend"',
        "libpng error: IDAT: Read error: hit end of file in png reader"]


class TestPlural:
    @pytest.mark.parametrize("n, text", [(0, "0 materials"), (1, "1 material"),
                                         (2, "2 materials"), (1.0, "1 material"),
                                         (2.5, "2.5 materials")])
    def test_the_number_decides(self, n, text):
        assert plural(n, "material") == text

    def test_irregular_plural(self):
        assert plural(3, "matrix", "matrices") == "3 matrices"
        assert plural(1, "matrix", "matrices") == "1 matrix"


class TestMapsMade:
    def result(self, maps, groups, emitters):
        return {"maps": maps, "groups": groups, "emitters": emitters}

    def test_one_map_per_object_and_light_group(self):
        r = self.result({f"O{k}": {"Sun": 0, "Lamps": 0} for k in range(3)},
                        ["Sun", "Lamps"], ["Sun", "L1", "L2", "L3"])
        assert maps_made(r) == "6 maps (3 objects x 2 light groups of 4 emitters)"

    def test_emitters_are_named_only_when_they_are_not_the_groups(self):
        r = self.result({"Floor": {"Sun": 0}}, ["Sun"], ["Sun"])
        assert maps_made(r, "exposure map") == "1 exposure map (1 object x 1 light group)"

    def test_no_product_when_an_object_misses_a_group(self):
        r = self.result({"A": {"Sun": 0, "Lamps": 0}, "B": {"Sun": 0}}, ["Sun", "Lamps"],
                        ["Sun", "Lamps"])
        assert maps_made(r) == "3 maps (2 objects, 2 light groups)"


class TestNoise:
    @pytest.mark.parametrize("kind, line", [(k, x) for k, lines in SEEN.items() for x in lines])
    def test_known_noise_matches(self, kind, line):
        assert any(re.fullmatch(p, line) for p in NOISE[kind])

    @pytest.mark.parametrize("line", REAL)
    def test_real_messages_do_not(self, line):
        assert not any(re.fullmatch(p, line) for ps in NOISE.values() for p in ps)


class TestCaptured:
    def test_catches_what_c_code_writes_to_the_descriptors(self, capfd):
        with captured() as out:
            os.write(1, b"to stdout\n")
            os.write(2, b"to stderr\nsecond\n")
        assert out.lines == {1: ["to stdout"], 2: ["to stderr", "second"]}
        assert capfd.readouterr() == ("", "")
        os.write(2, b"after\n")                               # the descriptors are back
        assert capfd.readouterr().err == "after\n"

    def test_a_descriptor_that_is_not_open_is_left_alone(self, capfd):
        """Blender's UI on Windows runs without a console: nothing to catch, no error."""
        closed = 987
        with pytest.raises(OSError):
            os.fstat(closed)
        with captured((1, closed)) as out:
            os.write(1, b"caught\n")
        assert out.lines == {1: ["caught"], closed: []}
        assert capfd.readouterr() == ("", "")

    def test_quiet_writes_back_all_but_the_noise(self, capfd):
        with quiet("save", "gpu"):
            os.write(1, (SEEN["save"][0] + "\n" + REAL[0] + "\n").encode())
            os.write(2, (SEEN["gpu"][0] + "\n" + REAL[1] + "\n").encode())
        out, err = capfd.readouterr()
        assert out == REAL[0] + "\n" and err == REAL[1] + "\n"

    def test_quiet_writes_back_on_an_error_too(self, capfd):
        with pytest.raises(RuntimeError), quiet("render"):
            os.write(2, b"Fra:1 Mem:1M (Peak 1M) | Compositing\nwhat went wrong\n")
            raise RuntimeError
        assert capfd.readouterr().err == "what went wrong\n"

    def test_replay_drops_what_the_caller_says_itself(self, capfd):
        with captured((2,)) as out:
            os.write(2, b"Error: bad file\nother\n")
        out.replay(drop=("Error: bad file",))
        assert capfd.readouterr().err == "other\n"
