"""Annual daylight: the sun's path, the sky map in Blender's frame, weather files, and
agreement with pvlib (NREL SPA, Ineichen, Perez 1990) where pvlib is installed."""

import dataclasses

import numpy as np
import pytest

from lightfade_addon.core.daylight import annual as dl
from lightfade_addon.core.daylight import skygrid, skymap, skysamples
from lightfade_addon.core.daylight.annual import PLACES, Place, annual_sky_map, plane_dose

WIDTH = 64  # coarse maps keep the tests quick; the physics does not depend on the width

UP, NORTH, SOUTH, EAST, WEST = ((0, 0, 1), (0, 1, 0), (0, -1, 0), (1, 0, 0), (-1, 0, 0))


@pytest.fixture(scope="module")
def london():
    return annual_sky_map(PLACES["London"], width=WIDTH)


@pytest.fixture(scope="module")
def london_samples():
    return skysamples.sky_samples(PLACES["London"], skymap.substeps_for(WIDTH))


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

    def test_sun_position_addon_north_offset(self):
        # Blender's Sun Position add-on: azimuth += north_offset; get_sun_vector gives
        # (sin θ sin A, sin θ cos A, cos θ) (sun_position/sun_calc.py)
        z, a, offset = 60.0, 130.0, np.radians(25.0)
        A, th = np.radians(a) + offset, np.radians(z)
        addon = (np.sin(th) * np.sin(A), np.sin(th) * np.cos(A), np.cos(th))
        north = skygrid.north_from_sun_position_addon(offset)
        assert north == pytest.approx(-25.0)
        np.testing.assert_allclose(skygrid.sun_direction_scene(z, a, north), addon, atol=1e-12)

    def test_bad_width(self):
        with pytest.raises(ValueError, match="multiple of 4"):
            annual_sky_map(PLACES["London"], width=50)


class TestAnnualSkyMap:
    def test_shape_dtype_finite_nonnegative(self, london):
        assert london.shape == (WIDTH // 2, WIDTH) and london.dtype == np.float32
        assert np.all(np.isfinite(london)) and london.min() >= 0

    def test_each_call_gets_its_own_array(self, london):
        again = annual_sky_map(PLACES["London"], width=WIDTH)
        np.testing.assert_array_equal(again, london)
        again[:] = 0                                   # the memoised map is not touched
        assert annual_sky_map(PLACES["London"], width=WIDTH).max() == london.max() > 0

    def test_an_edited_weather_file_is_read_again(self, pvlib_data, tmp_path):
        import os
        import shutil

        path = tmp_path / "w.tm2"
        shutil.copy(pvlib_data / "12839.tm2", path)
        place = Place.from_weather(path)
        first = plane_dose(annual_sky_map(place, width=16, sky="Perez1990"), UP)
        lines = path.read_text().splitlines(keepends=True)
        # halve every GHI/DNI/DHI (columns 17-33 hold them with their flags)
        halved = [ln if i == 0 else ln[:17] + "".join(
            f"{int(ln[a:a + 4]) // 2:04d}" + ln[a + 4:a + 6] for a in (17, 23, 29)) + ln[35:]
            for i, ln in enumerate(lines)]
        path.write_text("".join(halved))
        os.utime(path, ns=(1, 1))
        second = plane_dose(annual_sky_map(place, width=16, sky="Perez1990"), UP)
        assert 0.45 < second / first < 0.55

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
        whiter = annual_sky_map(dataclasses.replace(PLACES["London"], albedo=0.6), width=WIDTH,
                                sky="Perez1990")
        assert np.isclose(plane_dose(whiter, (0, 0, -1)), 0.6 * glob, rtol=1e-4)

    def test_horizontal_dose_equals_the_samples_global(self, london, london_samples):
        s = london_samples
        beam = s.K_direct * s.dni * np.cos(np.radians(s.zenith))
        expected = np.sum((beam + s.K_diffuse * s.dhi) * s.hours)
        # the sun pixel's cosine is its centre's: a small discretisation error
        assert np.isclose(plane_dose(london, UP), expected, rtol=0.005)

    def test_sun_pixels_hold_the_direct_normal_integral(self, london_samples):
        s = dataclasses.replace(london_samples, dhi=np.zeros_like(london_samples.dhi),
                                F1=np.zeros_like(london_samples.F1), F2=np.zeros_like(london_samples.F2))
        m = skymap.accumulate(s, WIDTH, 0.0, 0.2, False, photometric=False, sky_model="Perez1990")
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
        m = annual_sky_map(place, width=WIDTH, photometric=False, sky="Perez1990")
        normals = (UP, SOUTH, EAST, NORTH, (0, -1, 1))
        direct = dl.annual_irradiation(place, normals, substeps=skymap.substeps_for(WIDTH))
        assert direct.shape == (5,)
        assert np.isclose(direct[0], dl.annual_irradiation(place, UP, substeps=skymap.substeps_for(WIDTH)))
        for n, ref in zip(normals, direct):
            assert np.isclose(plane_dose(m, n), ref, rtol=0.02), n

    def test_luminous_efficacy_range(self, london):
        w = annual_sky_map(PLACES["London"], width=WIDTH, photometric=False)
        k = plane_dose(london, UP) / plane_dose(w, UP)
        assert 90 < k < 130


class TestPlace:
    def test_from_weather_takes_the_station(self, pvlib_data):
        place = Place.from_weather(pvlib_data / "12839.tm2", north=10.0)
        assert (place.latitude, place.altitude, place.north) == (25.8, 2.0, 10.0)
        assert place.longitude == pytest.approx(-80 - 16 / 60)
        assert place.weather.endswith("12839.tm2")

    def test_presets_and_validation(self):
        assert {"London", "Amsterdam/52N", "Madrid", "New York", "Sydney"} <= set(PLACES)
        assert PLACES["Sydney"].latitude < 0 < PLACES["London"].latitude
        with pytest.raises(ValueError, match="latitude"):
            Place(95.0, 0.0)
        with pytest.raises(ValueError, match="albedo"):
            Place(50.0, 0.0, albedo=1.5)


# ---- against pvlib (a test requirement of both stacks: requirements*.txt) -------------

@pytest.fixture(scope="module")
def pvlib():
    return pytest.importorskip("pvlib")


@pytest.fixture(scope="module")
def pvlib_data(pvlib):
    import pathlib

    return pathlib.Path(pvlib.__file__).parent / "data"


def _unit(zenith, azimuth):
    z, a = np.radians(zenith), np.radians(azimuth)
    return np.stack([np.sin(z) * np.sin(a), np.sin(z) * np.cos(a), np.cos(z)], -1)


class TestSunPosition:
    @pytest.mark.parametrize("lat, lon", [(51.5, -0.13), (-33.9, 151.2), (1.3, 103.8), (64.1, -21.9)])
    def test_within_a_hundredth_of_a_degree_of_spa(self, pvlib, lat, lon):
        import pandas as pd

        times = pd.date_range("2025-01-01", "2026-01-01", freq="173min", tz="UTC")
        ref = pvlib.solarposition.spa_python(times, lat, lon)
        z, a = dl.sun_position(Place(lat, lon), times.tz_convert(None).to_numpy())
        up = ref["apparent_zenith"].to_numpy() < 89.0
        cos = np.sum(_unit(z, a) * _unit(ref["apparent_zenith"].to_numpy(), ref["azimuth"].to_numpy()), -1)
        assert np.degrees(np.arccos(np.clip(cos[up], -1, 1))).max() < 0.01

    def test_noon_sun_is_south_in_the_north_and_north_in_the_south(self):
        t = np.array(["2025-06-21T12:00"], "datetime64[m]")
        z, a = dl.sun_position(PLACES["London"], t)
        assert abs(a[0] - 180) < 3 and abs(z[0] - (51.5 - 23.44)) < 0.5
        z, a = dl.sun_position(Place(-33.87, 0.0), t)
        assert (a[0] < 3 or a[0] > 357) and abs(z[0] - (33.87 + 23.44)) < 0.5


class TestClearSky:
    def test_ineichen_matches_pvlib(self, pvlib):
        from lightfade_addon.core.daylight.clearsky import clearsky_Ineichen2002

        z = np.linspace(0, 89.9, 200)
        tl = np.linspace(2, 6, 200)
        for alt in (0.0, 657.0, 2000.0):
            am = pvlib.atmosphere.get_absolute_airmass(pvlib.atmosphere.get_relative_airmass(z),
                                                       pvlib.atmosphere.alt2pres(alt))
            ref = pvlib.clearsky.ineichen(z, am, tl, altitude=alt, dni_extra=1400.0)
            ghi, dni, dhi = clearsky_Ineichen2002(z, tl, alt, 1400.0)
            for ours, key in ((ghi, "ghi"), (dni, "dni"), (dhi, "dhi")):
                np.testing.assert_allclose(ours, ref[key], rtol=1e-9, atol=1e-9)


class TestPerez:
    def test_sky_diffuse_on_planes_matches_pvlib(self, pvlib):
        from lightfade_addon.core.daylight import perez

        rng = np.random.default_rng(1)
        n = 500
        z = rng.uniform(0, 89, n)
        sa = rng.uniform(0, 360, n)
        dhi = rng.uniform(5, 400, n)
        dni = rng.uniform(0, 900, n)
        e0 = 1361.0
        am = pvlib.atmosphere.get_relative_airmass(z)
        eps = perez.sky_clearness(dni, dhi, z)
        F1, F2 = perez.perez_F1_F2(eps, perez.sky_brightness(dhi, am, e0), z)
        for tilt, az in ((0, 180), (90, 180), (90, 0), (35, 120)):
            ref = pvlib.irradiance.perez(tilt, az, dhi, dni, e0, z, sa, am)
            n_ = _unit(tilt, az)
            a = np.maximum(_unit(z, sa) @ n_, 0)
            ours = dhi * ((1 - F1) * (1 + np.cos(np.radians(tilt))) / 2
                          + F1 * a / np.maximum(np.cos(np.radians(z)), np.cos(np.radians(85)))
                          + F2 * np.sin(np.radians(tilt)))
            np.testing.assert_allclose(np.maximum(ours, 0), ref, rtol=1e-9, atol=1e-9)

    def test_efficacy_bounds(self):
        from lightfade_addon.core.daylight import perez

        # a clear high sun (ε bin 8) and an overcast sky (bin 1), W = 2 cm
        K_b, K_d = perez.luminous_efficacy(np.array([8.0, 1.02]), np.array([0.12, 0.3]),
                                           np.array([30.0, 30.0]))
        assert 90 < K_b[0] < 110 and 110 < K_d[0] < 160      # Perez 1990, fig. 6-7 ranges
        assert 100 < K_d[1] < 130
        with pytest.raises(ValueError, match="Perez1990"):
            perez.luminous_efficacy(8.0, 0.1, 30.0, method="constant")


class TestWeatherFiles:
    def test_tmy3_matches_pvlib_reader(self, pvlib, pvlib_data):
        from lightfade_addon.core.daylight.weather import read_weather

        path = pvlib_data / "723170TYA.CSV"
        ref, meta = pvlib.iotools.read_tmy3(path, coerce_year=2025, map_variables=True)
        wx = read_weather(path)
        assert (wx.latitude, wx.longitude, wx.altitude, wx.timezone) == (36.1, -79.95, 273.0, -5.0)
        assert len(wx.times) == 8760
        order = np.argsort(ref.index.tz_convert("UTC").tz_localize(None).to_numpy(), kind="stable")
        for ours, key in ((wx.ghi, "ghi"), (wx.dni, "dni"), (wx.dhi, "dhi"), (wx.dew_point, "temp_dew")):
            np.testing.assert_allclose(ours, ref[key].to_numpy(float)[order])
        # first record: 01/01 01:00 local standard time (UTC-5) = 06:00 UTC, the hour's end
        assert wx.times[0] == np.datetime64("2025-01-01T06:00:00")

    def test_tmy2_matches_pvlib_reader(self, pvlib, pvlib_data):
        from lightfade_addon.core.daylight.weather import read_weather

        path = pvlib_data / "12839.tm2"
        ref, meta = pvlib.iotools.read_tmy2(path)
        wx = read_weather(path)
        assert np.isclose(wx.latitude, meta["latitude"]) and np.isclose(wx.longitude, meta["longitude"])
        assert (wx.altitude, wx.timezone) == (meta["altitude"], meta["TZ"])
        for ours, key in ((wx.ghi, "GHI"), (wx.dni, "DNI"), (wx.dhi, "DHI")):
            assert np.isclose(ours.sum(), ref[key].sum())
        np.testing.assert_allclose(wx.dew_point[:48], ref["DewPoint"].to_numpy(float)[:48] / 10)
        # pvlib stamps the hour's start: ours is its end, in UTC
        start = ref.index[0].tz_convert("UTC").tz_localize(None).to_datetime64()
        assert str(wx.times[0])[5:16] == str(start + np.timedelta64(1, "h"))[5:16] == "01-01T06:00"

    def test_epw_matches_pvlib_reader(self, pvlib, pvlib_data, tmp_path):
        # pvlib ships no EPW: write the TMY3 file's first two days as one, read it both ways
        from lightfade_addon.core.daylight.weather import read_tmy3, read_weather

        src = read_tmy3(pvlib_data / "723170TYA.CSV")
        header = ["LOCATION,GREENSBORO,NC,USA,TMY3,723170,36.10,-79.95,-5.0,273.0",
                  "DESIGN CONDITIONS,0", "TYPICAL/EXTREME PERIODS,0", "GROUND TEMPERATURES,0",
                  "HOLIDAYS/DAYLIGHT SAVINGS,No,0,0,0", "COMMENTS 1,test", "COMMENTS 2,test",
                  "DATA PERIODS,1,1,Data,Sunday, 1/ 1,12/31"]
        rows = []
        for i in range(48):
            local = src.times[i] - np.timedelta64(5, "h")
            day = int(str(local)[8:10]) - (1 if str(local)[11:13] == "00" else 0)
            hour = int(str(local)[11:13]) or 24
            rows.append(f"1988,1,{day},{hour},60,?,10.0,{src.dew_point[i]:.1f},80,99000,0,0,300,"
                        f"{src.ghi[i]:.0f},{src.dni[i]:.0f},{src.dhi[i]:.0f},0,0,0,0,0,0,0,0,0,0,"
                        "9,999999999,0,0,0,0,0,0,0")          # 35 fields
        path = tmp_path / "greensboro.epw"
        path.write_text("\n".join(header + rows) + "\n")
        ref, meta = pvlib.iotools.read_epw(path)
        wx = read_weather(path)
        assert (wx.latitude, wx.longitude, wx.timezone, wx.altitude) == (36.1, -79.95, -5.0, 273.0)
        np.testing.assert_allclose(wx.ghi, ref["ghi"].to_numpy(float))
        np.testing.assert_allclose(wx.dni, src.dni[:48])
        assert wx.times[0] == np.datetime64("2025-01-01T06:00:00")

    def test_unknown_file_is_a_clear_error(self, tmp_path):
        from lightfade_addon.core.daylight.weather import WeatherFileError, read_weather

        p = tmp_path / "x.txt"
        p.write_text("hello")
        with pytest.raises(WeatherFileError, match="unknown weather file type"):
            read_weather(p)
        with pytest.raises(WeatherFileError, match="no such weather file"):
            read_weather(tmp_path / "missing.epw")


class TestAgainstPvlibAnnual:
    def test_tmy3_planes_within_five_percent(self, pvlib, pvlib_data):
        # the benchmark's check on one weather file, at a coarse map width
        import pandas as pd

        path = pvlib_data / "703165TY.csv"
        data, meta = pvlib.iotools.read_tmy3(path, coerce_year=2025, map_variables=True)
        times = data.index - pd.Timedelta("30min")
        sp = pvlib.solarposition.get_solarposition(times, meta["latitude"], meta["longitude"],
                                                   altitude=meta["altitude"])
        e0 = pvlib.irradiance.get_extra_radiation(times)
        place = Place(meta["latitude"], meta["longitude"], weather=str(path))
        m = annual_sky_map(place, width=WIDTH, photometric=False)
        ref = {}
        for name, tilt, az, n in (("H", 0, 180, UP), ("S", 90, 180, SOUTH), ("E", 90, 90, EAST),
                                  ("N", 90, 0, NORTH)):
            poa = pvlib.irradiance.get_total_irradiance(
                tilt, az, sp["apparent_zenith"].to_numpy(), sp["azimuth"].to_numpy(),
                data["dni"].to_numpy(float), data["ghi"].to_numpy(float), data["dhi"].to_numpy(float),
                dni_extra=e0.to_numpy(), albedo=0.2, model="perez")["poa_global"]
            ref[name] = (np.nansum(poa), plane_dose(m, n))
        assert np.isclose(ref["H"][1], ref["H"][0], rtol=0.05)
        for k in "SEN":
            assert np.isclose(ref[k][1] / ref["H"][1], ref[k][0] / ref["H"][0], rtol=0.05), k
        lux = plane_dose(annual_sky_map(place, width=WIDTH), UP)
        assert 90 < lux / ref["H"][0] < 130


@pytest.fixture(scope="module")
def few(london_samples):
    """Every 37th of London's samples (spread over the year)."""
    s = london_samples
    pick = np.arange(0, s.zenith.size, 37)
    arrays = {f.name: getattr(s, f.name)[pick] for f in dataclasses.fields(s)
              if isinstance(getattr(s, f.name), np.ndarray)}
    return dataclasses.replace(s, **arrays)


class TestPerez1993:
    """The all-weather distribution (``sky="Perez1993"``) on a subset of London's samples."""

    def test_normalised_to_the_diffuse_horizontal_dose(self, few):
        from lightfade_addon.core.daylight.allweather import diffuse_sky_Perez1993

        w = few.dhi * few.hours
        part = diffuse_sky_Perez1993(few, w, 32, 0.0)
        d, omega = skygrid.grid(32)
        assert np.isclose(np.sum(part * omega[8:] * d[8:, :, 2]), w.sum(), rtol=1e-6)   # float32 inside
        assert part.min() >= 0

    def test_a_sky_dark_everywhere_is_spread_isotropically(self, few):
        from lightfade_addon.core.daylight.allweather import diffuse_sky_Perez1993

        # an overcast, very bright sky with the sun on the horizon (a Greensboro TMY3 hour):
        # the model's luminance is negative over the whole sky
        one = dataclasses.replace(few, **{k: np.array([v]) for k, v in dict(
            epsilon=1.0, delta=0.7735, zenith=89.891, azimuth=250.0, dhi=29.0, dni=0.0,
            hours=1.0).items()})
        part = diffuse_sky_Perez1993(one, np.array([29.0]), 32, 0.0)
        d, omega = skygrid.grid(32)
        assert np.isclose(np.sum(part * omega[8:] * d[8:, :, 2]), 29.0)
        assert np.allclose(part, part[0, 0])

    def test_clear_sky_is_brightest_round_the_sun_and_overcast_at_the_zenith(self):
        from lightfade_addon.core.daylight.allweather import (
            perez1993_parameters,
            relative_luminance_Perez1993,
        )

        clear = perez1993_parameters(8.0, 0.15, 40.0)
        near_sun = relative_luminance_Perez1993(clear, np.cos(np.radians(45)), np.radians(5))
        away = relative_luminance_Perez1993(clear, np.cos(np.radians(45)), np.radians(90))
        assert near_sun > 5 * away
        overcast = perez1993_parameters(1.01, 0.3, 40.0)
        zenith = relative_luminance_Perez1993(overcast, 1.0, np.radians(40))
        horizon = relative_luminance_Perez1993(overcast, np.cos(np.radians(85)), np.radians(90))
        assert 1.5 < zenith / horizon < 4.5          # CIE overcast sky: 3 (Moon & Spencer)

    def test_planes_agree_with_the_1990_split_within_five_percent(self, few):
        a = skymap.accumulate(few, WIDTH, 0.0, 0.2, True, False, "Perez1990")
        b = skymap.accumulate(few, WIDTH, 0.0, 0.2, True, False, "Perez1993")
        assert np.isclose(plane_dose(b, UP), plane_dose(a, UP), rtol=0.01)
        for n in (SOUTH, EAST, NORTH):
            ra, rb = plane_dose(a, n) / plane_dose(a, UP), plane_dose(b, n) / plane_dose(b, UP)
            assert np.isclose(rb, ra, rtol=0.05), n
        # the difference is in the sky, not the sun: the 1993 sky has no point source
        assert (b[WIDTH // 4:] > 0).all()

    def test_unknown_sky_model(self):
        with pytest.raises(ValueError, match="sky model"):
            annual_sky_map(PLACES["London"], width=WIDTH, sky="CIE")
