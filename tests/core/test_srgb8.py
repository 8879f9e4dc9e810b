"""8-bit sRGB codes through a table (core/colour/srgb8.py) against the formula."""

import numpy as np

from lightfade_addon.core.colour import srgb8


def _around_thresholds():
    """Every float32 within 3 ulps of each code threshold, and 0, 1."""
    t = srgb8._thresholds()[1:-1]
    bits = t.view(np.int32)[:, None] + np.arange(-3, 4, dtype=np.int32)
    return np.concatenate([bits.ravel().view(np.float32), np.float32([0.0, 1.0])])


def test_codes_are_the_formula_at_every_threshold_and_at_random():
    rng = np.random.default_rng(1)
    x = np.concatenate([_around_thresholds(), rng.uniform(0, 1, 200_000).astype(np.float32),
                        rng.uniform(0, 0.004, 50_000).astype(np.float32)])
    want = srgb8.formula_codes(x)
    assert np.array_equal(srgb8.srgb_codes(x), want)
    floats = srgb8.srgb_code_floats(x)
    # what Blender stores for them: floor(255 f + 0.5)
    assert np.array_equal(np.floor(np.float32(255) * floats + np.float32(0.5)), want)


def test_out_of_range_values_clip_and_in_place_works():
    x = np.float32([[-0.5, 0.0, 2.0], [1.0, 0.5, 1e-4]])
    want = srgb8.formula_codes(x) / np.float32(255.0)
    got = srgb8.srgb_code_floats(x, out=x)
    assert got is x
    np.testing.assert_array_equal(x, want.astype(np.float32))
    assert x[0, 0] == 0.0 and x[0, 2] == 1.0
