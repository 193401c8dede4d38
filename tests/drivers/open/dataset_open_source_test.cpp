// openFrameSource: the specification strings of the command line.
#include <gtest/gtest.h>

#include "drivers/open/open_source.h"

namespace plumb {
namespace {

TEST(OpenFrameSource, SyntheticSpecRendersTheRequestedFrames) {
  std::unique_ptr<FrameSource> source;
  const Status st = openFrameSource("synth:low_texture:7:2", "", &source);
  ASSERT_TRUE(st.ok()) << st.message();
  EXPECT_FALSE(source->isLive());
  RgbdImage frame;
  EXPECT_EQ(source->next(frame), SourceResult::kFrame);
  EXPECT_EQ(frame.bgr.cols, source->camera().width);
  EXPECT_EQ(frame.depth_raw.type(), CV_16UC1);
  EXPECT_EQ(source->next(frame), SourceResult::kFrame);
  EXPECT_EQ(source->next(frame), SourceResult::kEndOfStream);
}

void expectSpecError(const std::string& spec, const std::string& camera, const std::string& words) {
  std::unique_ptr<FrameSource> source;
  const Status st = openFrameSource(spec, camera, &source);
  ASSERT_FALSE(st.ok()) << spec;
  EXPECT_NE(st.message().find(words), std::string::npos) << st.message();
  EXPECT_EQ(source, nullptr);
}

TEST(OpenFrameSource, BadSpecificationsAreClearErrors) {
  expectSpecError("", "", "empty source");
  expectSpecError("synth:", "", "synth:PRESET");
  expectSpecError("synth:textured:x", "", "seed 'x'");
  expectSpecError("synth:textured:1:0", "", "frames '0'");
  expectSpecError("synth:textured:1:10:9", "", "synth:PRESET");
  expectSpecError("synth:no_such_preset", "", "synth:no_such_preset");
  expectSpecError("synth:textured", "tum1", "own camera");
  expectSpecError("/nonexistent/rgbd_dataset_freiburg1_desk", "", "not a TUM RGB-D folder");
}

}  // namespace
}  // namespace plumb
