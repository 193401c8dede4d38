// libFuzzer target for the map file reader (drivers/mapfile/map_file.h + the codec,
// pipeline/loop/saved_map_codec.h): any bytes as a `--load-map` file must be read or refused with
// a Status, never crash, hang or allocate beyond the input's bounds. The first input byte is a
// mode: bit 0 set = the header's size and CRC and every section's CRC are recomputed before
// reading, so mutations reach the codec behind the checksums (without it nearly every mutation
// stops at a CRC). The rest is the file. Beyond "no crash", a map that is accepted must encode
// back to exactly the same bytes (the format has one spelling per map: flags 0/1, reserved 0,
// exact section sizes, finite numbers kept bit for bit).
#include <cstdint>
#include <cstring>
#include <vector>

#include "drivers/mapfile/map_file.h"
#include "drivers/recording/crc32.h"
#include "fuzz/fuzz_support.h"
#include "pipeline/loop/saved_map_codec.h"

namespace {

void putU32(std::vector<uint8_t>& b, std::size_t at, uint32_t v) {
  for (int i = 0; i < 4; ++i) b[at + std::size_t(i)] = uint8_t(v >> (8 * i));
}
void putU64(std::vector<uint8_t>& b, std::size_t at, uint64_t v) {
  for (int i = 0; i < 8; ++i) b[at + std::size_t(i)] = uint8_t(v >> (8 * i));
}
uint64_t getU64(const std::vector<uint8_t>& b, std::size_t at) {
  uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= uint64_t(b[at + std::size_t(i)]) << (8 * i);
  return v;
}

void fixChecksums(std::vector<uint8_t>& b) {
  if (b.size() < plumb::kMapFileHeaderBytes) return;
  putU64(b, 16, b.size());
  putU32(b, 28, plumb::crc32(b.data(), 28));
  std::size_t pos = plumb::kMapFileHeaderBytes;
  while (b.size() - pos >= plumb::kMapFileSectionOverheadBytes) {
    const uint64_t payload = getU64(b, pos + 8);
    if (payload > b.size() - pos - plumb::kMapFileSectionOverheadBytes) return;
    const std::size_t covered = 16 + std::size_t(payload);
    putU32(b, pos + covered, plumb::crc32(b.data() + pos, covered));
    pos += covered + 4;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  std::vector<uint8_t> bytes(data + 1, data + size);
  if (data[0] & 1) fixChecksums(bytes);
  plumb::fuzz::MemFile file(bytes.data(), bytes.size());
  if (!file.ok()) return 0;
  std::vector<plumb::MapFileSection> sections;
  if (!plumb::readMapFile(file.path(), plumb::loop::kSavedMapFormatVersion, plumb::MapFileLimits{}, &sections).ok()) {
    return 0;
  }
  std::vector<plumb::loop::MapSectionBytes> codec_sections;
  for (auto& s : sections) codec_sections.push_back(plumb::loop::MapSectionBytes{s.tag, std::move(s.bytes)});
  plumb::loop::SavedMap map;
  if (!plumb::loop::decodeSavedMap(codec_sections, plumb::loop::SavedMapLimits{}, &map).ok()) return 0;
  FUZZ_CHECK(map.keyframes.size() <= plumb::loop::SavedMapLimits{}.max_keyframes);
  FUZZ_CHECK(map.camera.validate().empty());
  std::vector<plumb::loop::MapSectionBytes> again;
  plumb::loop::encodeSavedMap(map, &again);
  std::vector<plumb::MapFileSection> again_file;
  for (auto& s : again) again_file.push_back(plumb::MapFileSection{s.tag, std::move(s.bytes)});
  FUZZ_CHECK(plumb::encodeMapFile(plumb::loop::kSavedMapFormatVersion, again_file) == bytes);
  return 0;
}
