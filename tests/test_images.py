"""Image files through OpenImageIO: exact round trips, every format, metadata, errors."""

import os

import numpy as np
import pytest
from PIL import Image, ImageCms

from lightfade_addon.images import FORMATS, read_image, write_image

#: (extension, sample type) pairs that store values exactly (JPEG is lossy: own test).
EXACT = [(".png", "uint8"), (".png", "uint16"), (".tif", "uint8"), (".tif", "uint16"),
         (".tif", "float"), (".exr", "half"), (".exr", "float")]
TOP = {"uint8": 255, "uint16": 65535}


def _samples(h, w, c, dtype, seed=0):
    """Gradients, a band of noise and flat areas, as stored samples of ``dtype``."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:h, 0:w]
    base = 0.5 + 0.35 * np.sin(x / 5.0 + np.arange(c)[:, None, None])
    base = np.moveaxis(base, 0, -1) + 0.1 * np.cos(y / 3.0)[..., None]
    v = np.clip(base + rng.normal(0, 0.01, (h, w, c)), 0, 1)
    v[h // 3:h // 3 + 2] = rng.random((2, w, c))
    if dtype in TOP:
        return np.rint(v * TOP[dtype]) / TOP[dtype]
    return v.astype(np.float16 if dtype == "half" else np.float32).astype(np.float64)


class TestRoundTrip:
    @pytest.mark.parametrize("alpha", [False, True])
    @pytest.mark.parametrize("suffix, dtype", EXACT)
    def test_every_value_survives(self, tmp_path, suffix, dtype, alpha):
        s = _samples(16, 24, 4 if alpha else 3, dtype)
        a = s[..., 3] if alpha else None
        write_image(tmp_path / f"x{suffix}", s[..., :3], a, dtype)
        rgb, a2, info = read_image(tmp_path / f"x{suffix}")
        assert (info.format, info.dtype, info.width, info.height) == (
            FORMATS[suffix][0], dtype, 24, 16)
        assert info.mode == ("RGBA" if alpha else "RGB")
        assert rgb.dtype == np.float32 and rgb.shape == (16, 24, 3)
        np.testing.assert_array_equal(rgb, s[..., :3].astype(np.float32))
        if alpha:
            np.testing.assert_array_equal(a2, a.astype(np.float32))
        else:
            assert a2 is None
        # write(read(file)) gives the same file contents again
        write_image(tmp_path / f"y{suffix}", rgb, a2, info.dtype, info.metadata)
        rgb3, a3, _ = read_image(tmp_path / f"y{suffix}")
        np.testing.assert_array_equal(rgb3, rgb)

    def test_integer_values_are_the_stored_samples_over_their_maximum(self, tmp_path):
        s = (np.arange(16 * 24 * 3, dtype=np.uint16) * 137).reshape(16, 24, 3)
        Image.fromarray(s[..., 0]).save(tmp_path / "g.png")     # Pillow: 16-bit grey
        rgb, alpha, info = read_image(tmp_path / "g.png")
        assert (info.dtype, info.bits, info.mode, alpha) == ("uint16", 16, "Y", None)
        np.testing.assert_array_equal(rgb, np.repeat(s[..., :1], 3, -1) / np.float32(65535))

    def test_values_above_one_survive_in_float_files(self, tmp_path):
        rgb = np.full((2, 3, 3), 4.5)
        write_image(tmp_path / "hdr.exr", rgb, None, "half")
        out, _, info = read_image(tmp_path / "hdr.exr")
        assert info.linear and not read_image(_png(tmp_path))[2].linear
        np.testing.assert_array_equal(out, rgb)

    def test_integers_are_clipped_and_rounded(self, tmp_path):
        write_image(tmp_path / "c.png", np.array([[[-0.5, 0.5, 1.5]]]))
        out, _, _ = read_image(tmp_path / "c.png")
        np.testing.assert_array_equal(out * 255, [[[0, 128, 255]]])

    def test_jpeg_is_read_like_pillow_reads_it(self, tmp_path):
        s = _samples(16, 24, 3, "uint8")
        write_image(tmp_path / "x.jpg", s, np.ones((16, 24)), "uint8")   # alpha dropped
        rgb, alpha, info = read_image(tmp_path / "x.jpg")
        assert (info.format, info.dtype, alpha) == ("jpeg", "uint8", None)
        with Image.open(tmp_path / "x.jpg") as im:
            pil = np.asarray(im.convert("RGB")).astype(int)
        assert np.abs(np.rint(rgb * 255) - pil).max() <= 2        # libjpeg IDCT variants
        Image.fromarray(np.rint(s * 255).astype(np.uint8)).save(tmp_path / "q50.jpg",
                                                                quality=50)
        rough = np.abs(read_image(tmp_path / "q50.jpg")[0] - s).mean()
        assert np.abs(rgb - s).mean() < 0.8 * rough              # written at quality 95


def _png(folder, **save):
    path = folder / "p.png"
    Image.fromarray((_samples(8, 8, 3, "uint8") * 255).astype(np.uint8)).save(path, **save)
    return path


class TestLayoutsAndMetadata:
    def test_palette_with_transparency_becomes_rgba(self, tmp_path):
        p = Image.fromarray((_samples(16, 24, 3, "uint8") * 255).astype(np.uint8)).quantize(16)
        p.save(tmp_path / "p.png", transparency=0)
        rgb, alpha, _ = read_image(tmp_path / "p.png")
        with Image.open(tmp_path / "p.png") as im:
            expected = np.asarray(im.convert("RGBA"))
        np.testing.assert_array_equal(rgb * 255, expected[..., :3])
        np.testing.assert_array_equal(alpha * 255, expected[..., 3])
        assert alpha.min() == 0

    def test_alpha_is_straight_not_premultiplied(self, tmp_path):
        rgb = np.full((2, 2, 3), 0.8)
        write_image(tmp_path / "a.png", rgb, np.full((2, 2), 0.2), "uint16")
        out, alpha, _ = read_image(tmp_path / "a.png")
        np.testing.assert_allclose(out, 0.8, atol=1e-5)

    def test_icc_profile_and_colour_space_travel_to_the_output(self, tmp_path):
        profile = ImageCms.ImageCmsProfile(ImageCms.createProfile("sRGB")).tobytes()
        rgb, alpha, info = read_image(_png(tmp_path, icc_profile=profile))
        assert bytes(info.metadata["ICCProfile"]) == profile
        assert info.colorspace.lower().startswith("srgb")      # 3.0: "sRGB"; 3.2: "srgb_rec709_scene"
        write_image(tmp_path / "out.tif", rgb, alpha, info.dtype, info.metadata)
        with Image.open(tmp_path / "out.tif") as im:
            assert im.info["icc_profile"] == profile

    def test_exr_chromaticities_travel_to_the_output(self, tmp_path):
        chroma = (0.713, 0.293, 0.165, 0.830, 0.128, 0.044, 0.32168, 0.33767)   # ACES AP1
        write_image(tmp_path / "a.exr", np.zeros((2, 2, 3)), None, "half",
                    {"chromaticities": chroma})
        rgb, alpha, info = read_image(tmp_path / "a.exr")
        write_image(tmp_path / "b.exr", rgb, alpha, info.dtype, info.metadata)
        np.testing.assert_allclose(read_image(tmp_path / "b.exr")[2].metadata["chromaticities"],
                                   chroma, rtol=1e-6)

    def test_orientation_tag_is_applied(self, tmp_path):
        s = (_samples(4, 6, 3, "uint8") * 255).astype(np.uint8)
        im = Image.fromarray(s)
        exif = im.getexif()
        exif[0x0112] = 6                                   # rotate 90° clockwise to view
        im.save(tmp_path / "r.jpg", exif=exif, quality=100, subsampling=0)
        rgb, _, info = read_image(tmp_path / "r.jpg")
        assert (info.width, info.height) == (4, 6)
        plain, _, _ = read_image(_jpeg_without_exif(tmp_path, s))
        np.testing.assert_array_equal(rgb, np.rot90(plain, k=-1))


def _jpeg_without_exif(folder, s):
    Image.fromarray(s).save(folder / "plain.jpg", quality=100, subsampling=0)
    return folder / "plain.jpg"


class TestErrors:
    def test_missing_file(self, tmp_path):
        with pytest.raises(ValueError, match=r"^cannot read '.*nope.png': no such file$"):
            read_image(tmp_path / "nope.png")

    def test_folder(self, tmp_path):
        with pytest.raises(ValueError, match="it is a folder"):
            read_image(tmp_path)

    def test_not_an_image(self, tmp_path):
        (tmp_path / "notes.png").write_text("hello")
        with pytest.raises(ValueError, match=r"^cannot read '.*notes.png': .+") as exc:
            read_image(tmp_path / "notes.png")
        assert "\n" not in str(exc.value)

    def test_truncated_file(self, tmp_path, capfd):
        """One line naming the file, with libpng's reason in it; libpng (C) prints
        nothing of its own."""
        write_image(tmp_path / "whole.png", _samples(64, 64, 3, "uint16"), None, "uint16")
        data = (tmp_path / "whole.png").read_bytes()
        (tmp_path / "cut.png").write_bytes(data[: len(data) // 2])
        capfd.readouterr()
        with pytest.raises(ValueError, match=r"^cannot read '.*cut.png': ") as exc:
            read_image(tmp_path / "cut.png")
        assert "\n" not in str(exc.value)
        assert "libpng error: IDAT: Read error: hit end of file" in str(exc.value)
        assert capfd.readouterr() == ("", "")

    def test_what_a_library_says_about_a_file_it_reads_gets_through(self, tmp_path, capfd,
                                                                      monkeypatch):
        """Only a failed read folds the library's lines into its error."""
        from lightfade_addon import images

        write_image(tmp_path / "ok.png", _samples(4, 4, 3, "uint8"), None, "uint8")
        real = images._read

        def chatty(oiio, path):
            os.write(2, b"libpng warning: iCCP: known incorrect sRGB profile\n")
            return real(oiio, path)

        monkeypatch.setattr(images, "_read", chatty)
        capfd.readouterr()
        rgb, _alpha, _info = read_image(tmp_path / "ok.png")
        assert rgb.shape == (4, 4, 3)
        assert capfd.readouterr().err == "libpng warning: iCCP: known incorrect sRGB profile\n"

    @pytest.mark.parametrize("suffix, dtype", [(".png", "half"), (".jpg", "uint16"),
                                               (".exr", "uint8")])
    def test_a_type_the_format_cannot_hold(self, tmp_path, suffix, dtype):
        with pytest.raises(ValueError, match=f"cannot write .*x{suffix}.*{dtype}"):
            write_image(tmp_path / f"x{suffix}", np.zeros((2, 2, 3)), None, dtype)
        assert list(tmp_path.iterdir()) == []

    def test_unknown_extension(self, tmp_path):
        with pytest.raises(ValueError, match="unknown image type"):
            write_image(tmp_path / "x.bmp", np.zeros((2, 2, 3)))

    def test_failed_write_leaves_no_file(self, tmp_path):
        with pytest.raises(ValueError, match="NaN"):
            write_image(tmp_path / "n.png", np.full((2, 2, 3), np.nan))
        assert list(tmp_path.iterdir()) == []

    def test_unwritable_folder_leaves_no_file(self, tmp_path):
        with pytest.raises(OSError):
            write_image(tmp_path / "no" / "such" / "x.png", np.zeros((2, 2, 3)))
        assert list(tmp_path.iterdir()) == []

    def test_without_openimageio_the_message_says_what_to_install(self, tmp_path, monkeypatch):
        import sys

        write_image(tmp_path / "x.png", np.zeros((2, 2, 3)))
        monkeypatch.setitem(sys.modules, "OpenImageIO", None)       # import fails
        with pytest.raises(ValueError, match=r"^cannot read '.*x.png': .*pip install OpenImageIO"):
            read_image(tmp_path / "x.png")
