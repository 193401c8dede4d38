#include "tools/map_files.h"

#include <utility>
#include <vector>

#include "drivers/mapfile/map_file.h"
#include "pipeline/loop/saved_map_codec.h"

namespace plumb::tools {

Status loadMapFile(const std::string& path, loop::SavedMap* map) {
  std::vector<MapFileSection> file_sections;
  PLUMB_RETURN_IF_ERROR(readMapFile(path, loop::kSavedMapFormatVersion, MapFileLimits{}, &file_sections));
  std::vector<loop::MapSectionBytes> sections(file_sections.size());
  for (std::size_t i = 0; i < sections.size(); ++i) {
    sections[i].tag = file_sections[i].tag;
    sections[i].bytes = std::move(file_sections[i].bytes);
  }
  return loop::decodeSavedMap(sections, loop::SavedMapLimits{}, map).withContext("map " + path);
}

Status saveMapFile(const std::string& path, const loop::SavedMap& map, uint64_t* bytes) {
  std::vector<loop::MapSectionBytes> sections;
  loop::encodeSavedMap(map, &sections);
  std::vector<MapFileSection> file_sections(sections.size());
  *bytes = kMapFileHeaderBytes;
  for (std::size_t i = 0; i < sections.size(); ++i) {
    file_sections[i].tag = sections[i].tag;
    file_sections[i].bytes = std::move(sections[i].bytes);
    *bytes += kMapFileSectionOverheadBytes + file_sections[i].bytes.size();
  }
  return writeMapFile(path, loop::kSavedMapFormatVersion, file_sections);
}

}  // namespace plumb::tools
