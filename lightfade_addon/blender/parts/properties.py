"""The data model of a material's parts: several recipes in one material, by mask.

One texture often holds several materials (a sofa's fabric, its carved wooden frame,
its leather-look arms). ``Material.lightfade.parts`` (:class:`LIGHTFADE_PG_part`) says
which parts age with which recipe, each by a **mask**: an image (sampled with a UV map
of the mesh), a colour or float attribute of the mesh, or an output socket of a node in
the artist's own graph (picked by name). ``Material.lightfade.rest`` says what
happens to everything no part claims: it ages with the material's own recipe, or it
does not age. A part whose recipe is *Does Not Age* stays exactly as it is.

On an aged copy, ``Material.lightfade.lanes`` (:class:`LIGHTFADE_PG_lane`) holds one
preparation per recipe in use (parts with the same recipe and sensitivity share one):
its recipe, the colour table its aging group reads and the weights baked for Apply to
Images (:mod:`..aging.parts`).
"""

import bpy
from bpy.props import EnumProperty, FloatProperty, IntProperty, PointerProperty, \
    StringProperty
from bpy.types import PropertyGroup

from ..vocabulary import RECIPE_BLUE_WOOL, RECIPE_ITEMS

#: The part recipe that keeps its pixels exactly as they are.
KEEP = "KEEP"

PART_RECIPE_ITEMS = (
    (KEEP, "Does Not Age", "This part stays exactly as it is, pixel for pixel, at every years "
     "(glass, metal, a print under UV-filtering glazing)"),
    *RECIPE_ITEMS,
)

REST_ITEMS = (
    ("RECIPE", "Material's Recipe", "Everything no part claims ages with the material's recipe "
     "above"),
    (KEEP, "Does Not Age", "Everything no part claims stays exactly as it is"),
)

MASK_ITEMS = (
    ("IMAGE", "Image", "A mask image, white where this part is (sampled with a UV map of the "
     "mesh)"),
    ("ATTRIBUTE", "Attribute", "A colour or float attribute of the mesh (e.g. painted vertex "
     "colours), 1 where this part is"),
    ("SOCKET", "Node Output", "An output of a node in your own material graph, picked by the "
     "node's name: 1 where this part is"),
)

CHANNEL_ITEMS = (
    ("R", "R", "The red channel (or the value of a grey mask or a float attribute)"),
    ("G", "G", "The green channel"),
    ("B", "B", "The blue channel"),
    ("A", "A", "The alpha channel (images and colour attributes)"),
)


def _on_recipe_changed(self, context):
    # A new recipe brings its usual light-fastness; the user may change it afterwards.
    if self.recipe != KEEP:
        self.blue_wool = RECIPE_BLUE_WOOL.get(self.recipe, 3)


class LIGHTFADE_PG_part(PropertyGroup):
    """One part of a material: which texels (a mask) age with which recipe."""

    recipe: EnumProperty(
        name="Recipe",
        description="What this part is made of (or Does Not Age: it keeps its pixels)",
        items=PART_RECIPE_ITEMS,
        default=KEEP,
        update=_on_recipe_changed,
    )
    sensitivity_mode: EnumProperty(
        name="Sensitivity",
        description="How this part's light sensitivity is given",
        items=(("BLUE_WOOL", "Blue Wool", "ISO Blue Wool class 1-8"),
               ("BETA", "β", "The sensitivity coefficient β of the fading model directly")),
        default="BLUE_WOOL",
    )
    blue_wool: IntProperty(
        name="Blue Wool Class",
        description="ISO Blue Wool light-fastness class of this part: 1 very fugitive to 8 "
        "very stable",
        default=3, min=1, max=8,
    )
    beta: FloatProperty(
        name="β (×10⁻⁶)",
        description="Sensitivity β of this part's most light-sensitive colourant, in millionths",
        default=23.0, min=0.0, soft_max=1000.0, precision=3,
    )
    mask: EnumProperty(name="Mask", description="Where this part's mask comes from",
                       items=MASK_ITEMS, default="IMAGE")
    image: PointerProperty(name="Mask Image", type=bpy.types.Image,
                           description="White where this part is, black elsewhere")
    uv_map: StringProperty(name="UV Map",
                           description="UV map the mask image is sampled with (empty: the "
                           "mesh's active render UV map, the one textures usually use)")
    attribute: StringProperty(name="Attribute",
                              description="Name of the mesh's colour or float attribute")
    node: StringProperty(name="Node", description="Name of a node in the material's graph "
                         "(in the node tree that holds the colour BSDF)")
    socket: StringProperty(name="Output", description="Name of the node's output (empty: its "
                           "first output)")
    channel: EnumProperty(name="Channel", description="Which channel of the mask says 'this "
                          "part'", items=CHANNEL_ITEMS, default="R")


class LIGHTFADE_PG_lane(PropertyGroup):
    """On an aged copy: one recipe in use and its preparation (written by Age)."""

    recipe: StringProperty(name="Recipe", description="Recipe identifier of this preparation")
    sensitivity_mode: StringProperty(name="Sensitivity", description="BLUE_WOOL or BETA")
    blue_wool: IntProperty(name="Blue Wool Class", default=3,
                           description="Blue Wool class of this preparation")
    beta: FloatProperty(name="β (×10⁻⁶)", default=23.0,
                        description="Sensitivity β of this preparation, in millionths")
    fastness: StringProperty(name="Per-Colourant Classes",
                             description="Per-colourant Blue Wool classes of this preparation")
    table_image: PointerProperty(name="Aging Table Image", type=bpy.types.Image,
                                 description="The colour table of this recipe (shared with "
                                 "every material aging with it under the same light spectra)")
    lost_texels: IntProperty(name="Lost Texels", default=0, min=0,
                             description="Texels whose colour when new this recipe cannot "
                             "recover")
    weight_image: PointerProperty(name="Weights", type=bpy.types.Image,
                                  description="This recipe's weight per texel (channel: the "
                                  "lane's index mod 3), baked for Apply to Images")


def part_recipe_key(settings):
    """The recipe and sensitivity that make one preparation (parts sharing it share one)."""
    sensitivity = (f"beta {settings.beta:g}" if settings.sensitivity_mode == "BETA"
                   else f"blue wool {settings.blue_wool}")
    fastness = getattr(settings, "fastness", "").strip()       # the material's own only
    return f"{settings.recipe} / {sensitivity}" + (f" / {fastness}" if fastness else "")


def parts_digest(props):
    """Everything of a material's parts the aged copy depends on ('' without parts)."""
    if len(props.parts) == 0:
        return ""
    rows = [f"rest {props.rest}"]
    for part in props.parts:
        source = {"IMAGE": f"{part.image.name if part.image else ''}@{part.uv_map}",
                  "ATTRIBUTE": part.attribute,
                  "SOCKET": f"{part.node}.{part.socket}"}[part.mask]
        rows.append(f"{part.name}: {part_recipe_key(part)}; {part.mask} {source} "
                    f"{part.channel}")
    return "\n".join(rows)


_MASKS = {"image": "IMAGE", "attribute": "ATTRIBUTE", "node": "SOCKET"}
_OPTIONS = {"name", "recipe", "uv_map", "socket", "channel", "blue_wool", "beta", *_MASKS}


def _checked(material, i, part):
    """``part`` (a dict) as property values, or ValueError naming what is wrong."""
    where = f"Material '{material.name}', part {i + 1}"
    unknown = sorted(set(part) - _OPTIONS)
    if unknown:
        raise ValueError(f"{where}: unknown key {unknown[0]!r} (known: "
                         f"{', '.join(sorted(_OPTIONS))})")
    recipe = part.get("recipe", KEEP)
    recipes = [item[0] for item in PART_RECIPE_ITEMS]
    if recipe not in recipes:
        raise ValueError(f"{where}: recipe {recipe!r} is not one of {', '.join(recipes)}")
    masks = [key for key in _MASKS if key in part]
    if len(masks) != 1:
        raise ValueError(f"{where}: give exactly one mask: image=, attribute= or node=")
    values = {"name": str(part.get("name", f"Part {i + 1}")), "recipe": recipe,
              "mask": _MASKS[masks[0]], "channel": part.get("channel", "R")}
    if values["channel"] not in "RGBA" or len(values["channel"]) != 1:
        raise ValueError(f"{where}: channel {values['channel']!r} is not R, G, B or A")
    image = part.get("image")
    if image is not None and not isinstance(image, bpy.types.Image):
        raise ValueError(f"{where}: image= takes a bpy.types.Image, got {type(image).__name__}")
    values.update(image=image, uv_map=str(part.get("uv_map", "")),
                  attribute=str(part.get("attribute", "")), node=str(part.get("node", "")),
                  socket=str(part.get("socket", "")))
    if "beta" in part:
        values.update(sensitivity_mode="BETA", beta=float(part["beta"]))
    elif "blue_wool" in part:
        if not 1 <= int(part["blue_wool"]) <= 8:
            raise ValueError(f"{where}: blue_wool {part['blue_wool']!r} is not 1 to 8")
        values["blue_wool"] = int(part["blue_wool"])
    return values


def set_parts(material, parts, rest=None):
    """Replace ``material``'s parts (``api.set_parts``); every value is checked first."""
    rests = [item[0] for item in REST_ITEMS]
    if rest is not None and rest not in rests:
        raise ValueError(f"Material '{material.name}': rest {rest!r} is not one of "
                         f"{', '.join(rests)}")
    checked = [_checked(material, i, part) for i, part in enumerate(parts)]
    props = material.lightfade
    props.parts.clear()
    for values in checked:
        part = props.parts.add()
        for key in ("name", "recipe", "mask", "image", "uv_map", "attribute", "node",
                    "socket", "channel", "sensitivity_mode", "beta", "blue_wool"):
            if key in values:                    # recipe first: it sets its Blue Wool class
                setattr(part, key, values[key])
    props.part_index = 0
    if rest is not None:
        props.rest = rest
    return props.parts





#: Registered before :mod:`..properties` (``LIGHTFADE_PG_material`` holds both).
CLASSES = (LIGHTFADE_PG_part, LIGHTFADE_PG_lane)
