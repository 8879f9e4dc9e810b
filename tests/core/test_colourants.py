"""Tests for lightfade_addon.core.fading.colourants: data format, loaders, bundled data."""

import numpy as np
import pytest

from lightfade_addon.core.colour.colorimetry import delta_E_ab, reflectance_to_Lab
from lightfade_addon.core.fading.colourants import (
    FORMAT_LINE,
    Colourant,
    Substrate,
    available,
    load_colourant,
    load_substrate,
    save_colourant,
    save_substrate,
)
from lightfade_addon.core.fading.kubelka import kubelka_layer, over_ground
from lightfade_addon.core.fading.spectra import WAVELENGTHS

COLOURANTS = ["cyan", "extractive", "lignin", "magenta", "quinone", "yellow"]
SUBSTRATES = ["fabric", "paper", "white-ground", "wood"]

#: ISO 12647-2 coated-paper primaries (CIELAB D50) and the Delta E*ab documented in
#: docs/data.md: <= 0.1 on the bundled 5 nm grid, <= 1.0 on the default 12 nm grid.
TARGETS = {"cyan": (55.0, -37.0, -50.0), "magenta": (48.0, 74.0, -3.0),
           "yellow": (89.0, -5.0, 93.0)}


def write(tmp_path, text, name="custom.txt"):
    path = tmp_path / name
    path.write_text(text)
    return path


GOOD = """# LightFade colourant data v1
name: test-dye
kind: colourant
description: a test
provenance: made up for a test,
  continued here
columns: wavelength_nm K S
400 1.0 0.1
500 2.0 0.1
600 0.5 0.2
700 0.0 0.2
"""


class TestAvailable:
    def test_bundled_names(self):
        assert available() == sorted(COLOURANTS + SUBSTRATES)
        assert available("colourant") == COLOURANTS
        assert available("substrate") == SUBSTRATES


class TestBundledData:
    @pytest.mark.parametrize("name", COLOURANTS)
    def test_colourant(self, name):
        c = load_colourant(name)
        assert isinstance(c, Colourant) and c.name == name
        assert c.K.shape == c.S.shape == WAVELENGTHS.shape
        assert np.all(c.K >= 0) and np.all(c.S >= 0)
        assert "parametric" in c.provenance and "not measured" in c.provenance
        assert c.description

    @pytest.mark.parametrize("name", SUBSTRATES)
    def test_substrate(self, name):
        s = load_substrate(name)
        assert isinstance(s, Substrate) and s.reflectance.shape == WAVELENGTHS.shape
        assert np.all((s.reflectance >= 0) & (s.reflectance <= 1))
        assert "parametric" in s.provenance and "not measured" in s.provenance

    @pytest.mark.parametrize("name, peak", [("cyan", 620), ("magenta", 550), ("yellow", 430)])
    def test_dye_absorption_maximum(self, name, peak):
        c = load_colourant(name, wavelengths=None)
        visible = c.wavelengths >= 400
        assert abs(c.wavelengths[visible][np.argmax(c.K[visible])] - peak) <= 20
        assert np.all((c.S > 0) & (c.S <= 0.05))  # dissolved dyes barely scatter

    def test_dyes_absorb_uv(self):
        for name in ("cyan", "magenta", "yellow"):
            c = load_colourant(name, wavelengths=None)
            assert c.K[c.wavelengths <= 380].max() > 0.1

    def test_lignin_absorbs_uv_not_visible(self):
        c = load_colourant("lignin", wavelengths=None)
        assert c.K[c.wavelengths == 300][0] > 10.0
        assert c.K[c.wavelengths >= 450].max() < 0.01

    def test_quinone_absorbs_blue(self):
        c = load_colourant("quinone", wavelengths=None)
        visible = c.wavelengths >= 380
        assert 400 <= c.wavelengths[visible][np.argmax(c.K[visible])] <= 500
        # a brown-red tail (sunlit pale wood reddens), far below the blue band
        assert c.K[c.wavelengths >= 650].max() < 0.2 * c.K[visible].max()

    def test_wood(self):
        s = load_substrate("wood", wavelengths=None)
        R = dict(zip(s.wavelengths, s.reflectance))
        assert R[400.0] == pytest.approx(0.25, abs=0.03)
        assert R[700.0] == pytest.approx(0.65, abs=0.03)

    def test_paper_drops_in_uv(self):
        s = load_substrate("paper", wavelengths=None)
        assert s.reflectance[s.wavelengths >= 450].min() > 0.85
        assert s.reflectance[0] < 0.5

    @pytest.mark.parametrize("grid, tol", [(None, 0.1), (WAVELENGTHS, 1.0)])
    @pytest.mark.parametrize("name", list(TARGETS))
    def test_solid_on_paper_hits_iso_primary(self, name, grid, tol):
        c = load_colourant(name, grid)
        paper = load_substrate("paper", grid)
        R = over_ground(*kubelka_layer(c.K, c.S, 1.0), paper.reflectance)
        lab = reflectance_to_Lab(R, c.wavelengths, "D50")
        assert delta_E_ab(lab, TARGETS[name]) <= tol


class TestLoad:
    def test_custom_file_native_grid(self, tmp_path):
        c = load_colourant(write(tmp_path, GOOD), wavelengths=None)
        np.testing.assert_array_equal(c.wavelengths, [400, 500, 600, 700])
        np.testing.assert_array_equal(c.K, [1.0, 2.0, 0.5, 0.0])
        assert c.provenance == "made up for a test, continued here"

    def test_edge_hold_outside_range(self, tmp_path):
        c = load_colourant(write(tmp_path, GOOD))
        assert c.K[0] == pytest.approx(1.0) and c.K[-1] == pytest.approx(0.0)
        assert c.S[0] == pytest.approx(0.1) and c.S[-1] == pytest.approx(0.2)

    @pytest.mark.parametrize("name", ["cyan", "magenta", "yellow", "lignin"])
    def test_resampling_keeps_the_band_area(self, name):
        """Band-averaging onto a coarser or the same grid keeps each absorption band's
        area (what the fading integral sees) and its peak position."""
        from scipy.integrate import trapezoid

        native = load_colourant(name, None)
        coarse = load_colourant(name, np.linspace(300.0, 780.0, 25))
        again = load_colourant(name, native.wavelengths)
        area = trapezoid(native.K, native.wavelengths)
        assert trapezoid(coarse.K, coarse.wavelengths) == pytest.approx(area, rel=0.03)
        assert trapezoid(again.K, again.wavelengths) == pytest.approx(area, rel=0.01)
        peak = native.wavelengths[np.argmax(native.K)]
        assert abs(coarse.wavelengths[np.argmax(coarse.K)] - peak) <= 20

    def test_arrays_are_read_only(self):
        with pytest.raises(ValueError):
            load_colourant("cyan").K[0] = 0.0

    def test_unknown_name_lists_bundled(self):
        with pytest.raises(ValueError, match="cyan.*magenta"):
            load_colourant("vermilion")

    def test_wrong_kind(self):
        with pytest.raises(ValueError, match="is a substrate, not a colourant"):
            load_colourant("paper")
        with pytest.raises(ValueError, match="is a colourant, not a substrate"):
            load_substrate("cyan")

    @pytest.mark.parametrize("bad, message", [
        (GOOD.replace("500 2.0 0.1", "500 2.0 abc"), r"custom.txt:9: expected numbers"),
        (GOOD.replace("500 2.0 0.1", "500 -2.0 0.1"), r"custom.txt:9: K and S must be >= 0"),
        (GOOD.replace("600 0.5 0.2", "450 0.5 0.2"), r"custom.txt:10: .*strictly increasing"),
        (GOOD.replace("600 0.5 0.2", "600 0.5"), r"custom.txt:10: expected 3 numbers, got 2"),
        (GOOD.replace("600 0.5 0.2", "600 nan 0.2"), r"custom.txt:10: .*finite"),
        (GOOD.replace("columns: wavelength_nm K S\n", ""), r"missing header line 'columns"),
        (GOOD.replace("kind: colourant", "kind: pigment"), r"kind must be"),
        (GOOD.replace("wavelength_nm K S", "wavelength_nm S K"), r"needs 'columns"),
    ])
    def test_malformed(self, tmp_path, bad, message):
        with pytest.raises(ValueError, match=message):
            load_colourant(write(tmp_path, bad))

    def test_reflectance_out_of_range(self, tmp_path):
        text = ("name: s\nkind: substrate\ncolumns: wavelength_nm reflectance\n"
                "400 0.5\n500 1.2\n")
        with pytest.raises(ValueError, match=r"custom.txt:5: reflectance must lie in \[0, 1\]"):
            load_substrate(write(tmp_path, text))


class TestSave:
    def test_colourant_round_trip(self, tmp_path):
        c = load_colourant("magenta", wavelengths=None)
        path = tmp_path / "m.txt"
        save_colourant(path, c)
        assert path.read_text().startswith(FORMAT_LINE + "\n")
        back = load_colourant(path, wavelengths=None)
        np.testing.assert_allclose(back.K, c.K, rtol=1e-5)
        np.testing.assert_allclose(back.S, c.S, rtol=1e-5)
        assert back.provenance == c.provenance and back.name == "magenta"

    def test_substrate_round_trip(self, tmp_path):
        s = Substrate(name="grey card", reflectance=np.full(3, 0.18),
                      wavelengths=[400.0, 550.0, 700.0], description="18 % grey",
                      provenance="made up")
        save_substrate(tmp_path / "g.txt", s)
        back = load_substrate(tmp_path / "g.txt", wavelengths=None)
        np.testing.assert_array_equal(back.reflectance, s.reflectance)
        assert back.name == "grey card" and back.description == "18 % grey"
