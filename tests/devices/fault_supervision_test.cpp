// Fault injection + supervision: the supervisor's counts match exactly what was injected, the
// backoff follows the configured schedule on a virtual clock, and the stream continues after
// every reconnection.
#include <gtest/gtest.h>

#include <atomic>
#include <functional>

#include "drivers/common/source_capture.h"
#include "drivers/fault/fault_injecting_source.h"
#include "drivers/fault/resilient_source.h"
#include "tests/devices/device_test_util.h"

namespace plumb {
namespace {

constexpr int kFrames = 40;

struct Rig {
  VirtualClock clock;
  FaultInjectingSource* faulty = nullptr;  // owned by `supervised`
  std::unique_ptr<ResilientSource> supervised;
};

std::unique_ptr<Rig> makeRig(std::vector<FaultEvent> plan, ResilientSourceOptions options = {}) {
  auto rig = std::make_unique<Rig>();
  auto inner = std::make_unique<test::VectorSource>(test::makeNoiseFrames(9, 8, 6, kFrames),
                                                    test::smallCamera(8, 6));
  auto faulty = std::make_unique<FaultInjectingSource>(std::move(inner), std::move(plan));
  rig->faulty = faulty.get();
  rig->supervised = std::make_unique<ResilientSource>(std::move(faulty), options, rig->clock);
  return rig;
}

// Drains the source; returns the delivered sequence numbers.
std::vector<uint64_t> drain(FrameSource& source, int* no_frames = nullptr) {
  std::vector<uint64_t> sequences;
  RgbdImage out;
  for (int guard = 0; guard < 10 * kFrames; ++guard) {
    const SourceResult r = source.next(out);
    if (r == SourceResult::kFrame) sequences.push_back(out.sequence);
    if (r == SourceResult::kNoFrame && no_frames) ++*no_frames;
    if (r == SourceResult::kEndOfStream || r == SourceResult::kError) break;
  }
  return sequences;
}

TEST(FaultSupervision, CountsMatchWhatWasInjectedAndTheStreamContinues) {
  auto rig = makeRig({
      {5, FaultKind::kDrop, 2},
      {10, FaultKind::kStall, 3},
      {14, FaultKind::kError},
      {20, FaultKind::kDisconnect, /*frames lost*/ 4, /*failed reopens*/ 3},
      {30, FaultKind::kDrop, 1},
  });
  int no_frames = 0;
  const std::vector<uint64_t> delivered = drain(*rig->supervised, &no_frames);
  const InjectedFaults& injected = rig->faulty->injected();
  const ResilienceStats& stats = rig->supervised->stats();

  EXPECT_EQ(injected.frames_dropped, 2u + 4u + 1u);
  EXPECT_EQ(stats.frames_missing, injected.frames_dropped);
  EXPECT_EQ(stats.gaps, 3u);
  EXPECT_EQ(stats.frames_delivered, kFrames - injected.frames_dropped);
  EXPECT_EQ(delivered.size(), stats.frames_delivered);
  EXPECT_EQ(delivered.back(), static_cast<uint64_t>(kFrames - 1));  // continued to the end
  EXPECT_EQ(stats.no_frame_results, 3u);
  EXPECT_EQ(no_frames, 3);
  EXPECT_EQ(stats.errors, 2u);
  EXPECT_EQ(injected.errors, 2u);
  EXPECT_EQ(stats.reconnects, 2u);
  EXPECT_EQ(stats.reopen_failures, 3u);
  EXPECT_EQ(injected.failed_reopens, 3u);
  EXPECT_EQ(stats.reopen_attempts, 5u);
  // Exactly the frames that were not dropped, in order: 0-4, 7-..., missing 20-23 and 30.
  std::vector<uint64_t> expected;
  for (uint64_t s = 0; s < kFrames; ++s)
    if (s != 5 && s != 6 && !(s >= 20 && s < 24) && s != 30) expected.push_back(s);
  EXPECT_EQ(delivered, expected);
  // Backoff 50, 100, 200 ms for the three failed attempts; the transient error needed no sleep.
  EXPECT_EQ(rig->clock.sleeps_ns, (std::vector<int64_t>{50'000'000, 100'000'000, 200'000'000}));
  EXPECT_EQ(stats.time_disconnected_ns, 350'000'000);
  // What happened and when (virtual clock): the disconnect after frame 19 at t = 0, three
  // failed reopens at 0, 50 and 150 ms, back at 350 ms, then the 4 lost frames seen as a gap.
  std::vector<std::pair<SourceEventKind, int64_t>> timeline;
  for (const SourceEvent& e : stats.events) timeline.emplace_back(e.kind, e.t_ns);
  using K = SourceEventKind;
  const std::vector<std::pair<SourceEventKind, int64_t>> expected_timeline = {
      {K::kGap, 0},          {K::kError, 0},        {K::kReconnected, 0},   {K::kError, 0},
      {K::kReopenFailed, 0}, {K::kReopenFailed, 50'000'000}, {K::kReopenFailed, 150'000'000},
      {K::kReconnected, 350'000'000}, {K::kGap, 350'000'000}, {K::kGap, 350'000'000}};
  EXPECT_EQ(timeline, expected_timeline);
  const std::string report = rig->supervised->describeEvents();
  EXPECT_NE(report.find("reconnected"), std::string::npos) << report;
  EXPECT_NE(report.find("frames missing (4)"), std::string::npos) << report;
}

TEST(FaultSupervision, BackoffIsCappedAndGivesUpAfterTheBudget) {
  ResilientSourceOptions options;
  options.initial_backoff_ns = 100;
  options.backoff_multiplier = 3;
  options.max_backoff_ns = 500;
  options.max_reopen_attempts = 5;
  auto rig = makeRig({{2, FaultKind::kDisconnect, 0, /*failed reopens*/ 100}}, options);
  const std::vector<uint64_t> delivered = drain(*rig->supervised);
  EXPECT_EQ(delivered.size(), 2u);
  EXPECT_EQ(rig->clock.sleeps_ns, (std::vector<int64_t>{100, 300, 500, 500, 500}));
  EXPECT_EQ(rig->supervised->stats().reopen_failures, 5u);
  EXPECT_EQ(rig->supervised->stats().reconnects, 0u);
  EXPECT_NE(rig->supervised->lastError().message().find("gave up after 5"), std::string::npos)
      << rig->supervised->lastError().message();
}

TEST(FaultSupervision, ALongStallTriggersAReopen) {
  ResilientSourceOptions options;
  options.stall_timeout_ns = 1'000'000'000;
  auto rig = makeRig({{3, FaultKind::kStall, 5}}, options);
  RgbdImage out;
  for (int i = 0; i < 3; ++i) ASSERT_EQ(rig->supervised->next(out), SourceResult::kFrame);
  EXPECT_EQ(rig->supervised->next(out), SourceResult::kNoFrame);
  rig->clock.advance(2'000'000'000);  // the sensor stays silent for 2 s
  // The timeout fires: reopen (immediately successful: nothing failed) and the stall continues.
  EXPECT_EQ(rig->supervised->next(out), SourceResult::kNoFrame);
  EXPECT_EQ(rig->supervised->stats().stall_timeouts, 1u);
  EXPECT_EQ(rig->supervised->stats().reconnects, 1u);
  const std::vector<uint64_t> rest = drain(*rig->supervised);
  EXPECT_EQ(rest.size(), static_cast<std::size_t>(kFrames - 3));
}

TEST(FaultSupervision, ReplaysAreNotReopened) {
  // A non-live source that fails is reported as it is: no reopen loop around a broken file.
  class BrokenReplay : public test::VectorSource {
   public:
    BrokenReplay() : VectorSource({}, test::smallCamera(8, 6)) {}
    SourceResult next(RgbdImage&) override { return SourceResult::kError; }
    const Status& lastError() const override { return error_; }
    Status error_ = Status::Error("replay.plumbrec: read failed");
  };
  VirtualClock clock;
  ResilientSource supervised(std::make_unique<BrokenReplay>(), {}, clock);
  RgbdImage out;
  EXPECT_EQ(supervised.next(out), SourceResult::kError);
  EXPECT_EQ(supervised.lastError().message(), "replay.plumbrec: read failed");
  EXPECT_EQ(supervised.stats().reopen_attempts, 0u);
}

}  // namespace
}  // namespace plumb

// SIGINT while the camera is gone: the supervisor stops waiting for it, and the capture ends
// instead of asking a silent source again forever (found on the virtual-machine bench, where a
// stopped run sat out 30 reopen attempts, ~50 s).
namespace plumb {
namespace {

// Frames the capture step delivers until it ends.
int framesUntilTheCaptureEnds(SourceCapture& capture) {
  int64_t t_ns = 0;
  int frames = 0;
  while (capture.prepareNext(&t_ns)) {
    RgbdImage out;
    if (!capture.take(out).ok()) break;
    ++frames;
  }
  return frames;
}

TEST(FaultSupervision, AStopRequestEndsAReconnectionInProgress) {
  std::atomic<bool> stop{false};
  class StoppingClock : public VirtualClock {
   public:
    explicit StoppingClock(std::atomic<bool>& stop) : stop_(stop) {}
    void sleepForNs(int64_t ns) override {
      VirtualClock::sleepForNs(ns);
      if (sleeps_ns.size() == 2) stop_.store(true);  // the operator presses Ctrl-C
    }
    std::atomic<bool>& stop_;
  } clock(stop);
  auto inner = std::make_unique<test::VectorSource>(test::makeNoiseFrames(9, 8, 6, kFrames), test::smallCamera(8, 6));
  auto faulty = std::make_unique<FaultInjectingSource>(
      std::move(inner), std::vector<FaultEvent>{{3, FaultKind::kDisconnect, 4, /*failed reopens*/ 1000}});
  ResilientSource supervised(std::move(faulty), {}, clock);
  SourceCapture capture(supervised, &stop);
  EXPECT_EQ(framesUntilTheCaptureEnds(capture), 3);
  EXPECT_EQ(clock.sleeps_ns.size(), 2u) << "no reopen attempt after the stop";
  EXPECT_EQ(supervised.stats().reopen_attempts, 2u);
  EXPECT_EQ(supervised.stats().reconnects, 0u);
}

TEST(FaultSupervision, WithoutAStopASilentLiveSourceIsAskedAgain) {
  // The other side of the rule: kNoFrame alone never ends a capture.
  std::atomic<bool> stop{false};
  auto inner = std::make_unique<test::VectorSource>(test::makeNoiseFrames(9, 8, 6, 4), test::smallCamera(8, 6));
  FaultInjectingSource stalling(std::move(inner), {{1, FaultKind::kStall, 5}});
  SourceCapture capture(stalling, &stop);
  EXPECT_EQ(framesUntilTheCaptureEnds(capture), 4);
}

}  // namespace
}  // namespace plumb

// Hot-plug hints (UsbArrivalWaker calls them from its thread): an arrival cuts a backoff short; a
// departure is a disconnect at once, and reopening waits for the arrival.
namespace plumb {
namespace {

// A virtual clock that calls `hook(n)` after its n-th sleep: the camera's USB events, on time.
class HookedClock : public VirtualClock {
 public:
  void sleepForNs(int64_t ns) override {
    VirtualClock::sleepForNs(ns);
    if (hook) hook(sleeps_ns.size());
  }
  std::function<void(std::size_t)> hook;
};

struct HotplugRig {
  HookedClock clock;
  FaultInjectingSource* faulty = nullptr;
  std::unique_ptr<ResilientSource> supervised;
};

std::unique_ptr<HotplugRig> makeHotplugRig(std::vector<FaultEvent> plan, ResilientSourceOptions options) {
  auto rig = std::make_unique<HotplugRig>();
  auto inner = std::make_unique<test::VectorSource>(test::makeNoiseFrames(9, 8, 6, 10), test::smallCamera(8, 6));
  auto faulty = std::make_unique<FaultInjectingSource>(std::move(inner), std::move(plan));
  rig->faulty = faulty.get();
  options.wake_slice_ns = 20'000'000;
  rig->supervised = std::make_unique<ResilientSource>(std::move(faulty), options, rig->clock);
  return rig;
}

std::size_t countOf(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(FaultSupervision, AHotplugWakeUpEndsTheBackoffEarly) {
  ResilientSourceOptions options;
  options.initial_backoff_ns = 500'000'000;
  auto rig = makeHotplugRig({{3, FaultKind::kDisconnect, 2, /*failed reopens*/ 1}}, options);
  ResilientSource& supervised = *rig->supervised;
  rig->clock.hook = [&](std::size_t sleeps) {
    if (sleeps == 1) supervised.wakeReconnect();  // the camera arrives 20 ms into the 500 ms backoff
  };
  const std::vector<uint64_t> delivered = drain(supervised);
  EXPECT_EQ(delivered.size(), 8u);
  EXPECT_EQ(rig->clock.sleeps_ns, (std::vector<int64_t>{20'000'000})) << "woken after the first 20 ms slice";
  EXPECT_EQ(supervised.stats().hotplug_wakeups, 1u);
  EXPECT_EQ(supervised.stats().reconnects, 1u);
  EXPECT_EQ(supervised.stats().usb_departures, 0u);
  EXPECT_NE(supervised.describeEvents().find("woken by a hot-plug arrival"), std::string::npos);
}

TEST(FaultSupervision, ADepartureIsADisconnectAndTheReopenWaitsForTheArrival) {
  auto rig = makeHotplugRig({}, ResilientSourceOptions{});
  ResilientSource& supervised = *rig->supervised;
  rig->clock.hook = [&](std::size_t sleeps) {
    if (sleeps == 100) supervised.wakeReconnect();  // replugged 2 s (100 slices) later
  };
  RgbdImage out;
  for (int i = 0; i < 4; ++i) ASSERT_EQ(supervised.next(out), SourceResult::kFrame);
  supervised.deviceLeft();  // libusb: the camera left; the source itself has not failed
  std::vector<uint64_t> delivered = drain(supervised);
  EXPECT_EQ(delivered.size(), 6u) << "frames 4..9 after the reconnection";
  EXPECT_EQ(delivered.front(), 4u);
  const ResilienceStats& stats = supervised.stats();
  EXPECT_EQ(stats.usb_departures, 1u);
  EXPECT_EQ(stats.outages, 1u);
  EXPECT_EQ(stats.errors, 0u);
  EXPECT_EQ(stats.reopen_attempts, 1u) << "no reopen while the camera was off the bus";
  EXPECT_EQ(stats.reconnects, 1u);
  EXPECT_EQ(stats.hotplug_wakeups, 1u);
  EXPECT_EQ(rig->clock.sleeps_ns.size(), 100u);
  EXPECT_EQ(stats.time_disconnected_ns, 2'000'000'000);
  EXPECT_EQ(stats.longest_outage_ns, 2'000'000'000);
  EXPECT_EQ(stats.arrival_to_frame_ns, 0) << "the first frame came at the arrival's (virtual) time";
  const std::string events = supervised.describeEvents();
  EXPECT_NE(events.find("after frame 3: usb camera left"), std::string::npos) << events;
  EXPECT_NE(events.find("t=2.000s after frame 3: woken by a hot-plug arrival"), std::string::npos) << events;
  SourceSupervision s;
  ASSERT_TRUE(supervised.supervision(&s));
  EXPECT_EQ(s.usb_departures, 1u);
  EXPECT_EQ(s.usb_arrivals, 1u);
  EXPECT_EQ(s.outages, 1u);
  EXPECT_EQ(s.longest_outage_ns, 2'000'000'000);
  EXPECT_EQ(s.arrival_to_frame_ns, 0);
  EXPECT_NE(supervised.healthReport().find("longest outage 2.000 s, 0 failed reopens, usb departures 1, hot-plug wake-ups 1"),
            std::string::npos)
      << supervised.healthReport();
}

TEST(FaultSupervision, ADepartureHeardDuringAnErrorOutageIsCountedOnceAndGatesTheReopens) {
  // A real camera: the driver fails first (ENODEV), libusb's departure comes during the backoff.
  auto rig = makeHotplugRig({{3, FaultKind::kDisconnect, 0, /*failed reopens*/ 1}}, ResilientSourceOptions{});
  ResilientSource& supervised = *rig->supervised;
  rig->clock.hook = [&](std::size_t sleeps) {
    if (sleeps == 1) supervised.deviceLeft();
    if (sleeps == 40) supervised.wakeReconnect();
  };
  const std::vector<uint64_t> delivered = drain(supervised);
  EXPECT_EQ(delivered.size(), 10u);
  const ResilienceStats& stats = supervised.stats();
  EXPECT_EQ(stats.errors, 1u);
  EXPECT_EQ(stats.outages, 1u) << "the departure belongs to the outage the error started";
  EXPECT_EQ(stats.usb_departures, 1u);
  EXPECT_EQ(stats.reopen_attempts, 2u) << "one failed before the departure was heard, one after the arrival";
  EXPECT_EQ(stats.reconnects, 1u);
  EXPECT_EQ(stats.hotplug_wakeups, 1u);
  // 50 ms backoff (20 + 20 + 10), then the wait for the arrival in 20 ms slices up to sleep 40.
  EXPECT_EQ(rig->clock.sleeps_ns.size(), 40u);
  EXPECT_EQ(countOf(supervised.describeEvents(), "usb camera left"), 0u) << "no second disconnect after the reconnection";
}

TEST(FaultSupervision, WithoutTheArrivalReopeningResumesAfterTheAbsentWait) {
  ResilientSourceOptions options;
  options.absent_wait_ns = 1'000'000'000;
  auto rig = makeHotplugRig({}, options);
  ResilientSource& supervised = *rig->supervised;
  RgbdImage out;
  ASSERT_EQ(supervised.next(out), SourceResult::kFrame);
  supervised.deviceLeft();  // and no arrival is ever heard (udev restarted, say)
  const std::vector<uint64_t> delivered = drain(supervised);
  EXPECT_EQ(delivered.size(), 9u);
  const ResilienceStats& stats = supervised.stats();
  EXPECT_EQ(stats.reconnects, 1u);
  EXPECT_EQ(stats.hotplug_wakeups, 0u);
  EXPECT_EQ(stats.time_disconnected_ns, 1'000'000'000);
  EXPECT_EQ(stats.arrival_to_frame_ns, -1) << "no arrival woke this reconnection";
}

TEST(FaultSupervision, AStopEndsTheWaitForTheArrival) {
  auto rig = makeHotplugRig({}, ResilientSourceOptions{});
  ResilientSource& supervised = *rig->supervised;
  std::atomic<bool> stop{false};
  supervised.setStopFlag(&stop);
  rig->clock.hook = [&](std::size_t sleeps) {
    if (sleeps == 5) stop.store(true);
  };
  RgbdImage out;
  ASSERT_EQ(supervised.next(out), SourceResult::kFrame);
  supervised.deviceLeft();
  EXPECT_EQ(supervised.next(out), SourceResult::kNoFrame);
  EXPECT_EQ(rig->clock.sleeps_ns.size(), 5u);
  EXPECT_EQ(supervised.stats().reopen_attempts, 0u);
  EXPECT_EQ(supervised.stats().usb_departures, 1u);
  EXPECT_EQ(supervised.stats().time_disconnected_ns, 100'000'000);
}

}  // namespace
}  // namespace plumb
