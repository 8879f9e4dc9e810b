"""Colour science: spectra to CIE XYZ, CIELAB, sRGB, colour differences, the gamut rule."""
