#include "platform/futex.h"

#include <gtest/gtest.h>

#include <thread>

namespace plumb {
namespace {

TEST(Futex, WaitReturnsAtOnceWhenTheWordAlreadyChanged) {
  std::atomic<uint32_t> word{7};
  futexWait(&word, 6);  // would block forever if the comparison were not done
  EXPECT_EQ(word.load(), 7u);
}

TEST(Futex, WakeReleasesAWaiter) {
  std::atomic<uint32_t> word{0};
  std::thread waiter([&] {
    while (word.load() == 0) futexWait(&word, 0);
  });
  word.store(1);
  futexWakeAll(&word);
  waiter.join();
  EXPECT_EQ(word.load(), 1u);
}

TEST(Futex, TimeoutEnds) {
  std::atomic<uint32_t> word{0};
  futexWait(&word, 0, 1'000'000);  // 1 ms, nobody wakes us
  EXPECT_EQ(word.load(), 0u);
}

}  // namespace
}  // namespace plumb
