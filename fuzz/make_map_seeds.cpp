// Writes the seed corpus of fuzz_map_file (fuzz/corpus/map_file/): tiny valid maps made by the
// tests' example-map builder (tests/support/saved_map_example.h), each with the fuzzer's mode
// byte in front (0: read as is, 1: checksums recomputed first). Built on request only:
//   cmake --build build-fuzz --target make_map_seeds && ./build-fuzz/make_map_seeds fuzz/corpus/map_file
#include <cstdio>
#include <string>
#include <vector>

#include "drivers/mapfile/map_file.h"
#include "pipeline/loop/saved_map_codec.h"
#include "tests/support/saved_map_example.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_map_seeds DIR\n");
    return 2;
  }
  const struct {
    const char* name;
    int keyframes, points, lines, loop_edges;
  } seeds[] = {{"empty", 0, 0, 0, 0}, {"one_keyframe", 1, 3, 1, 0}, {"two_keyframes_loop", 2, 2, 2, 1}};
  for (const auto& s : seeds) {
    plumb::loop::SavedMap map;
    plumb::test::makeExampleMap(5, s.keyframes, s.points, s.lines, s.loop_edges, &map);
    std::vector<plumb::loop::MapSectionBytes> sections;
    plumb::loop::encodeSavedMap(map, &sections);
    std::vector<plumb::MapFileSection> file_sections;
    for (auto& x : sections) file_sections.push_back(plumb::MapFileSection{x.tag, x.bytes});
    const std::vector<uint8_t> bytes = plumb::encodeMapFile(plumb::loop::kSavedMapFormatVersion, file_sections);
    for (uint8_t mode : {uint8_t(0), uint8_t(1)}) {
      const std::string path = std::string(argv[1]) + "/" + s.name + (mode ? "_fixcrc" : "") + ".map";
      std::FILE* f = std::fopen(path.c_str(), "wb");
      if (f == nullptr || std::fwrite(&mode, 1, 1, f) != 1 ||
          std::fwrite(bytes.data(), 1, bytes.size(), f) != bytes.size() || std::fclose(f) != 0) {
        std::fprintf(stderr, "cannot write %s\n", path.c_str());
        return 1;
      }
      std::printf("%s: %zu bytes\n", path.c_str(), bytes.size() + 1);
    }
  }
  return 0;
}
