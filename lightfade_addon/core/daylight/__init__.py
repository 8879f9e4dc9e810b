"""Annual daylight for a place: the sun's path, clear and all-weather skies, weather files, the annual sky map."""
