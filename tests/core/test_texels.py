"""texels: photographs with more colours than the unmixing budget, unmixed through bins.

Beyond :data:`.texels.UNMIX_BUDGET` distinct colours, colours are gathered in bins of
fewer bits (:func:`.texels._codes`), each bin's centre (:func:`.texels._decode`) is
unmixed exactly and every colour takes a linear step from it
(:func:`.texels._linearised`). A wrong centre is partly hidden by the linear step (the
step starts from wherever the centre is), so these tests pin the centres themselves
and the linearised concentrations to the accuracy of the right centres. The budget
is made small so that a small crop of a real photograph takes the binned path.
"""

import numpy as np
import pytest

from lightfade_addon.core.aging import texels
from lightfade_addon.core.colour.colorimetry import (
    XYZ_to_Lab,
    delta_E_2000,
    linear_srgb_to_XYZ,
    srgb_decode,
)
from lightfade_addon.core.fading.recipes import get_recipe
from lightfade_addon.core.fading.unmix import get_unmixer


@pytest.fixture(scope="module")
def photo():
    """A crop of Grace Hopper's portrait (matplotlib's sample data), 8-bit encoded sRGB,
    (n, 3): the face, uniform and background, a few thousand distinct colours."""
    cbook = pytest.importorskip("matplotlib.cbook")
    from PIL import Image

    img = np.asarray(Image.open(cbook.get_sample_data("grace_hopper.jpg")).convert("RGB"))
    return (img[120:440:4, 100:420:4].reshape(-1, 3) / 255.0).astype(np.float32)


@pytest.fixture(scope="module")
def unmixer():
    return get_unmixer(get_recipe("printed-paper"))


def lab(encoded):
    return XYZ_to_Lab(linear_srgb_to_XYZ(srgb_decode(np.asarray(encoded, float))))


class TestBins:
    """Codes and their decoded bin centres."""

    @pytest.mark.parametrize("drop", [0, 1, 3, 5])
    def test_every_colour_is_within_half_a_bin_of_its_centre(self, photo, drop):
        centre = texels._decode(texels._codes(photo, drop), drop)
        half = ((1 << drop) - 1) / 2 / 255 + 0.5 / 255            # the bin, and 8-bit rounding
        assert np.abs(centre - photo).max() <= half + 1e-6
        # the centres are the middles: over many colours the offsets average out
        assert np.abs((centre - photo).mean(axis=0)).max() < 0.25 * (1 << drop) / 255 + 1e-3

    def test_channels_keep_their_places(self):
        red = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]], np.float32)
        for drop in (0, 2):
            centre = texels._decode(texels._codes(red, drop), drop)
            assert centre[0, 0] > 0.9 and centre[0, 2] < 0.1
            assert centre[1, 2] > 0.9 and centre[1, 0] < 0.1

    def test_eight_bit_colours_decode_exactly(self, photo):
        np.testing.assert_array_equal(texels._decode(texels._codes(photo)).astype(np.float32),
                                      photo)


class TestLinearised:
    """Many colours from few solves: as good as solving each, to the linear step's error."""

    def test_concentrations_match_the_exact_solves(self, photo, unmixer, monkeypatch):
        colours = np.unique(photo, axis=0)
        monkeypatch.setattr(texels, "UNMIX_BUDGET", colours.shape[0] // 40)
        c_lin = texels._linearised(colours, unmixer, texels.UNMIX_REFINE)
        assert colours.shape[0] > 8 * texels.UNMIX_BUDGET          # bins of several bits
        c_exact = texels._unmix(colours, unmixer, texels.UNMIX_REFINE)
        # measured: median 0.41, mean 1.8 (bins 32 codes wide: 5 bits dropped, 107 bins);
        # a centre half a bin off gives 2.5 and 11, a wrong drop 35 and 38, swapped
        # channels 12.5 and 12, a slope of the wrong sign 7.6 and 8.9
        err = delta_E_2000(unmixer.Lab(c_lin), unmixer.Lab(c_exact))
        assert np.median(err) < 1.0 and err.mean() < 4.0

    def test_the_binned_path_ages_like_the_exact_path(self, photo, unmixer, monkeypatch):
        """texel_concentrations itself: beyond the budget, each texel's key keeps its
        colour's concentrations (within the key bins' width)."""
        colours = np.unique(photo, axis=0)
        exact_key, exact_c = texels.texel_concentrations(photo, unmixer,
                                                         max_keys=colours.shape[0])
        monkeypatch.setattr(texels, "UNMIX_BUDGET", colours.shape[0] // 40)
        key, c = texels.texel_concentrations(photo, unmixer, max_keys=colours.shape[0] - 1)
        err = delta_E_2000(unmixer.Lab(c[key]), unmixer.Lab(exact_c[exact_key]))
        assert np.median(err) < 1.0 and err.mean() < 4.0
