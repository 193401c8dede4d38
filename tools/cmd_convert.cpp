// plumb convert: TUM/ICL folder -> .plumbrec recording, and .plumbrec -> TUM folder.
#include <chrono>
#include <cstdio>
#include <filesystem>

#include "drivers/common/atomic_file.h"
#include "drivers/open/open_source.h"
#include "drivers/recording/recording_source.h"
#include "drivers/recording/recording_writer.h"
#include "drivers/recording/tum_folder_writer.h"
#include "tools/args.h"
#include "tools/io_plan.h"
#include "tools/command.h"

namespace {

void printHelp() {
  std::printf(
      "usage: plumb convert IN OUT [--camera SPEC]\n"
      "  IN a TUM/ICL folder, OUT.plumbrec   -> a lossless recording (camera from --camera, the\n"
      "                                         folder's camera.txt, or its sensor name)\n"
      "  IN.plumbrec, OUT a new folder       -> TUM layout: rgb/ depth/ rgb.txt depth.txt\n"
      "                                         associations.txt camera.txt\n"
      "Pixels and timestamps are preserved exactly both ways. A damaged recording converts up to\n"
      "the damage it can skip; what was skipped is reported.\n");
}

int fail(const std::string& message) {
  std::fprintf(stderr, "plumb convert: %s\n", message.c_str());
  return 1;
}

int folderToRecording(const std::string& in, const std::string& out, const std::string& camera) {
  std::unique_ptr<plumb::FrameSource> source;
  plumb::Status st = plumb::openFrameSource(in, camera, &source);
  if (!st.ok()) return fail(st.message());
  // Written aside and renamed into place when complete (drivers/common/atomic_file.h): a
  // conversion that fails part-way (a bad frame, a full disk) leaves an existing recording of that
  // name as it was and no partial file behind. (`plumb record` writes in place by design: a live
  // recording must survive a power cut.)
  plumb::AtomicFile staging;
  st = staging.open(out);
  if (!st.ok()) return fail(st.message());
  std::unique_ptr<plumb::RecordingWriter> writer;
  st = plumb::RecordingWriter::open(staging.temporaryPath(), source->camera(), {}, &writer);
  if (!st.ok()) return fail(st.message());
  plumb::RgbdImage frame;
  for (;;) {
    const plumb::SourceResult r = source->next(frame);
    if (r == plumb::SourceResult::kEndOfStream) break;
    if (r != plumb::SourceResult::kFrame) return fail(source->lastError().message());
    st = writer->append(frame);
    if (!st.ok()) return fail(st.message());
  }
  st = writer->close();
  if (st.ok()) st = staging.commit();
  if (!st.ok()) return fail(st.message());
  std::printf("%s -> %s: %llu frames, %.1f MB\n", in.c_str(), out.c_str(),
              static_cast<unsigned long long>(writer->framesWritten()), writer->bytesWritten() / 1e6);
  return 0;
}

int recordingToFolder(const std::string& in, const std::string& out, const std::string& camera) {
  std::unique_ptr<plumb::FrameSource> opened;
  plumb::Status st = plumb::openFrameSource(in, camera, &opened);
  if (!st.ok()) return fail(st.message());
  auto* recording = dynamic_cast<plumb::RecordingSource*>(opened.get());
  // A conversion that fails part-way leaves no half dataset: the folder (empty or new before)
  // is emptied again, so nothing can be mistaken for a whole conversion.
  const bool folder_existed = std::filesystem::exists(out);
  auto failAndClean = [&](const std::string& message) {
    std::error_code ec;
    if (folder_existed) {
      for (const auto& entry : std::filesystem::directory_iterator(out, ec)) std::filesystem::remove_all(entry.path(), ec);
    } else {
      std::filesystem::remove_all(out, ec);
    }
    return fail(message + " (nothing was kept in " + out + ")");
  };
  std::unique_ptr<plumb::TumFolderWriter> writer;
  st = plumb::TumFolderWriter::open(out, opened->camera(), &writer);
  if (!st.ok()) return failAndClean(st.message());
  plumb::RgbdImage frame;
  for (;;) {
    const plumb::SourceResult r = opened->next(frame);
    if (r == plumb::SourceResult::kEndOfStream) break;
    if (r != plumb::SourceResult::kFrame) return failAndClean(opened->lastError().message());
    st = writer->append(frame);
    if (!st.ok()) return failAndClean(st.message());
  }
  st = writer->close();
  if (!st.ok()) return failAndClean(st.message());
  std::printf("%s -> %s: %llu frames\n", in.c_str(), out.c_str(),
              static_cast<unsigned long long>(writer->framesWritten()));
  if (recording) {
    const plumb::RecordingStats& s = recording->stats();
    if (s.chunks_skipped > 0 || s.truncated_tail_bytes > 0 || !s.end_chunk_seen)
      std::printf("damage: %llu chunks skipped (%llu bytes), %llu truncated tail bytes, %s; last: %s\n",
                  static_cast<unsigned long long>(s.chunks_skipped),
                  static_cast<unsigned long long>(s.bytes_skipped),
                  static_cast<unsigned long long>(s.truncated_tail_bytes),
                  s.end_chunk_seen ? "closed properly" : "not closed properly",
                  s.last_damage.empty() ? "-" : s.last_damage.c_str());
  }
  return 0;
}

int runConvert(int argc, char** argv) {
  const plumb::tools::Args args(argc, argv, {"camera"}, {});
  if (args.help()) {
    printHelp();
    return 0;
  }
  if (!args.error().empty() || args.positional().size() != 2) {
    std::fprintf(stderr, "plumb convert: %s (see plumb convert --help)\n",
                 args.error().empty() ? "need IN and OUT" : args.error().c_str());
    return 2;
  }
  const std::string in = args.positional()[0], out = args.positional()[1];
  const bool in_is_folder = std::filesystem::is_directory(in);
  const bool out_is_recording = out.size() > 9 && out.compare(out.size() - 9, 9, ".plumbrec") == 0;
  const bool in_is_recording = in.size() > 9 && in.compare(in.size() - 9, 9, ".plumbrec") == 0;
  // Never write over the input (same file, or a file of the input folder) or into a folder that
  // already holds a dataset.
  if (out_is_recording) {
    plumb::tools::IoPlan io;
    io.addInput(in);
    io.addInput(args.get("camera"));
    io.addOutput("OUT", out);
    const plumb::Status st = io.check();
    if (!st.ok()) {
      std::fprintf(stderr, "plumb convert: %s\n", st.message().c_str());
      return 2;
    }
  } else {
    std::error_code ec;
    if (std::filesystem::exists(out, ec) && (!std::filesystem::is_directory(out, ec) || !std::filesystem::is_empty(out, ec))) {
      std::fprintf(stderr, "plumb convert: OUT %s exists and is not an empty folder: refusing to write over it\n",
                   out.c_str());
      return 2;
    }
  }
  if (in_is_folder && out_is_recording) return folderToRecording(in, out, args.get("camera"));
  if (in_is_recording && !out_is_recording) return recordingToFolder(in, out, args.get("camera"));
  return fail("convert a folder to FILE.plumbrec, or FILE.plumbrec to a folder (got '" + in +
              "' -> '" + out + "')");
}

}  // namespace

PLUMB_COMMAND(convert, "convert a TUM/ICL folder to a .plumbrec recording and back", runConvert);
