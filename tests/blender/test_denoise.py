"""Denoising exposure maps: OIDN through the compositor, the guard, the mean kept."""

import numpy as np
import pytest

bpy = pytest.importorskip("bpy")


@pytest.fixture
def dn(blender):
    from lightfade_addon.blender.bake import denoise

    return denoise


def shadow_scene(n=192, seed=0):
    """Raw bake of a lit half (x < n/2, irradiance 1, 2 % noise) and a shadow half that
    only rare bright paths reach (mean 0.02: one texel in 25 carries 0.5)."""
    rng = np.random.default_rng(seed)
    truth = np.where(np.arange(n)[None, :] < n // 2, 1.0, 0.02) * np.ones((n, 1))
    raw = np.where(truth > 0.5, 1.0 + 0.02 * rng.standard_normal((n, n)),
                   0.5 * (rng.random((n, n)) < 0.04))
    return truth, raw


def test_preserve_mean_undoes_a_shadow_bias_and_keeps_the_edge(dn):
    truth, raw = shadow_scene()
    denoised = truth * np.where(truth < 0.5, 0.9, 1.0)        # OIDN's 10 % low in the shadow
    out = dn.preserve_mean(denoised, raw, np.ones(truth.shape, bool), radius=32)
    n = truth.shape[0]
    shadow, lit = out[:, n // 2 + 4:], out[:, :n // 2 - 4]
    assert abs(shadow.mean() / raw[:, n // 2 + 4:].mean() - 1) < 0.02   # the raw mean, kept
    assert abs(lit.mean() - 1) < 0.005
    # the edge stays a step: the texels either side keep their side's level
    assert np.all(out[:, n // 2 - 1] > 0.9) and np.all(out[:, n // 2] < 0.03)
    # a smooth factor: it adds little noise to the shadow
    assert shadow.std() / shadow.mean() < 0.1


def test_preserve_mean_is_smooth_across_its_brightness_bands(dn):
    """A texel belongs to the two bands around its brightness with hat weights, so a
    loss that changes with brightness is given back smoothly: a ramp over four stops,
    denoised 5-20 % low (more where darker), comes out a ramp again, each step within
    a few per cent of the input's (in one band only, a band's edge would jump by the
    two bands' different losses)."""
    n = 96
    den = np.broadcast_to(2.0 ** np.linspace(-4.0, 0.0, n)[None, :], (n, n)).copy()
    raw = den / (0.8 + 0.15 * (np.log2(den) + 4.0) / 4.0)      # 20 % low at the dark end
    out = dn.preserve_mean(den, raw, np.ones((n, n), bool), radius=48)
    steps = np.diff(np.log(out[n // 2]))
    input_step = np.log(2.0) * 4.0 / (n - 1)
    assert np.all(steps > 0) and np.max(np.abs(steps / input_step - 1.0)) < 0.25
    assert abs(out[n // 2].mean() / raw[n // 2].mean() - 1.0) < 0.05


def test_preserve_mean_leaves_an_unbiased_map_and_the_outside_alone(dn):
    truth, raw = shadow_scene(seed=1)
    inside = np.ones(truth.shape, bool)
    inside[:, -16:] = False                                    # beyond the UV islands
    denoised = truth.copy()
    denoised[:, -16:] = 7.0
    out = dn.preserve_mean(denoised, raw, inside, radius=32)
    n = truth.shape[0]
    assert abs(out[:, n // 2 + 4:-16].mean() / raw[:, n // 2 + 4:-16].mean() - 1) < 0.02
    assert np.all(out[:, -16:] == 7.0)
    assert np.all(dn.preserve_mean(np.zeros_like(truth), raw, inside) == 0)


def test_guard_darkens_a_contact_shadow_but_not_a_bounce_lit_one(dn):
    n = 64
    raw = np.ones((n, n, 3))
    raw[20:44, 20:44] = 0.0                                    # under a box: no path at all
    raw[:, 52:] = 0.0
    raw[::5, 52::5] = 0.3                                      # sparse bounce light
    bled = np.full((n, n, 3), 0.05)
    out = dn.guard(bled, raw)
    assert np.all(out[25:39, 25:39] == 0)                      # > 4 texels from light: dark
    assert np.all(out[:, 54:] == 0.05)                         # a path within 4 texels: kept


def test_oidn_smooths_noise_and_keeps_seams_between_islands(dn):
    rng = np.random.default_rng(3)
    n = 64
    labels = np.zeros((n, n), int)
    labels[:, n // 2:] = 1                                     # two islands side by side
    level = np.where(labels == 0, 1.0, 0.25)
    noisy = (level * rng.exponential(1.0, (n, n)))[..., None].repeat(3, -1).astype(np.float32)
    out = dn.denoise(noisy, dn.island_colours(labels))[..., 0]
    left, right = out[:, 4:n // 2 - 4], out[:, n // 2 + 4:-4]
    assert left.std() / left.mean() < 0.5 * noisy[:, 4:n // 2 - 4, 0].std()
    assert abs(left.mean() - 1.0) < 0.15 and abs(right.mean() - 0.25) < 0.05
    # bleed across the seam stays within the texel either side of it
    assert abs(out[:, n // 2 + 1].mean() / right.mean() - 1) < 0.15
    assert abs(out[:, n // 2 - 2].mean() / left.mean() - 1) < 0.15


@pytest.fixture
def f3(blender):
    from lightfade_addon.blender.bake import filter3d

    return filter3d


def flipped_halves(n=64, texel=0.01):
    """An n × n texel square of floor (z = 0, normal +z) cut into two islands: the left
    half of the map is x in [0, n/2) texels, the right half x in [n/2, n) mirrored, so
    that texels side by side in the atlas (columns n/2 - 1, n/2) are far apart on the
    floor, and the seam on the floor (x = n/2) joins the map's columns n/2 - 1 and n - 1."""
    half = n // 2
    col = np.arange(n)
    xs = np.where(col < half, col, half + (n - 1 - col))[None, :].repeat(n, 0) * texel
    ys = np.arange(n)[:, None].repeat(n, 1) * texel
    position = np.dstack([xs, ys, np.zeros((n, n))])
    normal = np.zeros((n, n, 3))
    normal[..., 2] = 1.0
    return position, normal, np.ones((n, n), bool), texel


def test_3d_filter_averages_across_a_seam_not_across_the_atlas(f3):
    rng = np.random.default_rng(5)
    position, normal, covered, texel = flipped_halves()
    n = covered.shape[0]
    level = np.where(position[..., 0] < 48 * texel, 1.0, 0.25)    # 1 up to x = 48 texels
    raw = level * rng.exponential(1.0, level.shape)           # noisy, mean = level
    flat = np.ones_like(level)                                # a guide without edges
    out = f3.smooth_on_surface(raw, flat, position, normal, covered, texel)
    # atlas neighbours (x = 31 | x = 63 texels) do not mix, the seam (x = 31 | 32) does
    assert abs(out[:, n // 2 - 2:n // 2].mean() - 1.0) < 0.1
    assert abs(out[:, n // 2:n // 2 + 2].mean() - 0.25) < 0.03
    # the noise drops ~5× (≈28 texels averaged), as much along the seam, where half of
    # a texel's 3D neighbours lie in the other island, as inside
    out = f3.smooth_on_surface(flat * rng.exponential(1.0, level.shape), flat, position,
                               normal, covered, texel)
    assert out[4:-4, 4:n // 2 - 4].std() < 0.25 and abs(out.mean() - 1) < 0.05
    assert out[4:-4, -1].std() < 0.25 and out[4:-4, n // 2 - 1].std() < 0.25


def test_3d_filter_keeps_the_edges_the_denoiser_saw_and_the_other_side(f3):
    rng = np.random.default_rng(6)
    position, normal, covered, texel = flipped_halves()
    n = covered.shape[0]
    lit = position[..., 1] < 32 * texel                       # a shadow edge along y
    truth = np.where(lit, 1.0, 0.05)
    raw = truth * rng.exponential(1.0, truth.shape)
    out = f3.smooth_on_surface(raw, truth, position, normal, covered, texel)
    # either side of the edge keeps its side's raw mean (no bleed: 20× apart)
    assert abs(out[32:34].mean() / raw[32:38].mean() - 1) < 0.1
    assert abs(out[29:32].mean() / raw[26:32].mean() - 1) < 0.05
    # the back of a sheet 1 mm below, facing down, in the dark: it stays dark
    back = position.copy()
    back[..., 2] -= 0.001
    both_p = np.concatenate([position, back], axis=1)
    both_n = np.concatenate([normal, -normal], axis=1)
    both_raw = np.concatenate([np.ones_like(truth), np.zeros_like(truth)], axis=1)
    out = f3.smooth_on_surface(both_raw, both_raw + 1e-3, both_p, both_n,
                               np.ones(both_raw.shape, bool), texel)
    assert np.all(out[:, n:] == 0) and np.allclose(out[:, :n], 1.0)


def test_3d_filter_of_a_stack_is_each_map_filtered_alone(f3):
    """An object's maps (one per light group) share one neighbour search: the stack's
    result is each map's own, with its own range weights (a shadow edge in one map does
    not cut the other)."""
    rng = np.random.default_rng(7)
    position, normal, covered, texel = flipped_halves()
    lit = position[..., 1] < 32 * texel
    guides = np.stack([np.where(lit, 1.0, 0.05), np.ones(lit.shape)])
    raws = guides * rng.exponential(1.0, guides.shape)
    both = f3.smooth_on_surface(raws, guides, position, normal, covered, texel)
    for j in range(2):
        alone = f3.smooth_on_surface(raws[j], guides[j], position, normal, covered, texel)
        np.testing.assert_allclose(both[j], alone, rtol=1e-5, atol=1e-7)
    assert not np.allclose(both[0], both[1], rtol=0.1)


def test_3d_filter_weighs_neighbours_by_the_epanechnikov_kernel_of_their_distance(f3):
    """One bright texel on a flat floor: each texel within the radius (3 texels) takes
    ``K(d / r) / Σ K`` of it, ``K(x) = 1 - x²``; from 3 texels on, nothing."""
    position, normal, covered, texel = flipped_halves()
    raw = np.zeros(covered.shape)
    raw[20, 10] = 1.0
    out = f3.smooth_on_surface(raw, np.ones_like(raw), position, normal, covered, texel)
    offsets = [(dy, dx) for dy in range(-3, 4) for dx in range(-3, 4)]

    def kernel(dy, dx):
        return max(1.0 - (dy * dy + dx * dx) / 9.0, 0.0)

    total = sum(kernel(dy, dx) for dy, dx in offsets)     # every texel's disc is whole
    for dy, dx in [(0, 0), (0, 1), (1, 1), (2, 0), (2, 2), (0, 3), (3, 1)]:
        assert out[20 + dy, 10 + dx] == pytest.approx(kernel(dy, dx) / total, rel=1e-4,
                                                      abs=1e-7)


def test_3d_filter_mixes_the_dark_texels_of_one_shadow(f3):
    """Guide values under 1e-3 of its 99th percentile count as that: a shadow's texels
    at 1e-5 and 1e-6 of the light are alike and average together (a range weight on
    their own 3.3 stops would keep them apart)."""
    position, normal, covered, texel = flipped_halves()
    guide = np.full(covered.shape, 1e-5)
    guide[:, 16:32] = 1e-6
    guide[:8] = 1.0                                        # the lit part, far away
    out = f3.smooth_on_surface(guide, guide, position, normal, covered, texel)
    assert out[30, 15] < 0.8e-5 and out[30, 16] > 2e-6


def test_the_margin_takes_the_nearest_covered_texel(f3):
    covered = np.zeros((8, 8), bool)
    covered[2:6, 2:6] = True
    inside = np.zeros((8, 8), bool)
    inside[1:7, 1:7] = True
    values = np.arange(64, dtype=float).reshape(8, 8)
    out = f3.extend_over_margin(values, covered, inside)
    assert out[1, 3] == values[2, 3] and out[4, 6] == values[4, 5]
    assert out[1, 1] == values[2, 2] and out[0, 0] == values[0, 0]   # outside: as it was
    np.testing.assert_array_equal(out[covered], values[covered])


def test_preserve_mean_gives_back_rare_bright_paths_the_denoiser_took_for_outliers(dn):
    """Light through frosted glass: a few texels carry all of it and the denoiser keeps
    a third; the window's raw sum is three times its denoised one, and all of it comes
    back (a clip of the factor at 2 lost a third of the light)."""
    rng = np.random.default_rng(4)
    n = 128
    raw = 0.5 * (rng.random((n, n)) < 0.04)                   # mean 0.02
    denoised = np.full((n, n), 0.02 / 3.0)
    out = dn.preserve_mean(denoised, raw, np.ones((n, n), bool), radius=32)
    assert out.mean() == pytest.approx(raw.mean(), rel=0.01)


def test_preserve_mean_keeps_each_objects_mean_in_a_shared_map(dn):
    """Two objects side by side in one atlas at the same brightness, the denoiser 20 %
    low on one of them: corrected cell by cell, each gets its own raw mean back (one
    window across both gave each the pair's mean: -10 % and +10 %)."""
    rng = np.random.default_rng(6)
    n = 96
    raw = 1.0 + 0.05 * rng.standard_normal((n, 2 * n))
    denoised = np.ones((n, 2 * n))
    denoised[:, :n] = 0.8
    cells = [(slice(0, n), slice(0, n)), (slice(0, n), slice(n, 2 * n))]
    out = dn.preserve_mean(denoised, raw, np.ones(raw.shape, bool), parts=cells)
    for cell in cells:
        assert out[cell].mean() == pytest.approx(raw[cell].mean(), rel=0.005)


def test_the_bake_keeps_each_atlas_objects_mean_on_its_own(blender, monkeypatch):
    """Passes.add corrects an atlas cell by cell (its regions)."""
    from types import SimpleNamespace

    from lightfade_addon.blender.bake import BakeSettings, passes

    n = 96
    rng = np.random.default_rng(8)
    rgb = np.ones((2 * n, 2 * n, 4), np.float32)
    rgb[..., :3] = (1.0 + 0.05 * rng.standard_normal((2 * n, 2 * n)))[..., None]

    def lossy(rgb_in, guide=None):                             # 20 % low on the left cell
        out = np.array(rgb_in, np.float32)
        out[:, :n] *= 0.8
        return out

    monkeypatch.setattr(passes._denoise, "denoise", lossy)
    cells = {"A": (slice(0, 2 * n), slice(0, n)), "B": (slice(0, 2 * n), slice(n, 2 * n))}
    geo = SimpleNamespace(island=np.zeros((2 * n, 2 * n), int))
    image = SimpleNamespace(size=(2 * n, 2 * n), pixels=SimpleNamespace(
        foreach_get=lambda out: out.__setitem__(slice(None), rgb.ravel())))
    p = passes.Passes(BakeSettings(denoise=True), {"atlas": geo}, {"atlas": cells})
    p.add("atlas", "Sun", 8, image)
    (_, _, y), = p.pending["atlas"]
    for cell in cells.values():
        assert y[cell].mean() == pytest.approx(rgb[..., 0][cell].mean(), rel=0.005)


def test_preserve_mean_raises_a_band_the_denoiser_emptied_at_most_fourfold(dn):
    """A window whose denoised sum is a sliver of its raw one (the denoiser took nearly all
    of a shadow's rare paths away) is raised at most MEAN_GAIN times: unbounded, a few dim
    texels carried a whole window's light (bpy 4.2: a chair under a table read brighter
    than one in the sun)."""
    rng = np.random.default_rng(8)
    n = 96
    raw = 0.5 * (rng.random((n, n)) < 0.02)                    # mean 0.01
    denoised = np.full((n, n), 0.0002)                         # 50x below it
    out = dn.preserve_mean(denoised, raw, np.ones((n, n), bool), radius=32)
    assert out.max() <= 4.0 * 0.0002 * (1 + 1e-5)
    assert out.mean() == pytest.approx(4.0 * 0.0002, rel=1e-4)
