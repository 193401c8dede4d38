#include "tools/run_flags.h"

namespace plumb::tools {

const std::set<std::string>& scheduleValueFlags() {
  static const std::set<std::string> flags = {"mode", "profile", "slots", "rt-priority"};
  return flags;
}

const std::set<std::string>& scheduleSwitchFlags() {
  static const std::set<std::string> flags = {"pin-threads", "mlock"};
  return flags;
}

const char* scheduleUsage() {
  return "  --mode M             deterministic (default: the stages in lock-step on one thread, the\n"
         "                       same bytes every run), fast (a thread per stage, no drops, the\n"
         "                       tracker waits for the map after each keyframe: the same bytes as\n"
         "                       deterministic, faster) or realtime (threads, paced to the recorded\n"
         "                       timestamps, a frame finding no free slot is dropped and counted)\n"
         "  --profile FILE       write a Chrome trace (Perfetto / chrome://tracing) and print\n"
         "                       p50/p90/p99/max per stage and end to end, drops, frames/s\n"
         "  --slots N            frame slots in flight in the threaded modes (default 8)\n"
         "  --rt-priority P      SCHED_FIFO priority 1..99 for stage threads (falls back if refused)\n"
         "  --pin-threads        pin stage threads to CPUs\n"
         "  --mlock              lock process memory (falls back if refused)\n";
}

Status parseScheduleFlags(const Args& args, OdometryRunOptions* options, std::string* profile_path) {
  runtime::RunOptions& s = options->schedule;
  if (args.has("mode")) PLUMB_RETURN_IF_ERROR(runtime::parseRunMode(args.get("mode"), &s.mode));
  *profile_path = args.get("profile");
  bool ok = true;
  const long slots = args.getInt("slots", static_cast<long>(s.slot_count), &ok);
  const long priority = args.getInt("rt-priority", s.realtime_priority, &ok);
  if (!ok) return Status::Error("--slots and --rt-priority take integers");
  if (slots < 1 || slots > 64) return Status::Error("--slots must be within 1..64");
  if (priority < 0 || priority > 99) return Status::Error("--rt-priority must be within 0..99");
  s.slot_count = static_cast<std::size_t>(slots);
  s.realtime_priority = static_cast<int>(priority);
  s.pin_threads = args.has("pin-threads");
  s.lock_memory = args.has("mlock");
  return Status::Ok();
}

}  // namespace plumb::tools
