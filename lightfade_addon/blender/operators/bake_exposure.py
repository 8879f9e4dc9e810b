"""``lightfade.bake_exposure``: bake the exposure maps of the selected (or enabled) meshes."""

import bpy
from bpy.props import BoolProperty

from ..bake import BakeSettings, LightFadeBakeError, bake_exposure
from ..progress import window_progress


class LIGHTFADE_OT_bake_exposure(bpy.types.Operator):
    """Bake per-texel illuminance (lux) from each lamp, the world and emissive meshes with \
Cycles, for the selected meshes (or, with none selected, every mesh whose material has \
LightFade enabled)"""

    bl_idname = "lightfade.bake_exposure"
    bl_label = "Bake Exposure"
    bl_options = {"REGISTER", "UNDO"}

    unwrap: BoolProperty(
        name="Unwrap Missing UVs",
        description="Smart UV Project meshes that have no UV map instead of skipping them",
        default=False,
    )

    @classmethod
    def poll(cls, context):
        return context.scene is not None and context.mode == "OBJECT"

    def execute(self, context):
        selected = list(context.selected_objects)
        settings = BakeSettings.from_scene(context.scene, unwrap=self.unwrap)
        try:
            with window_progress(context) as progress:
                result = bake_exposure(
                    context, selected, settings,
                    report=lambda msg: self.report({"WARNING"}, msg),
                    progress=lambda done, total, text: progress((done - 1) / max(total, 1), text),
                )
        except LightFadeBakeError as err:
            self.report({"ERROR"}, str(err))
            return {"CANCELLED"}
        n = sum(len(m) for m in result["maps"].values())
        self.report(
            {"INFO"},
            f"Baked {n} exposure map(s) for {len(result['maps'])} object(s) in {result['seconds']:.1f} s",
        )
        return {"FINISHED"}
