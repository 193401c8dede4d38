#include "platform/thread_control.h"

#include <gtest/gtest.h>
#include <pthread.h>

#include <thread>

namespace plumb {
namespace {

std::string currentThreadName() {
  char name[32] = {};
  pthread_getname_np(pthread_self(), name, sizeof(name));
  return name;
}

TEST(ThreadControl, NamesTheCallingThreadTruncatedToTheKernelLimit) {
  std::string seen;
  Status status;
  std::thread worker([&] {
    status = setCurrentThreadName("a-very-long-stage-name");
    seen = currentThreadName();
  });
  worker.join();
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(seen, "a-very-long-sta");  // 15 characters
}

TEST(ThreadControl, PinningToAnAllowedCpuWorksAndANonexistentOneIsAClearError) {
  std::thread worker([] {
    // CPU 0 may be outside a restricted affinity mask; then the error must say so clearly.
    const Status pinned = pinCurrentThreadToCpu(0);
    if (!pinned.ok()) {
      EXPECT_NE(pinned.message().find("CPU 0"), std::string::npos);
    }
    const Status bad = pinCurrentThreadToCpu(-3);
    EXPECT_FALSE(bad.ok());
    EXPECT_NE(bad.message().find("no such CPU"), std::string::npos);
  });
  worker.join();
}

TEST(ThreadControl, RealtimePriorityEitherAppliesOrExplainsWhy) {
  std::thread worker([] {
    const Status status = setCurrentThreadRealtimePriority(10);
    if (status.ok()) {
      int policy = 0;
      sched_param param{};
      pthread_getschedparam(pthread_self(), &policy, &param);
      EXPECT_EQ(policy, SCHED_FIFO);
      EXPECT_EQ(param.sched_priority, 10);
    } else {
      EXPECT_NE(status.message().find("SCHED_FIFO"), std::string::npos) << status.message();
    }
    EXPECT_FALSE(setCurrentThreadRealtimePriority(1000).ok());
  });
  worker.join();
}

TEST(ThreadControl, ApplySettingsFallsBackAndKeepsTheThreadUsable) {
  std::thread worker([] {
    ThreadSettings settings;
    settings.name = "plumb-test";
    settings.realtime_priority = 5;
    const Status status = applyThreadSettings(settings);
    // Whether or not SCHED_FIFO was permitted, the name is set and the thread runs on.
    EXPECT_EQ(currentThreadName(), "plumb-test");
    if (!status.ok()) {
      EXPECT_FALSE(status.message().empty());
    }
  });
  worker.join();
  EXPECT_GE(availableCpuCount(), 1);
}

}  // namespace
}  // namespace plumb
