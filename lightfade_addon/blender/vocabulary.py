"""One vocabulary: the UI's light spectra and recipes, generated from the core's tables.

:data:`..core.spectra.LIGHTS` and :data:`..core.recipes.RECIPES` are the only lists of
spectra and recipes; the enum items here are made from them (identifier from the name,
description from the core's own one-line description), so the words in the interface
are the data's words, and a spectrum or recipe added to the core appears in the UI.
"""

from ..core.fading import recipes as _recipes
from ..core.fading import spectra as _spectra


def enum_id(core_name):
    """The enum identifier of a core name: ``"daylight-glass"`` -> ``"DAYLIGHT_GLASS"``."""
    return core_name.upper().replace("-", "_")


def _label(core_name):
    return core_name.replace("-", " ").title()


#: Spectrum enum identifier -> the id the core uses for that light spectrum.
SPECTRUM_IDS = {enum_id(name): name for name in _spectra.LIGHTS}

#: What ``AUTO`` means for each emitter kind.  Sun, sky and emissive meshes stand for
#: daylight entering a room through window glass; point, spot and area lamps are taken
#: as modern white LEDs.
AUTO_SPECTRUM = {
    "SUN": "DAYLIGHT_GLASS",
    "WORLD": "DAYLIGHT_GLASS",
    "EMISSIVE": "DAYLIGHT_GLASS",
    "DAYLIGHT": "DAYLIGHT_GLASS",
    "POINT": "LED",
    "SPOT": "LED",
    "AREA": "LED",
}

SPECTRUM_ITEMS = (
    ("AUTO", "Auto", "From the emitter type: sun, sky and emissive meshes: "
     f"{_spectra.LIGHTS['daylight-glass']}; point, spot and area lamps: "
     f"{_spectra.LIGHTS['led']}"),
    *((key, _label(name), _spectra.LIGHTS[name]) for key, name in SPECTRUM_IDS.items()),
)

#: The spectra a texture's own history can name (no AUTO: there is no emitter to ask).
PRIOR_SPECTRUM_ITEMS = tuple(item for item in SPECTRUM_ITEMS if item[0] != "AUTO")

EMITTER_KIND_ITEMS = (
    ("SUN", "Sun", "A sun lamp"),
    ("POINT", "Point", "A point lamp"),
    ("SPOT", "Spot", "A spot lamp"),
    ("AREA", "Area", "An area lamp"),
    ("WORLD", "World", "The world background (sky light)"),
    ("EMISSIVE", "Emissive Mesh", "A mesh with an emissive material"),
    ("DAYLIGHT", "Annual Daylight", "The sun over the year and the sky for the scene's place"),
)


def resolve_spectrum(schedule, kind):
    """The core's spectrum id for ``schedule`` on an emitter of ``kind``.

    Parameters
    ----------
    schedule : LIGHTFADE_PG_schedule
        The light schedule (its ``spectrum`` may be ``'AUTO'``).
    kind : str
        One of the :data:`EMITTER_KIND_ITEMS` identifiers.

    Returns
    -------
    str
        A key of :data:`..core.spectra.LIGHTS`.
    """
    spectrum = schedule.spectrum
    if spectrum == "AUTO":
        spectrum = AUTO_SPECTRUM.get(kind, "DAYLIGHT_GLASS")
    return SPECTRUM_IDS[spectrum]


#: Recipe enum identifier -> the id the core knows it by.
RECIPE_IDS = {enum_id(name): name for name in _recipes.RECIPES}

#: Blue Wool class a recipe starts from (ISO 105-B; 1 = very fugitive, 8 = very stable):
#: the class of its most light-sensitive colourant in the core's recipe.
RECIPE_BLUE_WOOL = {
    key: int(min(k for k in _recipes.RECIPES[core_id].blue_wool if k is not None))
    for key, core_id in RECIPE_IDS.items()
}

RECIPE_ITEMS = tuple((key, _label(name), _recipes.RECIPES[name].description)
                     for key, name in RECIPE_IDS.items())


#: Which rays see an aged copy's aged colour (``Scene.lightfade.aged_rays``, the ray gate
#: of :func:`.aging.copies.gate_rays`); the others see the original colour.
AGED_RAYS_ITEMS = (
    ("ALL", "All Rays", "Every ray, bounce light included: the exact render"),
    ("VISIBLE", "Visible Rays", "Camera, glossy and transmission rays see the aged colour; "
     "diffuse bounce light keeps the original colour (faster)"),
    ("CAMERA", "Camera Rays", "Only what the camera sees directly is aged; reflections and "
     "bounce light keep the original colour (fastest)"),
)
