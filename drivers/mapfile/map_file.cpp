#include "drivers/mapfile/map_file.h"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>

#include "drivers/common/atomic_file.h"
#include "drivers/recording/byte_io.h"
#include "drivers/recording/crc32.h"
#include "platform/input_file.h"

namespace plumb {

namespace {

constexpr char kMagic[8] = {'P', 'L', 'U', 'M', 'B', 'M', 'A', 'P'};

std::string hex32(uint32_t v) {
  char buffer[16];
  std::snprintf(buffer, sizeof buffer, "0x%08x", v);
  return buffer;
}

}  // namespace

std::vector<uint8_t> encodeMapFile(uint32_t version, const std::vector<MapFileSection>& sections) {
  uint64_t total = kMapFileHeaderBytes;
  for (const MapFileSection& s : sections) total += kMapFileSectionOverheadBytes + s.bytes.size();
  std::vector<uint8_t> out;
  out.reserve(std::size_t(total));
  ByteWriter w(out);
  w.bytes(kMagic, sizeof kMagic);
  w.u32(version);
  w.u32(uint32_t(sections.size()));
  w.u64(total);
  w.u32(0);
  w.u32(crc32(out.data(), out.size()));
  for (const MapFileSection& s : sections) {
    const std::size_t start = out.size();
    w.u32(s.tag);
    w.u32(0);
    w.u64(s.bytes.size());
    w.bytes(s.bytes.data(), s.bytes.size());
    w.u32(crc32(out.data() + start, out.size() - start));
  }
  return out;
}

namespace {

// The 32-byte header: magic, CRC, version, reserved, the file size within the limit.
Status checkMapHeader(const uint8_t* data, std::size_t size, uint32_t supported_version, const MapFileLimits& limits,
                      uint64_t* file_size, uint32_t* count) {
  if (size < kMapFileHeaderBytes) {
    return Status::Error("not a plumb map: " + std::to_string(size) + " bytes, shorter than the " +
                         std::to_string(kMapFileHeaderBytes) + "-byte header (truncated?)");
  }
  if (std::memcmp(data, kMagic, sizeof kMagic) != 0) return Status::Error("not a plumb map (wrong magic)");
  ByteReader header(data + sizeof kMagic, kMapFileHeaderBytes - sizeof kMagic);
  const uint32_t version = header.u32();
  *count = header.u32();
  *file_size = header.u64();
  const uint32_t reserved = header.u32();
  const uint32_t header_crc = header.u32();
  if (crc32(data, kMapFileHeaderBytes - 4) != header_crc) {
    return Status::Error("map header is corrupted (CRC mismatch)");
  }
  if (version > supported_version) {
    return Status::Error("map format version " + std::to_string(version) + " was written by a newer plumb; this build reads version " +
                         std::to_string(supported_version));
  }
  if (version != supported_version) {
    return Status::Error("map format version " + std::to_string(version) + " is not supported (this build reads version " +
                         std::to_string(supported_version) + ")");
  }
  if (reserved != 0) return Status::Error("map header: reserved field is not 0");
  if (*file_size > limits.max_file_bytes) {
    return Status::Error("map header says " + std::to_string(*file_size) + " bytes, beyond the limit of " +
                         std::to_string(limits.max_file_bytes));
  }
  return Status::Ok();
}

}  // namespace

Status parseMapFile(const uint8_t* data, std::size_t size, uint32_t supported_version, const MapFileLimits& limits,
                    std::vector<MapFileSection>* sections) {
  sections->clear();
  uint64_t file_size = 0;
  uint32_t count = 0;
  PLUMB_RETURN_IF_ERROR(checkMapHeader(data, size, supported_version, limits, &file_size, &count));
  if (file_size != size) {
    return Status::Error("map is " + std::to_string(size) + " bytes but its header says " + std::to_string(file_size) +
                         (size < file_size ? " (truncated)" : " (bytes after the end)"));
  }
  if (count > limits.max_sections) {
    return Status::Error("map has " + std::to_string(count) + " sections, beyond the limit of " +
                         std::to_string(limits.max_sections));
  }
  std::size_t pos = kMapFileHeaderBytes;
  for (uint32_t i = 0; i < count; ++i) {
    if (size - pos < kMapFileSectionOverheadBytes) {
      return Status::Error("map section " + std::to_string(i) + " at byte " + std::to_string(pos) + ": truncated header");
    }
    ByteReader r(data + pos, size - pos);
    const uint32_t tag = r.u32();
    const uint32_t section_reserved = r.u32();
    const uint64_t payload = r.u64();
    if (payload > size - pos - kMapFileSectionOverheadBytes) {
      return Status::Error("map section " + std::to_string(i) + " at byte " + std::to_string(pos) + ": size " +
                           std::to_string(payload) + " runs past the end of the file");
    }
    const std::size_t covered = 16 + std::size_t(payload);
    ByteReader crc_reader(data + pos + covered, 4);
    if (crc32(data + pos, covered) != crc_reader.u32()) {
      return Status::Error("map section " + std::to_string(i) + " (tag " + hex32(tag) + ") at byte " +
                           std::to_string(pos) + " is corrupted (CRC mismatch)");
    }
    if (section_reserved != 0) return Status::Error("map section " + std::to_string(i) + ": reserved field is not 0");
    MapFileSection s;
    s.tag = tag;
    s.bytes.assign(data + pos + 16, data + pos + covered);
    sections->push_back(std::move(s));
    pos += covered + 4;
  }
  if (pos != size) {
    return Status::Error("map has " + std::to_string(size - pos) + " bytes after its last section");
  }
  return Status::Ok();
}

Status readMapFile(const std::string& path, uint32_t supported_version, const MapFileLimits& limits,
                   std::vector<MapFileSection>* sections) {
  // Opened the one way (platform/input_file.h): a FIFO or device is refused without blocking, the
  // size is bounded before reading, and the header (magic, CRC, version, size) is checked before
  // the rest of the file is read: a foreign 900 MB file costs 32 bytes of reading.
  InputFile file;
  PLUMB_RETURN_IF_ERROR(file.open(path, limits.max_file_bytes, "map"));
  std::vector<uint8_t> bytes(std::size_t(std::min<uint64_t>(file.size(), kMapFileHeaderBytes)));
  if (!bytes.empty() && !file.readExactly(bytes.data(), bytes.size())) return Status::Error("map " + path + ": read error");
  if (file.size() > kMapFileHeaderBytes) {
    uint64_t file_size = 0;
    uint32_t count = 0;
    PLUMB_RETURN_IF_ERROR(
        checkMapHeader(bytes.data(), bytes.size(), supported_version, limits, &file_size, &count).withContext("map " + path));
    bytes.resize(std::size_t(file.size()));
    if (!file.readExactly(bytes.data() + kMapFileHeaderBytes, bytes.size() - kMapFileHeaderBytes))
      return Status::Error("map " + path + ": read error");
  }
  return parseMapFile(bytes.data(), bytes.size(), supported_version, limits, sections).withContext("map " + path);
}

Status writeMapFile(const std::string& path, uint32_t version, const std::vector<MapFileSection>& sections) {
  const std::vector<uint8_t> bytes = encodeMapFile(version, sections);
  AtomicFile file;
  PLUMB_RETURN_IF_ERROR(file.open(path));
  if (std::fwrite(bytes.data(), 1, bytes.size(), file.file()) != bytes.size()) {
    file.abandon();
    return Status::Error("writing map " + path + ": " + std::strerror(errno));
  }
  return file.commit();
}

}  // namespace plumb
