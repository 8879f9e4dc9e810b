"""``lightfade_addon.contact_sheet``: thumbnails, and sheets in one row or a grid."""

import numpy as np
import pytest
from PIL import Image

from lightfade_addon.contact_sheet import MIN_TILE_WIDTH, contact_sheet, thumbnail

PAD, TEXT_H, TITLE_H = 10, 44, 26            # the sheet's spacing, pixels
TW, TH = 130, 80                             # tile size, pixels
BACKGROUND = (250, 250, 248)
COLOURS = [(200, 0, 0), (0, 160, 0), (0, 0, 220), (200, 160, 0), (0, 150, 150)]


def tiles(n=5):
    return [Image.new("RGB", (TW, TH), COLOURS[i % len(COLOURS)]) for i in range(n)]


def sheet(n=5, **kw):
    labels = [f"{i} y" for i in range(n)]
    return np.asarray(contact_sheet(tiles(n), labels, ["1.0 Mlx·h"] * n, **kw))


def cell(a, r, c, title_h=0):
    """The tile and the label band under it, at row ``r`` and column ``c`` of ``a``."""
    x = PAD + c * (TW + PAD)
    y = PAD + title_h + r * (TH + TEXT_H + PAD)
    return a[y:y + TH, x:x + TW], a[y + TH:y + TH + TEXT_H, x:x + TW]


class TestContactSheet:
    def test_one_row_by_default(self):
        a = sheet()
        assert a.shape == (PAD + TH + TEXT_H + PAD, 5 * TW + 6 * PAD, 3)
        for c in range(5):
            tile, _ = cell(a, 0, c)
            assert (tile == COLOURS[c]).all()

    def test_five_tiles_in_three_columns_make_two_rows(self):
        a = sheet(columns=3, title="a title")
        assert a.shape == (PAD + TITLE_H + 2 * (TH + TEXT_H + PAD), 3 * TW + 4 * PAD, 3)
        for i in range(5):
            tile, band = cell(a, *divmod(i, 3), title_h=TITLE_H)
            assert (tile == COLOURS[i]).all(), i
            assert band.min() < 100, f"no label under tile {i}"
        tile, band = cell(a, 1, 2, title_h=TITLE_H)            # the empty sixth cell
        assert (tile == BACKGROUND).all() and (band == BACKGROUND).all()
        assert a[PAD:PAD + TITLE_H, PAD:].min() < 100           # the title

    def test_a_column_is_as_wide_as_its_widest_label(self):
        labels = ["0 y", "1 y", "a label much wider than one tile, surely", "3 y"]
        a = np.asarray(contact_sheet(tiles(4), labels, [""] * 4, columns=2))
        wide = a.shape[1] - TW - 3 * PAD                        # column 0; column 1 is TW
        assert wide > TW
        for i, x in enumerate([PAD + (wide - TW) // 2, 2 * PAD + wide] * 2):
            y = PAD + (i // 2) * (TH + TEXT_H + PAD)
            assert (a[y:y + TH, x:x + TW] == COLOURS[i]).all(), i    # centred in its column

    def test_more_columns_than_tiles_is_one_row(self):
        np.testing.assert_array_equal(sheet(3, columns=8), sheet(3))

    def test_one_column(self):
        a = sheet(3, columns=1)
        assert a.shape == (PAD + 3 * (TH + TEXT_H + PAD), TW + 2 * PAD, 3)
        assert (cell(a, 2, 0)[0] == COLOURS[2]).all()

    def test_zero_columns_is_an_error(self):
        with pytest.raises(ValueError, match="columns"):
            sheet(columns=0)


class TestThumbnail:
    def test_large_images_shrink_to_the_longest_side(self):
        im = thumbnail(np.full((200, 600, 3), 0.5), size=300)
        assert im.size == (300, 100) and im.mode == "RGB"

    def test_narrow_images_grow_by_a_whole_factor(self):
        im = thumbnail(np.zeros((10, 20, 3)))
        k = -(-MIN_TILE_WIDTH // 20)
        assert im.size == (20 * k, 10 * k)

    def test_alpha_is_composited_over_white(self):
        im = thumbnail(np.zeros((2, 200, 3)), alpha=np.zeros((2, 200)))
        assert (np.asarray(im) == 255).all()
