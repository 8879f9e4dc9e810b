"""Colour science: spectra to CIE XYZ, CIELAB, sRGB, colour differences, the gamut rule."""

import warnings

# colour-science imports its plotting module whenever it is imported, and says so once
# on the console where matplotlib is missing, as it is in Blender (the extension does
# not ship it): LightFade draws nothing with it, so the line would only puzzle.
warnings.filterwarnings("ignore", message='"Matplotlib" related API features are not available')
