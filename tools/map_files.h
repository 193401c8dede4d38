#pragma once
// `plumb run --load-map / --save-map` glue: the loop closer's map (pipeline/loop/saved_map.h) through
// its codec (pipeline/loop/saved_map_codec.h) into the checksummed container (drivers/mapfile/).
#include <cstdint>
#include <string>

#include "pipeline/loop/saved_map.h"
#include "platform/status.h"

namespace plumb::tools {

// Reads, checks and decodes a map file. Errors name the file and what is wrong.
Status loadMapFile(const std::string& path, loop::SavedMap* map);
// Encodes and writes it atomically; `bytes` = the file's size.
Status saveMapFile(const std::string& path, const loop::SavedMap& map, uint64_t* bytes);

}  // namespace plumb::tools
