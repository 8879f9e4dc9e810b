"""``python -m lightfade_addon age-image``: outputs, exactness at 0 years, fading, errors."""

import hashlib
import io
import os
import sys

import numpy as np
import pytest
from PIL import Image

from lightfade_addon import cli, images
from lightfade_addon.core.fading.recipes import RECIPES
from lightfade_addon.core.colour.colorimetry import (
    XYZ_to_Lab,
    delta_E_2000,
    linear_srgb_to_XYZ,
    srgb_decode,
    srgb_encode,
)

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
H, W = 16, 24


def sha(path):
    return hashlib.sha256(open(path, "rb").read()).hexdigest()


def lab(rgb):
    return XYZ_to_Lab(linear_srgb_to_XYZ(srgb_decode(rgb)))


def mean_dE(a, b):
    return float(delta_E_2000(lab(a), lab(b)).mean())


def photo_samples(bits, seed=0):
    """A small colourful test picture: gradients plus saturated patches, with alpha."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:H, 0:W] / np.array([H - 1, W - 1])[:, None, None]
    rgb = np.stack([x, 1 - x * y, 0.3 + 0.6 * y], -1)
    rgb[2:7, 3:9] = (0.9, 0.1, 0.5)          # magenta-ish
    rgb[9:14, 14:21] = (0.1, 0.5, 0.9)       # blue
    rgb = np.clip(rgb + rng.normal(0, 0.02, rgb.shape), 0, 1)
    alpha = np.clip(0.5 + x, 0, 1)
    top = 2 ** bits - 1
    return np.rint(rgb * top) / top, np.rint(alpha * top) / top


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    """One grid cache for the module (the same grid serves most runs)."""
    path = tmp_path_factory.mktemp("grid-cache")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("LIGHTFADE_CACHE", str(path))
        yield path


def make_photo(folder, name="photo.png", bits=8):
    rgb, alpha = photo_samples(bits)
    path = folder / name
    images.write_image(path, rgb, alpha, bits)
    return path


def age(capsys, *argv):
    code = cli.main(["age-image", *map(str, argv)])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope="module")
def run8(cache, tmp_path_factory):
    """One 8-bit run with the default settings at 0, 2.5, 5 and 25 years."""
    folder = tmp_path_factory.mktemp("run8")
    photo = make_photo(folder)
    before = sha(photo)
    out_dir = folder / "aged"
    buf_out, buf_err = io.StringIO(), io.StringIO()
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(sys, "stdout", buf_out)
        mp.setattr(sys, "stderr", buf_err)
        code = cli.main(["age-image", str(photo), "--years", "0", "2.5", "5", "25",
                         "--out", str(out_dir)])
    return dict(code=code, photo=photo, before=before, out=out_dir,
                stdout=buf_out.getvalue(), stderr=buf_err.getvalue())


class TestAgeImage:
    def test_outputs_are_named_by_the_years_as_written(self, run8):
        assert run8["code"] == 0, run8["stderr"]
        names = sorted(p.name for p in run8["out"].iterdir())
        assert names == ["photo_0y.png", "photo_2.5y.png", "photo_25y.png", "photo_5y.png",
                         "photo_contact.png"]

    def test_input_is_untouched(self, run8):
        assert sha(run8["photo"]) == run8["before"]

    def test_zero_years_is_bit_identical(self, run8):
        src, a_src, info = images.read_image(run8["photo"])
        out, a_out, info0 = images.read_image(run8["out"] / "photo_0y.png")
        assert info0.bits == 8 and info0.mode == "RGBA"
        np.testing.assert_array_equal(np.rint(out * 255), np.rint(src * 255))
        np.testing.assert_array_equal(np.rint(a_out * 255), np.rint(a_src * 255))

    def test_later_years_fade_more_and_keep_alpha(self, run8):
        src, a_src, _ = images.read_image(run8["photo"])
        dE = []
        for y in ("2.5", "5", "25"):
            out, a_out, info = images.read_image(run8["out"] / f"photo_{y}y.png")
            assert info.bits == 8
            np.testing.assert_array_equal(a_out, a_src)
            dE.append(mean_dE(src, out))
        assert 0.05 < dE[0] < dE[1] < dE[2], dE
        # magenta fades first on printed paper: the magenta patch loses chroma
        out25, _, _ = images.read_image(run8["out"] / "photo_25y.png")
        L0, L25 = lab(src[2:7, 3:9]), lab(out25[2:7, 3:9])
        assert np.hypot(L25[..., 1], L25[..., 2]).mean() < np.hypot(L0[..., 1], L0[..., 2]).mean()

    def test_prints_the_dose_of_each_year(self, run8):
        lines = run8["stdout"].splitlines()
        assert "5 y = 2.19 Mlx·h (150 lux × 8 h/day × 365 days/year)" in lines
        assert "25 y = 10.95 Mlx·h (150 lux × 8 h/day × 365 days/year)" in lines
        assert "0 y = 0.00 Mlx·h (150 lux × 8 h/day × 365 days/year)" in lines
        assert "building the fading grid" in run8["stderr"]      # the progress lines
        assert "\r" not in run8["stderr"]                        # not a terminal: plain lines

    def test_the_schedule_sets_the_light_and_the_dose(self, tmp_path, capsys, monkeypatch):
        from lightfade_addon.core.aging import ager as aging

        lights = []

        def exact(rgb, years, recipe, light, exposure, **kw):      # records, ages nothing
            lights.append(light)
            return [rgb] * len(years)

        monkeypatch.setattr(aging, "age_image_exact", exact, raising=False)
        images.write_image(tmp_path / "grey.png", np.full((2, 2, 3), 0.5))
        code, out, err = age(capsys, tmp_path / "grey.png", "--years", "0", "5", "--exact",
                             "--lux", "50", "--hours-per-day", "6", "--days-per-year", "100",
                             "--uv-filter", "--light", "led", "--out", tmp_path)
        assert code == 0, err
        assert lights == [aging.Light("led", True, 50.0, 6.0, 100.0)]
        assert "5 y = 0.15 Mlx·h (50 lux × 6 h/day × 100 days/year)" in out.splitlines()

    def test_contact_sheet(self, run8):
        with Image.open(run8["out"] / "photo_contact.png") as im:
            assert im.mode == "RGB"
            assert im.width > 4 * W and im.height > H

    def test_16_bit_in_16_bit_out(self, cache, tmp_path, capsys):
        photo = make_photo(tmp_path, "deep.png", bits=16)
        before = sha(photo)
        code, out, err = age(capsys, photo, "--years", "0", "25", "--out", tmp_path / "o")
        assert code == 0, err
        src, a_src, _ = images.read_image(photo)
        zero, a0, info0 = images.read_image(tmp_path / "o" / "deep_0y.png")
        aged, a25, info25 = images.read_image(tmp_path / "o" / "deep_25y.png")
        assert info0.bits == info25.bits == 16
        np.testing.assert_array_equal(np.rint(zero * 65535), np.rint(src * 65535))
        np.testing.assert_array_equal(a0, a_src)
        np.testing.assert_array_equal(a25, a_src)
        assert mean_dE(src, aged) > 0.5
        # 16-bit detail survives: more distinct levels than 8 bits could hold
        levels16 = np.unique(np.rint(aged[..., 0] * 65535)).size
        assert levels16 > np.unique(np.rint(aged[..., 0] * 255)).size
        assert sha(photo) == before

    def test_float_exr_is_linear_in_and_out(self, cache, run8, tmp_path, capsys):
        # The 8-bit photo, linearised into a half-float EXR: ages like the sRGB original.
        src, alpha, _ = images.read_image(run8["photo"])
        linear = srgb_decode(src)
        images.write_image(tmp_path / "lin.exr", linear, alpha, "half",
                           {"oiio:ColorSpace": "lin_rec709_scene"})
        stored, _, stored_info = images.read_image(tmp_path / "lin.exr")
        assert stored_info.colorspace.startswith("lin_rec709")   # OpenImageIO 3.0 drops _scene
        code, out, err = age(capsys, tmp_path / "lin.exr", "--years", "0", "25",
                             "--out", tmp_path / "o")
        assert code == 0, err
        assert "(linear)" in out
        zero, a0, info0 = images.read_image(tmp_path / "o" / "lin_0y.exr")
        aged, a25, info25 = images.read_image(tmp_path / "o" / "lin_25y.exr")
        assert info0.dtype == info25.dtype == "half"
        assert info25.colorspace == stored_info.colorspace
        np.testing.assert_array_equal(zero, stored)
        np.testing.assert_array_equal(a25, a0)
        via_srgb, _, _ = images.read_image(run8["out"] / "photo_25y.png")
        assert delta_E_2000(lab(srgb_encode(aged)), lab(via_srgb)).mean() < 1.0
        assert mean_dE(src, srgb_encode(aged)) > 0.5

    def test_colour_profile_travels_to_the_outputs(self, cache, tmp_path, capsys):
        from PIL import ImageCms

        profile = ImageCms.ImageCmsProfile(ImageCms.createProfile("sRGB")).tobytes()
        rgb, alpha = photo_samples(8)
        Image.fromarray(np.rint(rgb * 255).astype(np.uint8)).save(tmp_path / "icc.png",
                                                                 icc_profile=profile)
        code, out, err = age(capsys, tmp_path / "icc.png", "--years", "0", "25")   # run8's grid
        assert code == 0, err
        for name in ("icc_0y.png", "icc_25y.png"):
            with Image.open(tmp_path / name) as im:
                assert im.info.get("icc_profile") == profile, name

    def test_exposure_mask_keeps_the_shadow(self, cache, tmp_path, capsys):
        photo = make_photo(tmp_path)
        mask = np.zeros((H, W, 3))
        mask[:, W // 2:] = 1.0                                   # right half in the light
        images.write_image(tmp_path / "mask.png", mask)
        code, out, err = age(capsys, photo, "--years", "25", "--exposure", tmp_path / "mask.png",
                             "--out", tmp_path)
        assert code == 0, err
        src, _, _ = images.read_image(photo)
        aged, _, _ = images.read_image(tmp_path / "photo_25y.png")
        np.testing.assert_array_equal(aged[:, : W // 2], src[:, : W // 2])
        assert mean_dE(src[:, W // 2:], aged[:, W // 2:]) > 0.5
        assert "mask scales them by 0.00-1.00" in out

    def test_exact_path_agrees_with_the_grid(self, cache, run8, tmp_path, capsys):
        # --exact: one direct simulation per distinct colour, on a corner of the photo
        # (the magenta patch's edge and the gradient: 56 colours); each pixel ages on its
        # own, so the grid's result for the corner is that corner of run8's.
        rows, cols = slice(1, 8), slice(2, 10)
        src, alpha, _ = images.read_image(run8["photo"])
        src, alpha = src[rows, cols], alpha[rows, cols]
        images.write_image(tmp_path / "corner.png", src, alpha, 8)
        code, out, err = age(capsys, tmp_path / "corner.png", "--years", "0", "25", "--exact",
                             "--out", tmp_path / "o")
        assert code == 0, err
        assert "exact reference path" in out.splitlines()[0]
        assert "simulating exposure level" in err and "grid" not in err   # no grid was built
        exact, _, _ = images.read_image(tmp_path / "o" / "corner_25y.png")
        grid, _, _ = images.read_image(run8["out"] / "photo_25y.png")
        gap = delta_E_2000(lab(exact), lab(grid[rows, cols]))
        assert gap.max() < 1.0 < mean_dE(src, exact), (gap.max(), mean_dE(src, exact))
        zero, _, _ = images.read_image(tmp_path / "o" / "corner_0y.png")
        np.testing.assert_array_equal(zero, src)

    @pytest.mark.parametrize("recipe", list(RECIPES))
    def test_grid_within_1_dE00_of_exact_on_a_photo(self, cache, tmp_path, capsys, recipe):
        # a photo-like picture of many colours (sky, hills, blossoms, noise) under
        # bright fluorescent light for 15 years (a visible fade in every recipe): the grid (what age-image does) within ΔE00 1
        # of --exact at every pixel, for every recipe. Bare wood unmixes one colourant,
        # so its sky blues lie off the recipe's reach: only their converged
        # least-squares solution is the reference's (a few Newton steps left them at
        # 0.2 of extractive instead of none: ΔE00 9.4 here).
        from benchmarks.problem import synthetic_photo

        photo = tmp_path / "photo.png"           # 16 bits: the outputs' rounding is not
        images.write_image(photo, synthetic_photo(48, 48), None, 16)  # what is measured
        src, _, _ = images.read_image(photo)
        assert np.unique(src.reshape(-1, 3), axis=0).shape[0] > 2000     # many colours
        aged = {}
        for path in ("grid", "exact"):
            code, _, err = age(capsys, photo, "--years", "15", "--recipe", recipe,
                               "--light", "fluorescent", "--lux", "1000",
                               "--out", tmp_path / path,
                               *(["--exact"] if path == "exact" else []))
            assert code == 0, err
            aged[path] = images.read_image(tmp_path / path / "photo_15y.png")[0]
        gap = delta_E_2000(lab(aged["grid"]), lab(aged["exact"]))
        assert gap.max() < 1.0 < mean_dE(src, aged["exact"]) * 4, (gap.max(),
                                                                    mean_dE(src, aged["exact"]))

    def test_help_documents_defaults_and_units(self, capsys):
        assert cli.main(["age-image", "--help"]) == 0
        text = " ".join(capsys.readouterr().out.split())
        for s in ("default: printed-paper", "default: daylight-glass", "in lux (default: 150",
                  "in hours, 0-24 (default: 8)", "in days, 0-366 (default: 365)", "UV filter"):
            assert s in text, s


def _case_files(tmp_path, case):
    """Set up the inputs of an error case; returns the argument list."""
    photo = make_photo(tmp_path)
    base = [photo, "--out", tmp_path / "out"]
    if case == "missing":
        return [tmp_path / "nope.png", "--years", "5"]
    if case == "unreadable":
        (tmp_path / "text.png").write_text("not a picture")
        return [tmp_path / "text.png", "--years", "5"]
    if case == "out-is-file":
        (tmp_path / "file").write_text("x")
        return [photo, "--years", "5", "--out", tmp_path / "file"]
    if case == "mask-size":
        images.write_image(tmp_path / "m.png", np.ones((H + 1, W, 3)))
        return base + ["--years", "5", "--exposure", tmp_path / "m.png"]
    if case == "mask-missing":
        return base + ["--years", "5", "--exposure", tmp_path / "none.png"]
    if case == "output-is-input":                       # a hard link to the photo
        (tmp_path / "out").mkdir()
        os.link(photo, tmp_path / "out" / "photo_5y.png")
        return base + ["--years", "5"]
    if case == "output-is-mask":
        (tmp_path / "out").mkdir()
        images.write_image(tmp_path / "out" / "photo_5y.png", np.ones((H, W, 3)))
        return base + ["--years", "5", "--exposure", tmp_path / "out" / "photo_5y.png"]
    extra = {
        "negative-years": ["--years", "0", "-5"],
        "nan-years": ["--years", "nan"],
        "word-years": ["--years", "five"],
        "inf-years": ["--years", "inf"],
        "negative-lux": ["--years", "5", "--lux", "-150"],
        "nan-lux": ["--years", "5", "--lux", "nan"],
        "hours": ["--years", "5", "--hours-per-day", "25"],
        "days": ["--years", "5", "--days-per-year", "-1"],
        "recipe": ["--years", "5", "--recipe", "velvet"],
        "light": ["--years", "5", "--light", "candle"],
    }[case]
    return base + extra


ERROR_CASES = {
    "missing": "nope.png",
    "unreadable": "text.png",
    "out-is-file": "is a file",
    "mask-size": "must match",
    "mask-missing": "none.png",
    "output-is-input": "refusing to write",
    "output-is-mask": "refusing to write",
    "negative-years": "years",
    "nan-years": "years",
    "word-years": "'five'",
    "inf-years": "years",
    "negative-lux": "--lux",
    "nan-lux": "--lux",
    "hours": "--hours-per-day",
    "days": "--days-per-year",
    "recipe": ["--recipe: invalid choice: 'velvet'", "printed-paper", "dyed-fabric",
               "painted-wood", "bare-wood"],
    "light": ["--light: invalid choice: 'candle'", "daylight", "daylight-glass",
              "incandescent", "fluorescent", "led"],
}


class TestErrors:
    @pytest.mark.parametrize("case", list(ERROR_CASES))
    def test_one_line_exit_2_input_untouched(self, cache, tmp_path, capsys, case):
        argv = _case_files(tmp_path, case)
        hashes = {p: sha(p) for p in tmp_path.rglob("*") if p.is_file()}
        code, out, err = age(capsys, *argv)
        assert code == 2
        lines = err.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("lightfade: error: "), err
        expected = ERROR_CASES[case]
        for part in [expected] if isinstance(expected, str) else expected:
            assert part in lines[0]
        assert "Traceback" not in err
        assert {p: sha(p) for p in hashes} == hashes            # nothing overwritten
        new = [p for p in tmp_path.rglob("*") if p.is_file() and p not in hashes]
        assert new == []                                         # nothing written

    def test_a_truncated_png_is_one_line_naming_it(self, cache, tmp_path, capfd):
        """libpng's own complaint (C, on file descriptor 2) is part of our line."""
        data = make_photo(tmp_path).read_bytes()
        (tmp_path / "cut.png").write_bytes(data[: len(data) // 2])
        capfd.readouterr()
        code = cli.main(["age-image", str(tmp_path / "cut.png"), "--years", "5"])
        out, err = capfd.readouterr()
        assert code == 2 and out == ""
        [line] = err.splitlines()
        assert line.startswith(f"lightfade: error: cannot read {str(tmp_path / 'cut.png')!r}: ")
        assert "libpng error: IDAT: Read error: hit end of file" in line

    def test_in_a_real_process(self, early):
        folder, res = early("real process")
        assert res.returncode == 2
        assert res.stderr.splitlines() == [
            f"lightfade: error: cannot read {str(folder / 'missing.png')!r}: no such file"]


def age_a_missing_file(jobs, folder):
    """``python -m lightfade_addon age-image`` of a missing file, in a real process.  An
    early job (tests/conftest.py): it runs beside the tests before this one."""
    return folder, jobs.run([sys.executable, "-m", "lightfade_addon", "age-image",
                             str(folder / "missing.png"), "--years", "5"], cwd=ROOT, timeout=60)


EARLY = {"real process": age_a_missing_file}


class TestHelpers:
    def test_mask_luminance_is_rec_709_of_the_stored_values(self):
        from lightfade_addon.commands.age_image import exposure_from_mask

        rgb = np.array([[[1, 0, 0], [0, 1, 0], [0, 0, 1], [0.5, 0.5, 0.5], [2, 2, 2]]],
                       np.float32)
        np.testing.assert_allclose(exposure_from_mask(rgb),
                                   [[0.2126, 0.7152, 0.0722, 0.5, 1.0]], rtol=1e-6)

    def test_bounds_are_inclusive_and_finite(self):
        import argparse

        from lightfade_addon.commands import number

        hours = number("hours", 0, 24)
        assert (hours("0"), hours("24"), hours("7.5")) == (0.0, 24.0, 7.5)
        for bad in ("-0.001", "24.001", "inf", "nan", "eight", ""):
            with pytest.raises(argparse.ArgumentTypeError, match="hours"):
                hours(bad)
        assert number("lux")("1e6") == 1e6

    def test_parse_years_keeps_the_text(self):
        from lightfade_addon.commands.age_image import format_dose, parse_years

        assert parse_years(["0", "2.5", "2.5", "1e1"]) == [("0", 0.0), ("2.5", 2.5), ("1e1", 10.0)]
        assert format_dose(2.19e6) == "2.19" and format_dose(0) == "0.00"
        assert format_dose(1200.0) == "0.0012"
