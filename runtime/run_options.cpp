#include "runtime/run_options.h"

namespace plumb::runtime {

const char* runModeName(RunMode mode) {
  switch (mode) {
    case RunMode::kRealtime: return "realtime";
    case RunMode::kFast: return "fast";
    case RunMode::kDeterministic: return "deterministic";
  }
  return "?";
}

Status parseRunMode(const std::string& text, RunMode* mode) {
  for (RunMode m : {RunMode::kRealtime, RunMode::kFast, RunMode::kDeterministic}) {
    if (text == runModeName(m)) {
      *mode = m;
      return Status::Ok();
    }
  }
  return Status::Error("unknown run mode '" + text + "' (expected realtime, fast or deterministic)");
}

}  // namespace plumb::runtime
