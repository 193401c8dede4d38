#pragma once
// The two interfaces a pipeline is built from. The runtime knows nothing about what a frame is:
// T is the slot payload (for plumb, an RGB-D frame with its features and pose), and every stage
// works on it in place.
//
//   Source<T>: the capture end (dataset replay, device, synthetic scene). Stage 0.
//   Stage<T>:  one pure step per frame (extract, track, map, ...). Stages 1..N.
//
// Stages read what earlier stages wrote into the payload and write their own part. A stage does
// not know which thread runs it, nor whether the run is threaded or lock-step: the StageRunner owns
// threads, rings, timing, end of stream and error propagation.
#include <cstdint>

#include "platform/status.h"
#include "runtime/frame_stamps.h"

namespace plumb::runtime {

template <typename T>
class Stage {
 public:
  virtual ~Stage() = default;
  // Short name: thread name, trace track, table row.
  virtual const char* name() const = 0;
  // Processes one frame in place. Must not allocate once warmed up. A non-OK Status stops the
  // pipeline: the error travels downstream, later frames are passed through unprocessed so their
  // slots return to the pool, and the source stops reading.
  virtual Status process(T& payload, const FrameStamps& stamps) = 0;
  // End of stream reached this stage: every earlier frame has been processed. Flush here.
  virtual void finish() {}
};

template <typename T>
class Source {
 public:
  virtual ~Source() = default;
  virtual const char* name() const { return "capture"; }
  // Recording timestamp of the next frame, without consuming it; false at end of stream. A replay
  // source is paced against these in real-time mode.
  virtual bool peekNext(int64_t* t_recorded_ns) = 0;
  // Consumes the peeked frame into payload.
  virtual Status read(T& payload, const FrameStamps& stamps) = 0;
  // Consumes the peeked frame without decoding it (real-time mode: no free slot, frame dropped).
  virtual void skip() = 0;
  // True once the source was asked to stop (a SIGINT): real-time pacing waits in slices and gives
  // up the wait when this turns true, so a recorded gap of days never outlasts a stop request.
  virtual bool stopRequested() { return false; }
};

}  // namespace plumb::runtime
