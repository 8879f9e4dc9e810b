"""``lightfade.bake_exposure``: bake the exposure maps of the selected (or enabled) meshes.

From the UI (invoke) the bake runs modally, one light group per timer tick: the progress
bar and the status line show the group and the time left, and Esc cancels cleanly
(settings restored, no map stored).  From scripts (exec) it runs to the end, printing one
line per bake in background mode.
"""

import bpy
from bpy.props import BoolProperty

from ...output import maps_made
from ..bake import BakeCancelled, BakeSettings, ExposureBake, LightFadeBakeError, bake_exposure
from ..bake import calibrate
from ..progress import WindowProgress
from ..targets import format_problems, material_problems


class LIGHTFADE_OT_bake_exposure(bpy.types.Operator):
    """Bake per-texel illuminance (lux) from each light group (lamps sharing spectrum and \
schedule, the world, emissive meshes) with Cycles, for the selected meshes (or, with none \
selected, every mesh whose material has LightFade enabled).  Esc cancels"""

    bl_idname = "lightfade.bake_exposure"
    bl_label = "Bake Exposure"
    bl_options = {"REGISTER", "UNDO"}

    unwrap: BoolProperty(
        name="Unwrap Missing UVs",
        description="Give meshes without a UV map a LightFadeUV map instead of skipping them",
        default=False,
    )
    only_changed: BoolProperty(
        name="Changed Groups Only",
        description="Keep the maps of light groups that did not change; maps of groups that "
        "merged are added up without baking",
        default=False,
    )

    @classmethod
    def poll(cls, context):
        return context.scene is not None and context.mode == "OBJECT"

    def _settings(self, context):
        return BakeSettings.from_scene(context.scene, unwrap=self.unwrap)

    def _only_changed(self, context):
        return self.only_changed or context.scene.lightfade_bake.only_changed

    def _warn(self, msg):
        self.report({"WARNING"}, msg)

    def _refused(self, context):
        """Every problem that would refuse the bake or the Age after it — the materials'
        and the bake's own checks (UVs, modifiers, emitters) — reported in one message
        before any Cycles work.  True if there was any."""
        objects = list(context.selected_objects)
        problems = material_problems(context.scene, objects)
        dry_run = ExposureBake(context, objects, self._settings(context), report=lambda msg: None,
                               only_changed=self._only_changed(context))
        try:
            dry_run.plan()
        except LightFadeBakeError as err:
            problems += [line for line in str(err).splitlines() if line.strip()]
        if problems:
            self.report({"ERROR"}, format_problems(problems))
        return bool(problems)

    def execute(self, context):
        if self._refused(context):
            return {"CANCELLED"}
        try:
            result = bake_exposure(context, list(context.selected_objects), self._settings(context),
                                   report=self._warn, only_changed=self._only_changed(context))
        except LightFadeBakeError as err:
            self.report({"ERROR"}, str(err))
            return {"CANCELLED"}
        self.report({"INFO"}, f"Baked {maps_made(result, 'exposure map')}, "
                              f"{result['seconds']:.1f} s")
        return {"FINISHED"}

    # -- modal run from the UI
    def invoke(self, context, event):
        if context.window is None or bpy.app.background:
            return self.execute(context)
        if self._refused(context):
            return {"CANCELLED"}
        wm = context.window_manager
        self._window = WindowProgress(context, hint="Esc to cancel")
        self._job = ExposureBake(context, list(context.selected_objects), self._settings(context),
                                 report=self._warn, progress=self._window,
                                 only_changed=self._only_changed(context))
        try:
            self._job.plan()
            self._job.__enter__()
        except LightFadeBakeError as err:
            self._window.end()
            self.report({"ERROR"}, str(err))
            return {"CANCELLED"}
        self._cancel = False
        self._timer = wm.event_timer_add(0.05, window=context.window)
        wm.modal_handler_add(self)
        self._window(0.0, "baking exposure…")
        return {"RUNNING_MODAL"}

    def _end(self, context, exc=None):
        context.window_manager.event_timer_remove(self._timer)
        self._window.end()
        return self._job.__exit__(type(exc) if exc else None, exc, None)

    def modal(self, context, event):
        if event.type == "ESC":
            self._cancel = True
        if event.type != "TIMER":
            return {"RUNNING_MODAL"} if not self._cancel else self._finish(context)
        return self._finish(context)

    def _finish(self, context):
        try:
            more = self._job.step(cancel=lambda: self._cancel)
            if more:
                return {"RUNNING_MODAL"}
            maps = self._job.commit()
        except LightFadeBakeError as err:
            self._end(context, err)
            level = {"WARNING"} if isinstance(err, BakeCancelled) else {"ERROR"}
            self.report(level, str(err))
            return {"CANCELLED"}
        except Exception as err:
            self._end(context, err)
            raise
        self._end(context)
        made = {"maps": maps, "groups": self._job.groups, "emitters": self._job.emitters}
        self.report({"INFO"}, f"Baked {maps_made(made, 'exposure map')}")
        return {"FINISHED"}


class LIGHTFADE_OT_bake_calibrate(bpy.types.Operator):
    """Time tiny bakes on this scene to estimate how long the exposure bake takes"""

    bl_idname = "lightfade.bake_calibrate"
    bl_label = "Calibrate"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return context.scene is not None and context.mode == "OBJECT"

    def execute(self, context):
        try:
            rate, overhead = calibrate(context)
        except LightFadeBakeError as err:
            self.report({"ERROR"}, str(err))
            return {"CANCELLED"}
        self.report({"INFO"}, f"Cycles bakes {rate / 1e6:.2f} M texel·samples/s "
                              f"(+{overhead:.2f} s per call) here")
        return {"FINISHED"}
