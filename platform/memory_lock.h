#pragma once
// Optional memory locking for real-time runs: mlockall(MCL_CURRENT | MCL_FUTURE) keeps every page
// of the process resident, so a stage never stalls on a page fault after start-up. Needs
// CAP_IPC_LOCK or a large enough RLIMIT_MEMLOCK; when refused the process runs unlocked and the
// caller gets a Status saying why (printed once by lockProcessMemoryOrWarn).
#include "platform/status.h"

namespace plumb {

Status lockProcessMemory();
// As lockProcessMemory(), but prints one warning on failure and returns whether memory is locked.
bool lockProcessMemoryOrWarn();
void unlockProcessMemory();

}  // namespace plumb
