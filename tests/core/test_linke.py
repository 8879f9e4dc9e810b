"""The worldwide monthly Linke turbidity climatology bundled with the extension
(``core/data/linke_turbidity.npz``, ``core/clearsky.linke_turbidity``): its file, its
interpolation, and agreement with pvlib's own lookup and Perez wall doses."""

import numpy as np
import pytest

from lightfade_addon.core.daylight import clearsky
from lightfade_addon.core.daylight.clearsky import CLIMATOLOGY_FILE, linke_turbidity
from lightfade_addon.core.daylight.annual import Place, annual_sky_map, plane_dose

MONTHS = np.arange(1, 13)
#: Away from every preset: Berlin, Denver (1609 m), Sydney (southern hemisphere).
CITIES = {"Berlin": (52.52, 13.405), "Denver": (39.7392, -104.9903),
          "Sydney": (-33.8688, 151.2093)}


@pytest.fixture(scope="module")
def pvlib():
    return pytest.importorskip("pvlib")


def _cell(i, j, step=1.0):
    """Latitude, longitude of the centre of cell (row i, column j)."""
    return 90.0 - (i + 0.5) * step, -180.0 + (j + 0.5) * step


class TestFile:
    def test_compact_uint8_with_source_and_licence(self):
        assert CLIMATOLOGY_FILE.stat().st_size < 400_000
        with np.load(CLIMATOLOGY_FILE) as data:
            assert data["tl20"].dtype == np.uint8
            assert data["tl20"].shape == (12, 180, 360)
            assert float(data["step_deg"]) == 1.0
            assert "LinkeTurbidities.h5" in str(data["source"]) and "Remund" in str(data["source"])
            assert "BSD" in str(data["licence"])

    def test_cells_are_block_means_of_pvlibs_grid(self, pvlib):
        h5py = pytest.importorskip("h5py")
        import pathlib

        path = pathlib.Path(pvlib.__file__).parent / "data" / "LinkeTurbidities.h5"
        with h5py.File(path, "r") as f:
            block = f["LinkeTurbidity"][37 * 12:38 * 12, 193 * 12:194 * 12, :]  # 52.5° N, 13.5° E
        expected = np.rint(block.astype(float).mean(axis=(0, 1))) / 20.0
        np.testing.assert_allclose(linke_turbidity(*_cell(37, 193), MONTHS), expected, atol=1e-12)


class TestInterpolation:
    def test_cell_centres_and_midpoints(self):
        tl, _ = clearsky._climatology()
        np.testing.assert_allclose(linke_turbidity(*_cell(40, 100), MONTHS), tl[:, 40, 100])
        lat, lon = _cell(40, 100)
        np.testing.assert_allclose(linke_turbidity(lat, lon + 0.5, MONTHS),
                                   (tl[:, 40, 100] + tl[:, 40, 101]) / 2)
        np.testing.assert_allclose(linke_turbidity(lat - 0.25, lon, MONTHS),
                                   0.75 * tl[:, 40, 100] + 0.25 * tl[:, 41, 100])

    def test_longitude_wraps_and_poles_hold(self):
        for month in (1, 7):
            assert linke_turbidity(10.0, 180.0, month) == linke_turbidity(10.0, -180.0, month)
            assert linke_turbidity(10.0, 190.0, month) == linke_turbidity(10.0, -170.0, month)
        tl, _ = clearsky._climatology()
        np.testing.assert_allclose(linke_turbidity(90.0, *_cell(0, 7)[1:], MONTHS), tl[:, 0, 7])
        np.testing.assert_allclose(linke_turbidity(-90.0, *_cell(0, 7)[1:], MONTHS), tl[:, -1, 7])

    def test_month_shape_broadcasts(self):
        months = np.array([[1, 2, 3], [10, 11, 12]])
        out = linke_turbidity(52.52, 13.405, months)
        assert out.shape == (2, 3)
        np.testing.assert_allclose(out.ravel(), linke_turbidity(52.52, 13.405, months.ravel()))


class TestAgainstPvlib:
    @pytest.mark.parametrize("city", CITIES)
    def test_monthly_values_near_pvlibs_lookup(self, pvlib, city):
        import pandas as pd

        lat, lon = CITIES[city]
        times = pd.date_range("2025-01-15", periods=12, freq=pd.DateOffset(months=1))
        ref = pvlib.clearsky.lookup_linke_turbidity(times, lat, lon, interp_turbidity=False)
        ours = linke_turbidity(lat, lon, MONTHS)
        assert abs(ours.mean() - ref.mean()) < 0.1          # the year
        assert np.abs(ours - ref.to_numpy()).max() < 0.5     # every month
        assert np.corrcoef(ours, ref.to_numpy())[0, 1] > 0.8  # the seasons

    @pytest.mark.parametrize("city", ["Berlin", "Denver"])
    def test_wall_to_horizontal_lux_within_five_percent(self, pvlib, city):
        """Annual clear-sky lux on walls over the horizontal against pvlib's Perez (each
        component in lux by the Perez 1990 efficacies).  With T_L 3.5 everywhere (before
        the climatology) Berlin's south wall was 6.6 % low."""
        from benchmarks.daylight import PLANES, pvlib_lux

        place = Place(*CITIES[city], altitude={"Berlin": 34.0, "Denver": 1609.0}[city])
        ref, _ = pvlib_lux(place)
        lx = annual_sky_map(place, width=64)
        ours = {n: plane_dose(lx, v) for n, (v, _, _) in PLANES.items()}
        for wall in "SEWN":
            ratio = (ours[wall] / ours["horizontal"]) / (ref[wall] / ref["horizontal"])
            assert abs(ratio - 1.0) < 0.05, (wall, ratio)
