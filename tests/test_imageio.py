"""Image file I/O: exact PNG round trips at 8 and 16 bits, Pillow formats, errors."""

import struct
import zlib

import numpy as np
import pytest
from PIL import Image

from lightfade_addon import imageio
from lightfade_addon.imageio import decode_png, encode_png, read_image, write_image


def _samples(h, w, c, dtype, seed=0):
    """Smooth gradients, a band of noise and flat areas: every PNG filter gets used."""
    rng = np.random.default_rng(seed)
    top = np.iinfo(dtype).max
    y, x = np.mgrid[0:h, 0:w]
    base = 0.5 + 0.35 * np.sin(x / 5.0 + np.arange(c)[:, None, None])
    base = np.moveaxis(base, 0, -1) + 0.1 * np.cos(y / 3.0)[..., None]
    s = np.clip(base * top + rng.normal(0, top * 0.01, (h, w, c)), 0, top).astype(dtype)
    s[h // 3:h // 3 + 2] = rng.integers(0, top, (2, w, c), endpoint=True).astype(dtype)
    s[-2:] = top // 3
    return s


class TestEncodeDecodePNG:
    @pytest.mark.parametrize("dtype", [np.uint8, np.uint16])
    @pytest.mark.parametrize("channels", [1, 2, 3, 4])
    def test_round_trip_is_exact(self, dtype, channels):
        s = _samples(16, 24, channels, dtype)
        out, transparent = decode_png(encode_png(s))
        assert out.dtype == s.dtype and transparent is None
        np.testing.assert_array_equal(out, s)

    @pytest.mark.parametrize("filter_type", [0, 1, 2, 3, 4])
    def test_each_filter_type_round_trips(self, filter_type):
        s = _samples(9, 13, 3, np.uint16, seed=filter_type)
        data = encode_png(s, filter_type=filter_type)
        rows = np.frombuffer(zlib.decompress(data[41:-16]), np.uint8).reshape(9, -1)
        assert np.all(rows[:, 0] == filter_type)            # the filter really is used
        np.testing.assert_array_equal(decode_png(data)[0], s)

    def test_pillow_reads_our_16_bit_png_as_its_high_bytes(self):
        # An independent decoder: Pillow opens 16-bit RGB PNGs reduced to 8 bits.
        s = _samples(16, 24, 3, np.uint16)
        import io

        with Image.open(io.BytesIO(encode_png(s))) as im:
            assert im.size == (24, 16)
            np.testing.assert_array_equal(np.asarray(im.convert("RGB")), (s >> 8).astype(np.uint8))

    def test_pillow_16_bit_grey_png_decodes_identically(self, tmp_path):
        s = _samples(16, 24, 1, np.uint16)[..., 0]
        Image.fromarray(s).save(tmp_path / "g.png")          # Pillow writes I;16 grey
        out, _ = decode_png((tmp_path / "g.png").read_bytes())
        np.testing.assert_array_equal(out[..., 0], s)

    def test_pillow_8_bit_png_decodes_identically(self, tmp_path):
        # Pillow/libpng choose the filters adaptively (Paeth, Sub, Up, ...).
        s = _samples(16, 24, 3, np.uint8)
        Image.fromarray(s).save(tmp_path / "c.png")
        np.testing.assert_array_equal(decode_png((tmp_path / "c.png").read_bytes())[0], s)

    def test_damaged_file_is_rejected(self):
        data = bytearray(encode_png(_samples(4, 4, 3, np.uint16)))
        data[45] ^= 0xFF                                       # inside IDAT: bad CRC
        with pytest.raises(ValueError, match="CRC"):
            decode_png(bytes(data))


class TestReadWriteImage:
    @pytest.mark.parametrize("alpha", [False, True])
    @pytest.mark.parametrize("bits", [8, 16])
    def test_png_round_trip_is_exact(self, tmp_path, bits, alpha):
        dtype = np.uint8 if bits == 8 else np.uint16
        s = _samples(16, 24, 4 if alpha else 3, dtype)
        top = np.float32(2 ** bits - 1)
        rgb = s[..., :3] / top
        a = s[..., 3] / top if alpha else None
        write_image(tmp_path / "x.png", rgb, a, bits=bits)
        rgb2, a2, info = read_image(tmp_path / "x.png")
        assert (info.format, info.bits, info.width, info.height) == ("PNG", bits, 24, 16)
        assert info.mode == ("RGBA" if alpha else "RGB")
        assert rgb2.dtype == np.float32 and rgb2.shape == (16, 24, 3)
        np.testing.assert_array_equal(np.rint(rgb2 * top).astype(dtype), s[..., :3])
        if alpha:
            np.testing.assert_array_equal(np.rint(a2 * top).astype(dtype), s[..., 3])
        else:
            assert a2 is None
        # write(read(file)) gives the same pixels again
        write_image(tmp_path / "y.png", rgb2, a2, bits=bits)
        rgb3, a3, _ = read_image(tmp_path / "y.png")
        np.testing.assert_array_equal(rgb3, rgb2)

    def test_grey_and_palette_become_rgb(self, tmp_path):
        g = _samples(16, 24, 1, np.uint8)[..., 0]
        Image.fromarray(g, "L").save(tmp_path / "g.png")
        rgb, alpha, info = read_image(tmp_path / "g.png")
        assert info.mode == "L" and alpha is None
        np.testing.assert_array_equal(np.rint(rgb * 255).astype(np.uint8), np.stack([g] * 3, -1))

        p = Image.fromarray(_samples(16, 24, 3, np.uint8)).quantize(16)
        p.info["transparency"] = 0
        p.save(tmp_path / "p.png", transparency=0)
        rgb, alpha, info = read_image(tmp_path / "p.png")
        expected = np.asarray(p.convert("RGBA"))
        assert info.mode == "P"
        np.testing.assert_array_equal(np.rint(rgb * 255).astype(np.uint8), expected[..., :3])
        np.testing.assert_array_equal(np.rint(alpha * 255).astype(np.uint8), expected[..., 3])

    def test_16_bit_grey_alpha_png(self, tmp_path):
        s = _samples(16, 24, 2, np.uint16)
        (tmp_path / "la.png").write_bytes(encode_png(s))
        rgb, alpha, info = read_image(tmp_path / "la.png")
        assert (info.bits, info.mode) == (16, "LA")
        np.testing.assert_array_equal(np.rint(rgb * 65535).astype(np.uint16),
                                      np.repeat(s[..., :1], 3, axis=2))
        np.testing.assert_array_equal(np.rint(alpha * 65535).astype(np.uint16), s[..., 1])

    def test_16_bit_trns_colour_is_transparent(self, tmp_path):
        s = _samples(4, 5, 3, np.uint16)
        s[1, 2] = (1, 2, 3)
        data = encode_png(s)
        trns = struct.pack(">HHH", 1, 2, 3)
        crc = struct.pack(">I", zlib.crc32(b"tRNS" + trns))
        chunk = struct.pack(">I", 6) + b"tRNS" + trns + crc
        data = data[:33] + chunk + data[33:]                   # after IHDR
        (tmp_path / "t.png").write_bytes(data)
        _, alpha, _ = read_image(tmp_path / "t.png")
        assert alpha[1, 2] == 0 and alpha.sum() == alpha.size - 1

    @pytest.mark.parametrize("suffix, fmt", [(".tif", "TIFF"), (".jpg", "JPEG")])
    def test_pillow_formats(self, tmp_path, suffix, fmt):
        s = _samples(16, 24, 3, np.uint8)
        write_image(tmp_path / f"x{suffix}", s / 255.0, bits=8)
        rgb, alpha, info = read_image(tmp_path / f"x{suffix}")
        assert (info.format, info.bits, alpha) == (fmt, 8, None)
        got = np.rint(rgb * 255).astype(np.uint8)
        if fmt == "TIFF":
            np.testing.assert_array_equal(got, s)
        else:                                                  # JPEG is lossy
            with Image.open(tmp_path / f"x{suffix}") as im:
                np.testing.assert_array_equal(got, np.asarray(im.convert("RGB")))
            assert np.abs(got.astype(int) - s).mean() < 20

    def test_16_bit_only_for_png(self, tmp_path):
        with pytest.raises(ValueError, match="PNG only"):
            write_image(tmp_path / "x.tif", np.zeros((2, 2, 3)), bits=16)

    def test_values_are_clipped_and_rounded(self, tmp_path):
        rgb = np.array([[[-0.5, 0.5, 1.5]]])
        write_image(tmp_path / "c.png", rgb)
        out, _, _ = read_image(tmp_path / "c.png")
        np.testing.assert_array_equal(np.rint(out * 255), [[[0, 128, 255]]])

    def test_failed_write_leaves_no_file(self, tmp_path):
        with pytest.raises(ValueError):
            write_image(tmp_path / "n.png", np.full((2, 2, 3), np.nan))
        assert list(tmp_path.iterdir()) == []


class TestReadErrors:
    def test_missing_file(self, tmp_path):
        with pytest.raises(ValueError, match="nope.png.*no such file"):
            read_image(tmp_path / "nope.png")

    def test_not_an_image(self, tmp_path):
        (tmp_path / "notes.png").write_text("hello")
        with pytest.raises(ValueError, match="notes.png"):
            read_image(tmp_path / "notes.png")

    def test_truncated_png(self, tmp_path):
        data = encode_png(_samples(16, 24, 3, np.uint16))
        (tmp_path / "cut.png").write_bytes(data[: len(data) // 2])
        with pytest.raises(ValueError, match="cut.png.*truncated"):
            read_image(tmp_path / "cut.png")

    def test_folder(self, tmp_path):
        with pytest.raises(ValueError, match="folder"):
            read_image(tmp_path)

    def test_16_bit_tiff_is_refused_clearly(self, tmp_path):
        Image.fromarray(_samples(4, 4, 1, np.uint16)[..., 0]).save(tmp_path / "g.tif")
        with pytest.raises(ValueError, match="g.tif.*16-bit PNG"):
            read_image(tmp_path / "g.tif")

    def test_unknown_extension_on_write(self, tmp_path):
        with pytest.raises(ValueError, match="unknown image type"):
            write_image(tmp_path / "x.bmp", np.zeros((2, 2, 3)))

    def test_formats_table(self):
        assert imageio.FORMATS[".png"] == "PNG"
