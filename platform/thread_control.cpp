#include "platform/thread_control.h"

#include <pthread.h>
#include <sched.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>

namespace plumb {

namespace {

std::string errnoText(int err) { return std::string(std::strerror(err)); }

// Prints message once per flag for the lifetime of the process.
void warnOnce(std::atomic<bool>& already_warned, const Status& status) {
  if (!already_warned.exchange(true)) {
    std::fprintf(stderr, "plumb: warning: %s (continuing without it)\n", status.message().c_str());
  }
}

std::atomic<bool> g_warned_name{false};
std::atomic<bool> g_warned_pin{false};
std::atomic<bool> g_warned_priority{false};

}  // namespace

Status setCurrentThreadName(const std::string& name) {
  // Linux limits thread names to 16 bytes including the terminator.
  const std::string truncated = name.substr(0, 15);
  const int err = pthread_setname_np(pthread_self(), truncated.c_str());
  if (err != 0) return Status::Error("cannot name thread '" + truncated + "': " + errnoText(err));
  return Status::Ok();
}

Status pinCurrentThreadToCpu(int cpu) {
  if (cpu < 0 || cpu >= CPU_SETSIZE) {
    return Status::Error("cannot pin thread to CPU " + std::to_string(cpu) + ": no such CPU");
  }
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  const int err = pthread_setaffinity_np(pthread_self(), sizeof(set), &set);
  if (err != 0) {
    return Status::Error("cannot pin thread to CPU " + std::to_string(cpu) + ": " + errnoText(err));
  }
  return Status::Ok();
}

Status setCurrentThreadRealtimePriority(int priority) {
  const int lo = sched_get_priority_min(SCHED_FIFO);
  const int hi = sched_get_priority_max(SCHED_FIFO);
  if (priority < lo || priority > hi) {
    return Status::Error("SCHED_FIFO priority " + std::to_string(priority) + " outside " +
                         std::to_string(lo) + ".." + std::to_string(hi));
  }
  sched_param param{};
  param.sched_priority = priority;
  const int err = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param);
  if (err == EPERM) {
    return Status::Error("real-time priority SCHED_FIFO " + std::to_string(priority) +
                         " not permitted (needs CAP_SYS_NICE or an rtprio limit in "
                         "/etc/security/limits.conf); using normal scheduling");
  }
  if (err != 0) return Status::Error("cannot set SCHED_FIFO priority: " + errnoText(err));
  return Status::Ok();
}

Status applyThreadSettings(const ThreadSettings& settings) {
  Status first = Status::Ok();
  auto keep = [&first](Status status, std::atomic<bool>& warned) {
    if (status.ok()) return;
    warnOnce(warned, status);
    if (first.ok()) first = status;
  };
  if (!settings.name.empty()) keep(setCurrentThreadName(settings.name), g_warned_name);
  if (settings.cpu >= 0) keep(pinCurrentThreadToCpu(settings.cpu), g_warned_pin);
  if (settings.realtime_priority > 0) {
    keep(setCurrentThreadRealtimePriority(settings.realtime_priority), g_warned_priority);
  }
  return first;
}

int availableCpuCount() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof(set), &set) != 0) return 1;
  const int count = CPU_COUNT(&set);
  return count > 0 ? count : 1;
}

}  // namespace plumb
