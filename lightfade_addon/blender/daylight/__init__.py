"""Daylight over the year for a place on Earth, and doses people can read.

``settings``  ``Scene.lightfade_daylight``: place, weather, daylight spectrum
``place``     where the place comes from (Sun Position add-on or LightFade), the weather
              file, the annual sky map (cached), ``set_daylight``
``doses``     annual dose per texel and per material, years until a noticeable fade
``colours``   log scales, the false-colour ramp and the legend image (no Blender)
``view``      the false-colour view object (the user's object and material untouched)
``operators``, ``panel``  the UI

The bake of the daylight group itself is :mod:`..bake.daylight`.  Nothing is imported
here, so that the bake package and this one can import each other's modules.
"""
