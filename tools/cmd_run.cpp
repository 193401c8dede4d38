// plumb run: the odometry over a dataset, recording, sensor or synthetic scene, through the one
// runner (pipeline/run/odometry_run.h), writing the trajectory (TUM format, lost frames as
// `# <timestamp> lost`, frames real-time mode dropped as `# <timestamp> dropped`), optionally
// keyframe covariances and statistics, and the ATE when ground truth is at hand. Default mode:
// deterministic (lock-step, one thread): same input -> same output bytes.
//
// The command is parse -> plan -> run -> report (tools/run_command.h), each in its own file; this
// one holds the stop signals and calls the four.
#include <atomic>
#include <csignal>
#include <cstdio>

#include "platform/monotonic_time.h"
#include "tools/command.h"
#include "tools/run_command.h"

namespace plumb::tools {
namespace {

// SIGINT / SIGTERM / SIGHUP (a dropped SSH session) / SIGPIPE (`--trace 2>&1 | head -1`): the
// capture stops reading, the frames already read finish, and every pose reaches the outputs. A
// second SIGINT/SIGTERM/SIGHUP more than a second after the first is the default action (the
// outputs' temporary files are then left, never a partial file under an output's name). One within
// the second is the same request: `timeout -s INT` sends its signal to the process AND to its
// process group, so a stopped run sees two at once (a run under ASan was killed by the second).
// SIGPIPE never escalates: every later write to the closed pipe raises it again, and the run must
// still finish writing its files (the write itself then fails with EPIPE, which stderr ignores).
std::atomic<bool> g_stop_requested{false};
volatile std::sig_atomic_t g_stop_signal = 0;
std::atomic<int64_t> g_first_stop_ns{0};

void onStopSignal(int signal) {
  const int64_t now = monotonicNowNs();  // clock_gettime: async-signal-safe
  int64_t first = 0;
  const bool first_request = g_first_stop_ns.compare_exchange_strong(first, now);
  if (first_request || signal == SIGPIPE || now - first < 1'000'000'000) {
    if (g_stop_signal == 0 || first_request) g_stop_signal = signal;
    g_stop_requested.store(true);
    return;
  }
  std::signal(signal, SIG_DFL);
  std::raise(signal);
}

constexpr int kStopSignals[] = {SIGINT, SIGTERM, SIGHUP, SIGPIPE};

void setStopHandlers(bool on) {
  for (int signal : kStopSignals) std::signal(signal, on ? onStopSignal : SIG_DFL);
}

int runRun(int argc, char** argv) {
  RunCommandOptions options;
  FlagTable table = runFlagTable(&options);
  bool help = false;
  Status st = parseRunCommand(argc, argv, &table, &options, &help);
  if (help) {
    printRunUsage(table);
    return kExitOk;
  }
  if (!st.ok()) {
    std::fprintf(stderr, "plumb run: %s (see plumb run --help)\n", st.message().c_str());
    return kExitUsage;
  }
  // From here on a stop request is honoured: one that arrives while the source and the system are
  // being built ends the run before its first frame, cleanly (exit code 3, no output replaced).
  setStopHandlers(true);
  RunPlan plan;
  bool usage_error = false;
  st = planRun(options, &g_stop_requested, &plan, &usage_error);
  if (!st.ok()) {
    std::fprintf(stderr, "plumb run: %s\n", st.message().c_str());
    return usage_error ? kExitUsage : kExitFailed;
  }
  RunOutputs outputs(plan.output_options);
  RunExecution execution;
  executeRun(options, plan, outputs, &execution);
  // Outputs are closed: a signal now is the default action again, except SIGPIPE (the report's
  // lines to a closed pipe must not kill the writing of --stats).
  setStopHandlers(false);
  std::signal(SIGPIPE, SIG_IGN);
  return reportRun(options, table, plan, outputs, execution, int(g_stop_signal));
}

}  // namespace
}  // namespace plumb::tools

PLUMB_COMMAND(run, "odometry over a dataset or synthetic scene: trajectory, covariances, stats, ATE",
              plumb::tools::runRun);
