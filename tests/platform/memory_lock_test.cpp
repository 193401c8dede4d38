#include "platform/memory_lock.h"

#include <gtest/gtest.h>

namespace plumb {
namespace {

#if defined(__SANITIZE_THREAD__) || defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif

TEST(MemoryLock, LocksOrExplainsWhyNot) {
  // Sanitizers reserve terabytes of shadow memory; locking it all would exhaust the machine.
  if (kSanitized) GTEST_SKIP() << "mlockall is not meaningful under a sanitizer";
  const Status status = lockProcessMemory();
  if (!status.ok()) {
    EXPECT_NE(status.message().find("mlockall"), std::string::npos) << status.message();
  }
  unlockProcessMemory();  // leave the test process as it was
}

}  // namespace
}  // namespace plumb
