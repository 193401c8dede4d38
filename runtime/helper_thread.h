#pragma once
// HelperThread: one helper thread to hand half of a job to, for work that splits into two
// independent parts.
//
// runBoth(here, there): `there` runs on the helper (started on first use, kept until
// destruction), `here` on the caller; returns when both are done, with everything `there` wrote
// visible to the caller. Handshake through two Doorbells (no mutex; no allocation after the
// thread is started). Not reentrant: one caller thread at a time.
//
// Used by the synthetic renderer (drivers/synth/frame_renderer.h) on frames that paint faces:
// half of the faces painted by each thread, every other band of rows shaded by each, for the
// first frame's latency (docs/EMBEDDED.md "First pose"). Both parts run the same code on the same inputs whichever
// thread runs them, so results are byte-identical to one thread's.
#include <atomic>
#include <cstdint>
#include <thread>
#include <type_traits>

#include "runtime/doorbell.h"

namespace plumb::runtime {

class HelperThread {
 public:
  HelperThread() = default;
  ~HelperThread();
  HelperThread(const HelperThread&) = delete;
  HelperThread& operator=(const HelperThread&) = delete;

  template <class Here, class There>
  void runBoth(Here&& here, There&& there) {
    waitDone();  // a job from startJob()
    if (!started()) {  // no thread to be had: both parts here, one after the other
      here();
      there();
      return;
    }
    post(&call<std::remove_reference_t<There>>, &there);
    here();
    waitDone();
  }

  // Returns when the helper is idle (a job from startJob() done).
  void wait() { waitDone(); }

  // Starts job(context) on the helper and returns at once; the next runBoth() (or destruction)
  // waits for it. context must stay valid until then. False (nothing run) if no thread can be had.
  bool startJob(void (*job)(void*), void* context) {
    waitDone();
    if (!started()) return false;
    post(job, context);
    return true;
  }

 private:
  template <class F>
  static void call(void* f) {
    (*static_cast<F*>(f))();
  }
  bool started();  // starts the thread on first use; false if it cannot be started
  void post(void (*job)(void*), void* context);
  void waitDone();
  void helperMain();

  std::thread thread_;
  Doorbell posted_bell_, done_bell_;
  // The job: written by the caller before posted_ is bumped (release), read by the helper after
  // it sees the bump (acquire).
  void (*job_)(void*) = nullptr;
  void* context_ = nullptr;
  std::atomic<uint64_t> posted_{0};
  std::atomic<uint64_t> done_{0};
  std::atomic<bool> stop_{false};
  bool unavailable_ = false;  // starting the thread failed once: do not retry every call
};

}  // namespace plumb::runtime
