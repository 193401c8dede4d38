// `plumb run`, step 3 of 4 (tools/run_command.h): the plan through the one runner into the outputs,
// then --save-map.
#include "tools/map_files.h"
#include "tools/run_command.h"

namespace plumb::tools {

void executeRun(const RunCommandOptions& options, RunPlan& plan, RunOutputs& outputs, RunExecution* execution) {
  execution->status = runToOutputs(*plan.source, plan.system_options, plan.run_options, outputs,
                                   &execution->record, plan.serve.wrap(outputs));
  plan.serve.stop();
  if (options.save_map.empty()) return;
  // The map is written whatever ended the run (a stop, a read error): like the trajectory, it holds
  // what was computed. But only a map plumb can load again: one without a keyframe (the run never
  // initialised, or failed on its first frame) would replace a good map by a useless one.
  if (!execution->record.run.loop.enabled) {
    execution->map_note = "no map saved: loop closing did not run";
    return;
  }
  if (plan.saved_map.keyframes.empty()) {
    execution->map_note = "no map saved: the run made no keyframe; " + options.save_map + " was left unchanged";
    return;
  }
  const Status saved = saveMapFile(options.save_map, plan.saved_map, &execution->map_bytes);
  if (!saved.ok()) {
    execution->map_note = saved.message();
    if (execution->status.ok()) execution->status = saved;
    return;
  }
  execution->map_saved = true;
}

}  // namespace plumb::tools
