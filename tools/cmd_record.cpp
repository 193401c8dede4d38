// plumb record: records any frame source into a crash-safe .plumbrec file (drivers/recording).
#include <chrono>
#include <csignal>
#include <cstdio>

#include "drivers/open/open_source.h"
#include "tools/io_plan.h"
#include "drivers/recording/recording_writer.h"
#include "tools/args.h"
#include "tools/command.h"

namespace {

volatile std::sig_atomic_t g_stop_requested = 0;
void requestStop(int) { g_stop_requested = 1; }

void printHelp() {
  std::printf(
      "usage: plumb record --source SPEC --out FILE.plumbrec [options]\n"
      "Records RGB-D frames losslessly, in CRC-checked chunks with a periodic index: a file cut\n"
      "off by a power loss replays up to its last complete frame (format: docs/DRIVERS.md).\n"
      "Ctrl-C stops recording and closes the file cleanly.\n\n"
      "  --source SPEC    TUM/ICL folder, synth:PRESET[:SEED[:FRAMES]], FILE.plumbrec, FILE.oni,\n"
      "                   openni2:first, openni2:URI, v4l2:/dev/videoN[,/dev/videoM][:FORMAT]\n"
      "  --camera SPEC    camera preset (tum1 tum2 tum3 icl) or camera file, where the source needs one\n"
      "  --out FILE       output recording (overwritten)\n"
      "  --frames N       stop after N frames (default: until the source ends)\n"
      "  --codec C        auto (default: raw for live sensors, png otherwise), raw or png; both\n"
      "                   lossless. png is ~3x smaller but costs ~20 ms of CPU per 640x480 frame,\n"
      "                   most of a 30 Hz frame period; raw needs ~46 MB/s of disk at 30 Hz\n"
      "  --fsync P        never | index (default: after every index chunk) | frame\n");
}

int fail(const std::string& message) {
  std::fprintf(stderr, "plumb record: %s\n", message.c_str());
  return 1;
}

int runRecord(int argc, char** argv) {
  const plumb::tools::Args args(argc, argv, {"source", "camera", "out", "frames", "codec", "fsync"}, {});
  if (args.help()) {
    printHelp();
    return 0;
  }
  if (!args.error().empty() || !args.has("source") || !args.has("out") || !args.positional().empty()) {
    std::fprintf(stderr, "plumb record: %s (see plumb record --help)\n",
                 args.error().empty() ? "need --source SPEC and --out FILE" : args.error().c_str());
    return 2;
  }
  bool ok = true;
  const long max_frames = args.getInt("frames", -1, &ok);
  plumb::RecordingWriterOptions options;
  const std::string codec = args.get("codec", "auto");
  const std::string fsync = args.get("fsync", "index");
  if (codec != "auto" && codec != "raw" && codec != "png") ok = false;
  if (fsync == "never") options.fsync = plumb::FsyncPolicy::kNever;
  else if (fsync == "frame") options.fsync = plumb::FsyncPolicy::kEveryFrame;
  else if (fsync != "index") ok = false;
  if (!ok || max_frames == 0 || max_frames < -1) {
    std::fprintf(stderr, "plumb record: bad --frames, --codec or --fsync (see plumb record --help)\n");
    return 2;
  }

  // The recording is written in place (crash-safe append, readable after a power cut), so it must
  // never be one of the inputs: checked before anything is opened for writing.
  plumb::tools::IoPlan io;
  io.addInput(args.get("source"));
  io.addInput(args.get("camera"));
  io.addOutput("--out", args.get("out"));
  plumb::Status st = io.check();
  if (!st.ok()) {
    std::fprintf(stderr, "plumb record: %s\n", st.message().c_str());
    return 2;
  }
  std::unique_ptr<plumb::FrameSource> source;
  st = plumb::openFrameSource(args.get("source"), args.get("camera"), &source);
  if (!st.ok()) return fail(st.message());
  if (codec == "raw" || (codec == "auto" && source->isLive()))
    options.colour_codec = options.depth_codec = plumb::ImageCodec::kRaw;
  std::unique_ptr<plumb::RecordingWriter> writer;
  st = plumb::RecordingWriter::open(args.get("out"), source->camera(), options, &writer);
  if (!st.ok()) return fail(st.message());

  std::signal(SIGINT, requestStop);
  const auto start = std::chrono::steady_clock::now();
  plumb::RgbdImage frame;
  uint64_t no_frame_results = 0;
  int exit_code = 0;
  while (!g_stop_requested && (max_frames < 0 || static_cast<long>(writer->framesWritten()) < max_frames)) {
    const plumb::SourceResult r = source->next(frame);
    if (r == plumb::SourceResult::kEndOfStream) break;
    if (r == plumb::SourceResult::kNoFrame) {
      ++no_frame_results;
      continue;
    }
    if (r == plumb::SourceResult::kError) {
      std::fprintf(stderr, "plumb record: source failed: %s\n", source->lastError().message().c_str());
      exit_code = 1;
      break;
    }
    st = writer->append(frame);
    if (!st.ok()) {
      std::fprintf(stderr, "plumb record: %s\n", st.message().c_str());
      exit_code = 1;
      break;
    }
  }
  std::signal(SIGINT, SIG_DFL);
  st = writer->close();
  if (!st.ok()) return fail(st.message());
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("recorded %llu frames from %s to %s: %.1f MB in %.2f s (%.1f frames/s)%s\n",
              static_cast<unsigned long long>(writer->framesWritten()), source->describe().c_str(),
              args.get("out").c_str(), writer->bytesWritten() / 1e6, seconds,
              writer->framesWritten() / std::max(seconds, 1e-9),
              g_stop_requested ? " (stopped by Ctrl-C)" : "");
  if (no_frame_results > 0)
    std::printf("source timeouts (no frame): %llu\n", static_cast<unsigned long long>(no_frame_results));
  const std::string health = source->healthReport();
  if (!health.empty()) std::printf("%s\n", health.c_str());
  const plumb::SourceDamage damage = source->damage();
  if (damage.any()) {
    std::fprintf(stderr,
                 "plumb record: WARNING: the input is damaged: %llu damaged region(s) skipped (%llu bytes), %llu "
                 "bytes of incomplete tail, %s; last: %s. Frames in damaged regions are not in the recording.\n",
                 static_cast<unsigned long long>(damage.regions_skipped),
                 static_cast<unsigned long long>(damage.bytes_skipped),
                 static_cast<unsigned long long>(damage.truncated_tail_bytes),
                 damage.closed_properly ? "closed properly" : "not closed properly",
                 damage.last.empty() ? "-" : damage.last.c_str());
  }
  return exit_code;
}

}  // namespace

PLUMB_COMMAND(record, "record any source into a crash-safe .plumbrec file", runRecord);
