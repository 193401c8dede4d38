// libFuzzer target for the .plumbrec reader: any bytes as a recording file must open cleanly or
// fail with a Status, and replay must end without crashing, hanging or reading out of bounds.
// Build (not part of the default build): see fuzz/CMakeLists.txt.
#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>

#include "drivers/recording/recording_source.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // An in-memory file, reachable by path for the reader's fopen().
  const int fd = memfd_create("plumbrec", 0);
  if (fd < 0) return 0;
  if (size > 0 && write(fd, data, size) != static_cast<ssize_t>(size)) {
    close(fd);
    return 0;
  }
  const std::string path = "/proc/self/fd/" + std::to_string(fd);
  std::unique_ptr<plumb::RecordingSource> source;
  if (plumb::RecordingSource::open(path, &source).ok()) {
    plumb::RgbdImage frame;
    for (int i = 0; i < 1000 && source->next(frame) == plumb::SourceResult::kFrame; ++i) {
    }
    const plumb::RecordingStats& stats = source->stats();
    if (stats.bytes_skipped + stats.truncated_tail_bytes > size) __builtin_trap();
  }
  source.reset();
  close(fd);
  return 0;
}
