// `plumb eval` from the command line: the published answers, JSON output, the plot, and bad input
// (non-zero exit and a message naming the file).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "tests/support/plumb_cli.h"

namespace {

using plumb::test::runPlumb;
using plumb::test::RunResult;

const std::string kReference = PLUMB_DATASETS_DIR "/reference_trajectories";

bool haveReferenceTrajectories() { return std::filesystem::is_directory(kReference); }

TEST(EvalCli, Freiburg1XyzGivesThePublishedAte) {
  if (!haveReferenceTrajectories()) GTEST_SKIP() << kReference << " not found: skipping";
  const RunResult r = runPlumb("eval --gt " + kReference + "/freiburg1_xyz-groundtruth.txt --est " +
                               kReference + "/freiburg1_xyz-rgbdslam.txt");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("ATE RMSE 0.0135 m over 786 pairs"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("RPE translation RMSE"), std::string::npos) << r.output;
}

TEST(EvalCli, Freiburg2DeskJsonAndPlot) {
  if (!haveReferenceTrajectories()) GTEST_SKIP() << kReference << " not found: skipping";
  plumb::test::ScratchDir dir{"plumb_eval"};
  const std::string plot = dir.file("plot.png");
  const RunResult r = runPlumb("eval --json --gt " + kReference + "/fr2_desk_groundtruth.txt --est " +
                               kReference + "/fr2_desk_ORB.txt --plot " + plot);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::size_t rmse_at = r.output.find("\"rmse_m\": ");
  ASSERT_NE(rmse_at, std::string::npos) << r.output;
  const double rmse = std::strtod(r.output.c_str() + rmse_at + 10, nullptr);
  EXPECT_NEAR(rmse, 0.0081, 0.0001);
  EXPECT_NE(r.output.find("\"pairs\": 2223"), std::string::npos) << r.output;
  // The ground truth has one duplicated stamp; the tool says what it did with it.
  EXPECT_NE(r.output.find("duplicate timestamp"), std::string::npos) << r.output;
  const cv::Mat image = cv::imread(plot, cv::IMREAD_COLOR);
  ASSERT_FALSE(image.empty()) << "no plot written to " << plot;
  EXPECT_GE(image.cols, 300);
  // Not a blank canvas: the drawing put both trajectory colours on it.
  cv::Mat not_white;
  cv::inRange(image, cv::Scalar(0, 0, 0), cv::Scalar(250, 250, 250), not_white);
  EXPECT_GT(cv::countNonZero(not_white), image.total() / 100);
}

// Values near the double range overflow the statistics: the JSON must stay JSON (null, never inf).
TEST(EvalCli, JsonIsValidWhenTheNumbersOverflow) {
  plumb::test::ScratchDir dir{"plumb_eval"};
  const std::string gt = dir.write("gt.txt", "1.0 1e308 0 0 0 0 0 1\n2.0 -1e308 0 0 0 0 0 1\n3.0 1e308 1e308 0 0 0 0 1\n");
  const std::string est = dir.write("est.txt", "1.0 0 0 0 0 0 0 1\n2.0 1 0 0 0 0 0 1\n3.0 2 1 0 0 0 0 1\n");
  const RunResult r = runPlumb("eval --gt " + gt + " --est " + est + " --json");
  if (r.exit_code == 0) {
    EXPECT_EQ(r.output.find("inf"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("nan"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("\"rmse_m\": "), std::string::npos) << r.output;
  } else {
    EXPECT_FALSE(r.output.empty());  // refused with a message: also acceptable
  }
}

// Saturated-colour pixels: the trajectory curves (axes, grid and text are grey or black).
int colouredPixels(const cv::Mat& image) {
  int count = 0;
  for (int r = 0; r < image.rows; ++r) {
    for (int c = 0; c < image.cols; ++c) {
      const cv::Vec3b p = image.at<cv::Vec3b>(r, c);
      const int hi = std::max({p[0], p[1], p[2]}), lo = std::min({p[0], p[1], p[2]});
      count += hi - lo > 80;
    }
  }
  return count;
}

// ICL-NUIM's TUM-format files have timestamps 1 s apart: the curves must still be drawn (a fixed
// 0.5 s gap rule once broke them at every sample and left empty axes).
TEST(EvalCli, PlotDrawsCurvesForSamplesOneSecondApart) {
  plumb::test::ScratchDir dir{"plumb_eval"};
  std::string gt, est;
  for (int i = 0; i < 40; ++i) {
    const double a = 0.15 * i;
    char line[160];
    std::snprintf(line, sizeof(line), "%d.0 %.4f %.4f 0 0 0 0 1\n", i, std::cos(a), std::sin(a));
    gt += line;
    std::snprintf(line, sizeof(line), "%d.0 %.4f %.4f 0.01 0 0 0 1\n", i, 1.02 * std::cos(a), std::sin(a));
    est += line;
  }
  const std::string plot = dir.file("icl.png");
  const RunResult r = runPlumb("eval --gt " + dir.write("gt.txt", gt) + " --est " + dir.write("est.txt", est) +
                               " --plot " + plot);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const cv::Mat image = cv::imread(plot, cv::IMREAD_COLOR);
  ASSERT_FALSE(image.empty());
  const int coloured = colouredPixels(image);
  std::printf("coloured pixels: %d\n", coloured);
  EXPECT_GT(coloured, 5000) << "the trajectory curves are missing (old rule: 335 px, legend only)";
}

TEST(EvalCli, MissingFileExitsNonZeroNamingIt) {
  plumb::test::ScratchDir dir{"plumb_eval"};
  const std::string gt = dir.write("gt.txt", "1.0 0 0 0 0 0 0 1\n");
  const RunResult r = runPlumb("eval --gt " + gt + " --est " + dir.file("missing_est.txt"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find(dir.file("missing_est.txt")), std::string::npos) << r.output;
}

TEST(EvalCli, CorruptFileExitsNonZeroNamingFileAndLine) {
  plumb::test::ScratchDir dir{"plumb_eval"};
  const std::string gt = dir.write("gt.txt", "1.0 0 0 0 0 0 0 1\n2.0 0 0 0 0 0 0 1\n3.0 0 0 0 0 0 0 1\n");
  const std::string est = dir.write("est.txt", "1.0 0 0 0 0 0 0 1\n2.0 0 0 0 0 0 0 1\n3.0 0 0 nan 0 0 0 1\n");
  RunResult r = runPlumb("eval --gt " + gt + " --est " + est);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find(est + ":3"), std::string::npos) << r.output;

  const std::string binary = dir.write("binary.txt", std::string("\x89PNG\r\n\x1a\n\0\0\0", 11));
  r = runPlumb("eval --gt " + binary + " --est " + gt);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find(binary), std::string::npos) << r.output;
}

TEST(EvalCli, UnrelatedTrajectoriesAreAnErrorNotANumber) {
  plumb::test::ScratchDir dir{"plumb_eval"};
  const std::string gt = dir.write("gt.txt", "1.0 0 0 0 0 0 0 1\n2.0 1 0 0 0 0 0 1\n3.0 2 0 0 0 0 0 1\n");
  const std::string est =
      dir.write("est.txt", "71.0 0 0 0 0 0 0 1\n72.0 1 0 0 0 0 0 1\n73.0 2 0 0 0 0 0 1\n");
  const RunResult r = runPlumb("eval --gt " + gt + " --est " + est);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_EQ(r.output.find("ATE RMSE"), std::string::npos) << r.output;
}

TEST(EvalCli, UnwritablePlotIsAnErrorNamingThePath) {
  plumb::test::ScratchDir dir{"plumb_eval"};
  std::string poses;
  for (int i = 0; i < 40; ++i)
    poses += std::to_string(1.0 + 0.1 * i) + " " + std::to_string(0.01 * i) + " 0 0 0 0 0 1\n";
  const std::string gt = dir.write("gt.txt", poses);
  // A folder that does not exist is refused before any work, as by every command's output check
  // (tools/io_plan.h: a usage error, 2); a name that is not a .png fails when the plot is made.
  for (const auto& [plot, code] : {std::pair<std::string, int>{dir.file("no_such_folder/plot.png"), 2},
                                   std::pair<std::string, int>{dir.file("plot.jpgx"), 1}}) {
    const RunResult r = runPlumb("eval --gt " + gt + " --est " + gt + " --plot " + plot);
    EXPECT_EQ(r.exit_code, code) << r.output;
    EXPECT_NE(r.output.find(plot), std::string::npos) << r.output;
  }
}

TEST(EvalCli, UsageErrorsExitWithTwo) {
  EXPECT_EQ(runPlumb("eval").exit_code, 2);
  EXPECT_EQ(runPlumb("eval --gt a.txt").exit_code, 2);
  EXPECT_EQ(runPlumb("eval --gt a.txt --est b.txt --bogus").exit_code, 2);
  EXPECT_EQ(runPlumb("eval --help").exit_code, 0);
}

}  // namespace
