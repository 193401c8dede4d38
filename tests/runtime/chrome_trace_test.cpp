#include "runtime/chrome_trace.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

#include "runtime/json_reader.h"
#include "runtime/stage_runner.h"
#include "toy_pipeline.h"

namespace plumb::runtime {
namespace {

using testing::FoldStage;
using testing::MixStage;
using testing::ToyFrame;
using testing::ToySource;

constexpr int64_t kMs = 1'000'000;

// A reproducible run with drops: see realtime_simulation_test for the schedule.
struct SimulatedRun {
  VirtualClock clock;
  ToySource source{10, 10 * kMs};
  MixStage mix{&clock, 25 * kMs};
  FoldStage fold{10, -1, &clock, 1 * kMs};
  std::unique_ptr<StageRunner<ToyFrame>> runner;
  SimulatedRun() {
    RunOptions options;
    options.mode = RunMode::kRealtime;
    options.slot_count = 2;
    options.clock = &clock;
    runner = std::make_unique<StageRunner<ToyFrame>>(source, std::vector<Stage<ToyFrame>*>{&mix, &fold}, options);
    EXPECT_TRUE(runner->run().ok());
  }
};

TEST(ChromeTrace, IsWellFormedJsonWithOneTrackPerStage) {
  SimulatedRun run;
  const std::string text = formatChromeTrace(run.runner->trace(), run.runner->report());
  JsonValue root;
  const Status parsed = parseJson(text, &root);
  ASSERT_TRUE(parsed.ok()) << parsed.message();
  const JsonValue* events = root.find("traceEvents");
  ASSERT_NE(events, nullptr);
  int spans[3] = {0, 0, 0};
  int drops = 0, begins = 0, ends = 0;
  std::vector<std::string> thread_names(3);
  for (const JsonValue& e : events->items) {
    const std::string ph = e.find("ph")->string;
    const int tid = static_cast<int>(e.find("tid")->number);
    ASSERT_GE(tid, 0);
    ASSERT_LT(tid, 3);
    if (ph == "M" && e.find("name")->string == "thread_name") {
      thread_names[tid] = e.find("args")->find("name")->string;
    } else if (ph == "X") {
      ++spans[tid];
      ASSERT_NE(e.find("args")->find("frame"), nullptr);
      EXPECT_GE(e.find("dur")->number, 0.0);
    } else if (ph == "i") {
      ++drops;
    } else if (ph == "b") {
      ++begins;
    } else if (ph == "e") {
      ++ends;
    }
  }
  EXPECT_EQ(thread_names, (std::vector<std::string>{"capture", "mix", "fold"}));
  EXPECT_EQ(spans[0], 5);
  EXPECT_EQ(spans[1], 5);
  EXPECT_EQ(spans[2], 5);
  EXPECT_EQ(drops, 5);
  EXPECT_EQ(begins, 5);
  EXPECT_EQ(ends, 5);
  // ts/dur are microseconds: mix's first step is 25 ms long.
  for (const JsonValue& e : events->items) {
    if (e.find("ph")->string == "X" && e.find("tid")->number == 1) {
      EXPECT_DOUBLE_EQ(e.find("dur")->number, 25000.0);
      break;
    }
  }
}

TEST(ChromeTrace, ReadingTheFileBackReproducesTheReport) {
  SimulatedRun run;
  const std::string path = std::string(PLUMB_BINARY_DIR) + "/chrome_trace_test.json";
  ASSERT_TRUE(writeChromeTrace(path, run.runner->trace(), run.runner->report()).ok());
  RunReport back;
  const Status status = readChromeTrace(path, &back);
  ASSERT_TRUE(status.ok()) << status.message();
  const RunReport& original = run.runner->report();
  EXPECT_EQ(back.mode, "realtime");
  EXPECT_EQ(back.frames_dropped, original.frames_dropped);
  EXPECT_EQ(back.frames_completed, original.frames_completed);
  EXPECT_EQ(back.wall_ns, original.wall_ns);
  ASSERT_EQ(back.stages.size(), original.stages.size());
  for (std::size_t s = 0; s < back.stages.size(); ++s) {
    EXPECT_EQ(back.stages[s].name, original.stages[s].name);
    EXPECT_EQ(back.stages[s].latency.count(), original.stages[s].latency.count());
    EXPECT_EQ(back.stages[s].latency.maxNs(), original.stages[s].latency.maxNs());
    EXPECT_EQ(back.stages[s].latency.percentileNs(0.5), original.stages[s].latency.percentileNs(0.5));
  }
  EXPECT_EQ(back.end_to_end.count(), original.end_to_end.count());
  EXPECT_EQ(back.end_to_end.maxNs(), original.end_to_end.maxNs());
  EXPECT_EQ(formatRunReport(back), formatRunReport(original));
  std::remove(path.c_str());
}

TEST(ChromeTrace, BadFilesAreClearErrorsNamingTheFile) {
  RunReport report;
  Status missing = readChromeTrace("/nonexistent/trace.json", &report);
  EXPECT_FALSE(missing.ok());
  EXPECT_NE(missing.message().find("/nonexistent/trace.json"), std::string::npos);

  const std::string path = std::string(PLUMB_BINARY_DIR) + "/chrome_trace_bad.json";
  std::ofstream(path) << "{\"traceEvents\":[\n{\"ph\":\"X\",\"tid\":1,\"ts\":1}\n,]}";
  const Status bad = readChromeTrace(path, &report);
  EXPECT_FALSE(bad.ok());
  EXPECT_NE(bad.message().find(path), std::string::npos) << bad.message();
  std::remove(path.c_str());

  EXPECT_FALSE(parseChromeTrace("{\"traceEvents\":[{\"ph\":\"X\",\"tid\":1,\"ts\":1}]}", &report).ok())
      << "a complete event without dur must be refused";
  EXPECT_FALSE(parseChromeTrace("[]", &report).ok());
}

TEST(RunReportTable, PrintsEveryStageAndTheCounters) {
  SimulatedRun run;
  const std::string table = formatRunReport(run.runner->report());
  for (const char* needle : {"capture", "mix", "fold", "end-to-end", "p99 ms", "5 dropped"}) {
    EXPECT_NE(table.find(needle), std::string::npos) << needle << "\n" << table;
  }
}

}  // namespace
}  // namespace plumb::runtime
