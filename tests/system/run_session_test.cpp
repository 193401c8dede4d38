// RunSession (pipeline/run/run_session.h): the one owner of a run's objects and of its end-of-run
// protocol. Pushing frames with step() gives exactly what run() gives (the public API relies on it,
// tests/api compares them through the API); here: what a session refuses, and that a refused run
// never reaches the sink's begin() (so `plumb run` creates no file for it).
#include <gtest/gtest.h>

#include <memory>

#include "drivers/common/source_capture.h"
#include "drivers/synth/synthetic_scene.h"
#include "pipeline/run/run_session.h"

namespace plumb {
namespace {

class CountingSink final : public OdometrySink {
 public:
  Status begin(const OdometrySystem&) override {
    ++begins;
    return begin_status;
  }
  Status onFinishedFrame(const FinishedFrame&) override {
    ++finished;
    return Status::Ok();
  }
  Status begin_status;
  int begins = 0, finished = 0;
};

std::unique_ptr<SyntheticSource> textured(int frames) {
  SynthOptions o;
  o.preset = "textured";
  o.frames = frames;
  std::unique_ptr<SyntheticSource> source;
  EXPECT_TRUE(SyntheticSource::create(o, &source).ok());
  return source;
}

TEST(RunSession, StepAndFinishDeliverEveryFrameAndRefuseMisuse) {
  auto source = textured(5);
  CountingSink sink;
  std::unique_ptr<RunSession> session;
  ASSERT_TRUE(RunSession::create(source->camera(), SystemOptions{}, sink, OdometryRunOptions{}, &session).ok());
  EXPECT_EQ(sink.begins, 1);
  for (int i = 0; i < 5; ++i) {
    RgbdImage& image = session->slot().image;
    ASSERT_EQ(source->next(image), SourceResult::kFrame);
    ASSERT_TRUE(session->step().ok());
  }
  EXPECT_EQ(session->frames(), 5u);
  SourceCapture capture(*source);
  const Status run_after_step = session->run(capture);
  EXPECT_FALSE(run_after_step.ok());
  EXPECT_NE(run_after_step.message().find("run()"), std::string::npos) << run_after_step.message();
  ASSERT_TRUE(session->finish().ok());
  EXPECT_EQ(sink.finished, 5);  // every held-back pose
  EXPECT_TRUE(session->finish().ok());  // idempotent
  EXPECT_EQ(sink.finished, 5);
  EXPECT_EQ(session->result().frames, 5u);
  EXPECT_FALSE(session->step().ok());
}

TEST(RunSession, StepNeedsTheLockStepSchedule) {
  auto source = textured(1);
  CountingSink sink;
  OdometryRunOptions options;
  options.schedule.mode = runtime::RunMode::kFast;
  std::unique_ptr<RunSession> session;
  ASSERT_TRUE(RunSession::create(source->camera(), SystemOptions{}, sink, options, &session).ok());
  ASSERT_EQ(source->next(session->slot().image), SourceResult::kFrame);
  const Status st = session->step();
  EXPECT_FALSE(st.ok());
  EXPECT_NE(st.message().find("lock-step"), std::string::npos) << st.message();
}

TEST(RunSession, ARefusedRunNeverReachesTheSink) {
  auto source = textured(1);
  CountingSink sink;
  std::unique_ptr<RunSession> session;
  OdometryRunOptions bad_run;
  bad_run.max_frames = 0;
  EXPECT_FALSE(RunSession::create(source->camera(), SystemOptions{}, sink, bad_run, &session).ok());
  SystemOptions bad_system;
  bad_system.output_delay_frames = -1;
  EXPECT_FALSE(RunSession::create(source->camera(), bad_system, sink, OdometryRunOptions{}, &session).ok());
  PinholeCamera tiny = source->camera();
  tiny.width = 32;
  EXPECT_FALSE(RunSession::create(tiny, SystemOptions{}, sink, OdometryRunOptions{}, &session).ok());
  EXPECT_EQ(sink.begins, 0);
  EXPECT_EQ(session, nullptr);
  // The sink's own refusal ends the run before any frame.
  sink.begin_status = Status::Error("cannot open the output");
  const Status st = RunSession::create(source->camera(), SystemOptions{}, sink, OdometryRunOptions{}, &session);
  EXPECT_FALSE(st.ok());
  EXPECT_EQ(st.message(), "cannot open the output");
}

}  // namespace
}  // namespace plumb
