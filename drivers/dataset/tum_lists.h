#pragma once
// Readers of the TUM list files: rgb.txt / depth.txt (`timestamp filename`) and associations.txt
// (`t_rgb rgb/X.png t_depth depth/Y.png`; also depth-first lines `t_depth depth/Y.png t_rgb rgb/X.png`,
// recognised by the folder names, as ICL-NUIM and some tools write them). Each checks that the list is not
// empty, every line parses, and timestamps strictly increase; errors name the file and line.
#include <string>
#include <vector>

#include "drivers/dataset/tum_dataset.h"
#include "platform/status.h"

namespace plumb {

struct TumListEntry {
  double timestamp_s = 0;
  std::string path;  // relative to the dataset folder
  int line = 0;      // line number in the list file (for later messages)
};

Status readTumImageList(const std::string& list_path, std::vector<TumListEntry>* out);

// max_entries > 0: stop after that many associations (the rest of the file is not read).
Status readTumAssociations(const std::string& list_path, std::vector<TumFrameEntry>* out,
                           std::size_t max_entries = 0);

// Pairs rgb and depth lists with the benchmark's rule (timestamp_association.h).
std::vector<TumFrameEntry> associateTumLists(const std::vector<TumListEntry>& rgb,
                                             const std::vector<TumListEntry>& depth);

}  // namespace plumb
