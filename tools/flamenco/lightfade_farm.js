// SPDX-License-Identifier: GPL-3.0-or-later
// LightFade's farm job as a Flamenco job type: the steps of the OpenJD template that
// `lightfade farm-job` writes (docs/farm.md), as Flamenco tasks with dependencies.
//
// Put this file in the Flamenco Manager's `scripts/` folder and restart the Manager.
// Make the job first, on a machine with LightFade:
//     blender -c lightfade farm-job /shared/shots/lobby.blend --out /shared/jobs/lobby --years 25
// which writes /shared/jobs/lobby/flamenco_settings.json: the settings below (the plan,
// the light groups, the chunks, the frames). Submit a job of this type with them (the
// Manager's API: POST /api/v3/jobs with {"type": "lightfade-farm", "settings": ...}).
// The scene is read where it lies, on storage the workers share: the tasks check its
// SHA-256 against the plan, so a copy rewritten on submission (Flamenco's packing) is
// refused; give its path in `scene`.

const JOB_TYPE = {
  label: "LightFade Bake, Age and Time-lapse",
  description: "Exposure bake in tasks of one light group x a chunk of objects, merge, " +
    "aging and the years time-lapse (plain Blender renders it)",
  settings: [
    { key: "scene", type: "string", subtype: "file_path", required: true,
      description: "The .blend file the job was made from (read only)" },
    { key: "plan", type: "string", subtype: "file_path", required: true,
      description: "plan.json of the job's folder (written by farm-job)" },
    { key: "groups", type: "string", required: true,
      description: "The light groups, one per line (flamenco_settings.json)" },
    { key: "chunks", type: "int32", required: true, default: 1,
      description: "Chunks of objects per light group" },
    { key: "work_dir", type: "string", subtype: "dir_path", required: true,
      description: "Where the Bake tasks write their maps for Merge" },
    { key: "output_dir", type: "string", subtype: "dir_path", required: true,
      description: "Where Merge and Age write their files, Render the frames" },
    { key: "stem", type: "string", required: true,
      description: "The scene's file name without .blend" },
    { key: "years", type: "float", default: 0.0,
      description: "Years at the last frame; 0: no Age and Render" },
    { key: "frame_start", type: "int32", default: 1 },
    { key: "frame_end", type: "int32", default: 1 },
  ],
};

function lightfade(args) {
  // `blender -c lightfade ARGS`: options for Blender itself go before -c
  return author.Command("exec", { exe: "{blender}", args: ["-c", "lightfade"].concat(args) });
}

function compileJob(job) {
  const s = job.settings;
  const maps = path.join(s.work_dir, "maps");
  const merged = path.join(s.output_dir, s.stem + "_baked.blend");
  const aged = path.join(s.output_dir, s.stem + "_aged.blend");
  const groups = s.groups.split("\n").filter((g) => g.length > 0);

  const merge = author.Task("merge", "blender");
  merge.addCommand(lightfade(["farm-merge", s.scene, "--plan", s.plan,
    "--maps", maps, "--output", merged]));
  groups.forEach((group) => {
    for (let chunk = 0; chunk < s.chunks; chunk++) {
      const bake = author.Task(`bake ${group} ${chunk}`, "blender");
      bake.addCommand(lightfade(["farm-bake", s.scene, "--plan", s.plan,
        "--group", group, "--chunk", String(chunk), "--maps", maps]));
      job.addTask(bake);
      merge.addDependency(bake);
    }
  });
  job.addTask(merge);
  if (!(s.years > 0)) {
    return;
  }
  const age = author.Task("age", "blender");
  age.addCommand(lightfade(["farm-age", merged, "--years", String(s.years),
    "--frames", String(s.frame_start), String(s.frame_end), "--output", aged]));
  age.addDependency(merge);
  job.addTask(age);
  for (let frame = s.frame_start; frame <= s.frame_end; frame++) {
    // plain Blender: the aged file renders its years without LightFade
    const render = author.Task(`render ${frame}`, "blender");
    render.addCommand(author.Command("blender-render", {
      exe: "{blender}", exeArgs: "{blenderArgs}", argsBefore: [], blendfile: aged,
      args: ["--render-output", path.join(s.output_dir, "renders", s.stem + "_####"),
        "--render-frame", String(frame)],
    }));
    render.addDependency(age);
    job.addTask(render);
  }
}
