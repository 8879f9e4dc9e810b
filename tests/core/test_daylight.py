"""Annual daylight: the sun's path, the sky map in Blender's frame, weather files, and
agreement with pvlib (NREL SPA, Ineichen, Perez 1990) where pvlib is installed."""

import dataclasses

import numpy as np
import pytest

from lightfade_addon.core import daylight as dl
from lightfade_addon.core import skygrid, skysamples
from lightfade_addon.core.daylight import PLACES, Place, annual_sky_map, plane_dose

WIDTH = 64  # coarse maps keep the tests quick; the physics does not depend on the width

UP, NORTH, SOUTH, EAST, WEST = ((0, 0, 1), (0, 1, 0), (0, -1, 0), (1, 0, 0), (-1, 0, 0))


@pytest.fixture(scope="module")
def london():
    return annual_sky_map(PLACES["London"], width=WIDTH)


@pytest.fixture(scope="module")
def london_samples():
    return skysamples.sky_samples(PLACES["London"], dl._substeps_for(WIDTH))


class TestSkyGrid:
    def test_cycles_equirectangular_convention(self):
        # Cycles: u = 0.5 - atan2(y, x) / 2π, v = 1 - acos(z) / π; row 0 = v near 0 (nadir)
        W, H = 64, 32
        cases = {(-1, 0, 0.01): (H // 2, 0), (0, 1, 0.01): (H // 2, W // 4),
                 (1, 0, 0.01): (H // 2, W // 2), (0, -1, 0.01): (H // 2, 3 * W // 4),
                 (0, 0, 1): (H - 1, None), (0, 0, -1): (0, None)}
        for d, (row, col) in cases.items():
            i = skygrid.direction_to_pixel(np.array(d), W)
            assert i // W == row, d
            if col is not None:
                assert i % W == col, d

    def test_pixel_centres_map_to_themselves_and_solid_angles_sum_to_4pi(self):
        d, omega = skygrid.grid(32)
        idx = skygrid.direction_to_pixel(d, 32)
        np.testing.assert_array_equal(idx.ravel(), np.arange(16 * 32))
        assert np.isclose((omega * np.ones((1, 32))).sum(), 4 * np.pi)

    def test_north_rotation_is_counterclockwise_about_z(self):
        # north = 90: -X is north, so east (north turned clockwise) is +Y
        E, N, U = skygrid.scene_axes(90.0)
        np.testing.assert_allclose(N, (-1, 0, 0), atol=1e-12)
        np.testing.assert_allclose(E, (0, 1, 0), atol=1e-12)
        np.testing.assert_allclose(skygrid.sun_direction_scene(90.0, 90.0), (1, 0, 0), atol=1e-12)
        np.testing.assert_allclose(skygrid.sun_direction_scene(90.0, 180.0, north=30.0),
                                   (np.sin(np.radians(30)), -np.cos(np.radians(30)), 0),
                                   atol=1e-12)

    def test_bad_width(self):
        with pytest.raises(ValueError, match="multiple of 4"):
            annual_sky_map(PLACES["London"], width=50)


class TestAnnualSkyMap:
    def test_shape_dtype_finite_nonnegative(self, london):
        assert london.shape == (WIDTH // 2, WIDTH) and london.dtype == np.float32
        assert np.all(np.isfinite(london)) and london.min() >= 0

    def test_south_wall_beats_north_wall_in_the_north(self, london):
        assert plane_dose(london, SOUTH) > 2.5 * plane_dose(london, NORTH)

    def test_latitude_sign_flips_north_and_south(self):
        sydney = annual_sky_map(PLACES["Sydney"], width=WIDTH)
        assert plane_dose(sydney, NORTH) > 2.0 * plane_dose(sydney, SOUTH)

    def test_east_and_west_are_mirror_images(self, london):
        e, w = plane_dose(london, EAST), plane_dose(london, WEST)
        assert abs(e - w) < 0.01 * e
        assert plane_dose(london, SOUTH) > e > plane_dose(london, NORTH)

    def test_north_angle_rotates_the_map(self, london):
        # north = 90: geographic south is +X in the scene
        rotated = annual_sky_map(dataclasses.replace(PLACES["London"], north=90.0), width=WIDTH)
        assert np.isclose(plane_dose(rotated, EAST), plane_dose(london, SOUTH), rtol=0.02)
        assert np.isclose(plane_dose(rotated, WEST), plane_dose(london, NORTH), rtol=0.02)
        assert plane_dose(rotated, (0, -1, 0)) < plane_dose(rotated, EAST)

    def test_the_brightest_pixel_is_on_the_noon_side(self, london):
        # London's sun culminates due south (-Y when north = 0): columns near 3W/4
        row, col = np.unravel_index(np.argmax(london), london.shape)
        assert row >= WIDTH // 4          # above the horizon
        assert abs(col - 3 * WIDTH // 4) <= WIDTH // 8

    def test_ground_half_and_albedo(self, london, london_samples):
        H = WIDTH // 2
        no_ground = annual_sky_map(PLACES["London"], width=WIDTH, ground=False)
        assert np.all(no_ground[: H // 2] == 0)
        np.testing.assert_allclose(no_ground[H // 2:], london[H // 2:])
        s = london_samples
        glob = np.sum((s.K_direct * s.dni * np.cos(np.radians(s.zenith)) + s.K_diffuse * s.dhi) * s.hours)
        assert np.isclose(plane_dose(london, (0, 0, -1)), 0.2 * glob, rtol=1e-4)
        whiter = annual_sky_map(dataclasses.replace(PLACES["London"], albedo=0.6), width=WIDTH)
        assert np.isclose(plane_dose(whiter, (0, 0, -1)), 0.6 * glob, rtol=1e-4)

    def test_horizontal_dose_equals_the_samples_global(self, london, london_samples):
        s = london_samples
        beam = s.K_direct * s.dni * np.cos(np.radians(s.zenith))
        F = np.maximum(np.cos(np.radians(s.zenith)), np.cos(np.radians(85)))
        expected = np.sum((beam + s.K_diffuse * s.dhi * (1 - s.F1 + s.F1 * np.cos(np.radians(s.zenith)) / F)) * s.hours)
        # the circumsolar pixel's cosine is its centre's: a small discretisation error
        assert np.isclose(plane_dose(london, UP), expected, rtol=0.01)

    def test_sun_pixels_hold_the_direct_normal_integral(self, london_samples):
        s = dataclasses.replace(london_samples, dhi=np.zeros_like(london_samples.dhi),
                                F1=np.zeros_like(london_samples.F1), F2=np.zeros_like(london_samples.F2))
        m = dl._accumulate(s, WIDTH, 0.0, 0.2, False, photometric=False)
        _, omega = skygrid.grid(WIDTH)
        assert np.isclose((m * omega).sum(), np.sum(s.dni * s.hours), rtol=1e-5)
        # and only along the sun's path: nothing below the horizon, nothing above London's
        # highest noon sun (90 - 51.5 + 23.44 = 62°)
        H = WIDTH // 2
        bottom = -90.0 + 180.0 * np.arange(H) / H        # each row's lower edge, degrees
        assert (m[bottom < 0] == 0).all()
        assert (m[bottom > 62.5] == 0).all() and m[(bottom > 55) & (bottom < 62.5)].max() > 0

    def test_map_integral_matches_direct_model_on_planes(self):
        place = PLACES["Madrid"]
        m = annual_sky_map(place, width=128, photometric=False)
        for n in (UP, SOUTH, EAST, NORTH, (0, -1, 1)):
            assert np.isclose(plane_dose(m, n), dl.annual_irradiation(place, n), rtol=0.02), n

    def test_luminous_efficacy_range(self, london):
        w = annual_sky_map(PLACES["London"], width=WIDTH, photometric=False)
        k = plane_dose(london, UP) / plane_dose(w, UP)
        assert 90 < k < 130


class TestPlace:
    def test_presets_and_validation(self):
        assert {"London", "Amsterdam/52N", "Madrid", "New York", "Sydney"} <= set(PLACES)
        assert PLACES["Sydney"].latitude < 0 < PLACES["London"].latitude
        with pytest.raises(ValueError, match="latitude"):
            Place(95.0, 0.0)
        with pytest.raises(ValueError, match="albedo"):
            Place(50.0, 0.0, albedo=1.5)
