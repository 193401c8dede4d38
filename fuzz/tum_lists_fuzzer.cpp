// libFuzzer target for the TUM list readers (drivers/dataset/tum_lists.h): the same bytes are read
// as an image list (rgb.txt / depth.txt) and as associations.txt. Beyond "no crash", an accepted
// list must keep the readers' promises and survive a write/read round trip:
//  - not empty, timestamps finite, non-negative and strictly increasing, paths non-empty;
//  - written back with %.17g timestamps, it reads to the same values bit for bit;
//  - an image list associated with itself pairs every entry with itself (difference 0 wins).
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "drivers/dataset/tum_lists.h"
#include "fuzz/fuzz_support.h"

namespace {

using plumb::fuzz::MemFile;

std::string stamp(double t) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.17g", t);
  return text;
}

void checkStamp(double t) {
  FUZZ_CHECK(std::isfinite(t));
  FUZZ_CHECK(t >= 0);
}

void checkImageList(const std::vector<plumb::TumListEntry>& entries) {
  FUZZ_CHECK(!entries.empty());
  for (std::size_t i = 0; i < entries.size(); ++i) {
    checkStamp(entries[i].timestamp_s);
    FUZZ_CHECK(!entries[i].path.empty());
    if (i > 0) FUZZ_CHECK(entries[i].timestamp_s > entries[i - 1].timestamp_s);
    if (i > 0) FUZZ_CHECK(entries[i].line > entries[i - 1].line);
  }
  std::string text = "# written back by the fuzzer\n";
  for (const plumb::TumListEntry& e : entries) text += stamp(e.timestamp_s) + " " + e.path + "\n";
  MemFile again(text);
  if (!again.ok()) return;
  std::vector<plumb::TumListEntry> reread;
  FUZZ_CHECK(plumb::readTumImageList(again.path(), &reread).ok());
  FUZZ_CHECK(reread.size() == entries.size());
  for (std::size_t i = 0; i < entries.size(); ++i) {
    FUZZ_CHECK(reread[i].timestamp_s == entries[i].timestamp_s);
    FUZZ_CHECK(reread[i].path == entries[i].path);
  }
  const std::vector<plumb::TumFrameEntry> frames = plumb::associateTumLists(entries, entries);
  FUZZ_CHECK(frames.size() == entries.size());
  for (std::size_t i = 0; i < frames.size(); ++i) {
    FUZZ_CHECK(frames[i].rgb_timestamp_s == entries[i].timestamp_s);
    FUZZ_CHECK(frames[i].depth_timestamp_s == entries[i].timestamp_s);
    FUZZ_CHECK(frames[i].rgb_path == entries[i].path && frames[i].depth_path == entries[i].path);
  }
}

void checkAssociations(const std::vector<plumb::TumFrameEntry>& frames) {
  FUZZ_CHECK(!frames.empty());
  for (std::size_t i = 0; i < frames.size(); ++i) {
    checkStamp(frames[i].rgb_timestamp_s);
    checkStamp(frames[i].depth_timestamp_s);
    FUZZ_CHECK(!frames[i].rgb_path.empty() && !frames[i].depth_path.empty());
    if (i > 0) {
      FUZZ_CHECK(frames[i].rgb_timestamp_s > frames[i - 1].rgb_timestamp_s);
      FUZZ_CHECK(frames[i].depth_timestamp_s > frames[i - 1].depth_timestamp_s);
    }
  }
  // Written rgb-first (the benchmark's order) it must read back to the same entries, whichever
  // order the input used.
  std::string text;
  for (const plumb::TumFrameEntry& f : frames)
    text += stamp(f.rgb_timestamp_s) + " " + f.rgb_path + " " + stamp(f.depth_timestamp_s) + " " + f.depth_path + "\n";
  MemFile again(text);
  if (!again.ok()) return;
  std::vector<plumb::TumFrameEntry> reread;
  FUZZ_CHECK(plumb::readTumAssociations(again.path(), &reread).ok());
  FUZZ_CHECK(reread.size() == frames.size());
  for (std::size_t i = 0; i < frames.size(); ++i) {
    FUZZ_CHECK(reread[i].rgb_timestamp_s == frames[i].rgb_timestamp_s);
    FUZZ_CHECK(reread[i].depth_timestamp_s == frames[i].depth_timestamp_s);
    FUZZ_CHECK(reread[i].rgb_path == frames[i].rgb_path);
    FUZZ_CHECK(reread[i].depth_path == frames[i].depth_path);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  MemFile file(data, size);
  if (!file.ok()) return 0;
  std::vector<plumb::TumListEntry> entries;
  if (plumb::readTumImageList(file.path(), &entries).ok()) checkImageList(entries);
  std::vector<plumb::TumFrameEntry> frames;
  if (plumb::readTumAssociations(file.path(), &frames).ok()) checkAssociations(frames);
  return 0;
}
