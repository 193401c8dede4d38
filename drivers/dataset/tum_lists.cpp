#include "drivers/dataset/tum_lists.h"

#include <cmath>
#include <cstdio>

#include "drivers/common/text_lines.h"
#include "drivers/common/timestamp_association.h"
#include "sensor/rgbd_image.h"

namespace plumb {
namespace {

std::string formatStamp(double t) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.6f", t);
  return text;
}

Status parseStamp(const std::string& where, const std::string& token, double* t) {
  if (!parseDouble(token, t)) return Status::Error(where + ": '" + token + "' is not a timestamp");
  if (!std::isfinite(*t) || *t < 0)
    return Status::Error(where + ": timestamp '" + token + "' is not a finite non-negative number");
  if (*t > kMaxTimestampS)
    return Status::Error(where + ": timestamp '" + token + "' is beyond 1e10 s (the year 2286): seconds are expected, "
                         "not nanoseconds or microseconds");
  return Status::Ok();
}

// Timestamps must strictly increase: a duplicate would make two frames indistinguishable, a
// decrease means a shuffled or concatenated list.
Status checkIncreasing(const std::string& where, const char* what, double previous, int previous_line,
                       double current) {
  if (current > previous) return Status::Ok();
  const std::string kind = current == previous ? "duplicate " : "non-monotonic ";
  return Status::Error(where + ": " + kind + what + " timestamp " + formatStamp(current) + " (previous " +
                       formatStamp(previous) + " on line " + std::to_string(previous_line) + ")");
}

bool startsWith(const std::string& text, const char* prefix) { return text.rfind(prefix, 0) == 0; }

}  // namespace

namespace {

// A list entry names a file INSIDE the dataset folder: relative, no ".." component. A list that
// points elsewhere (`../../../etc/passwd`, `/home/x/y.png`) is refused, never followed.
Status checkEntryPath(const std::string& where, const std::string& path) {
  if (path.empty() || path[0] == '/') return Status::Error(where + ": '" + path + "' is not a path inside the dataset folder");
  std::size_t start = 0;
  while (start <= path.size()) {
    const std::size_t slash = path.find('/', start);
    const std::string part = path.substr(start, slash == std::string::npos ? std::string::npos : slash - start);
    if (part == "..") return Status::Error(where + ": '" + path + "' leaves the dataset folder (..)");
    if (slash == std::string::npos) break;
    start = slash + 1;
  }
  return Status::Ok();
}

// One line of associations.txt appended to *out, checked against the previous entry.
Status parseAssociation(const std::string& list_path, const TextLine& line, int previous_line,
                        std::vector<TumFrameEntry>* out) {
  const std::string where = fileLine(list_path, line.number);
  if (line.tokens.size() != 4)
    return Status::Error(where + ": expected `t_rgb rgb_file t_depth depth_file`, got " +
                         std::to_string(line.tokens.size()) + " fields");
  // The benchmark writes rgb first; some tools (and ICL-NUIM's TUM-format release) write
  // depth first. The folder names of the paths say which column is which.
  const bool depth_first = startsWith(line.tokens[1], "depth") && startsWith(line.tokens[3], "rgb");
  const int rgb_column = depth_first ? 2 : 0, depth_column = depth_first ? 0 : 2;
  TumFrameEntry entry;
  PLUMB_RETURN_IF_ERROR(parseStamp(where, line.tokens[rgb_column], &entry.rgb_timestamp_s));
  entry.rgb_path = line.tokens[rgb_column + 1];
  PLUMB_RETURN_IF_ERROR(parseStamp(where, line.tokens[depth_column], &entry.depth_timestamp_s));
  entry.depth_path = line.tokens[depth_column + 1];
  PLUMB_RETURN_IF_ERROR(checkEntryPath(where, entry.rgb_path));
  PLUMB_RETURN_IF_ERROR(checkEntryPath(where, entry.depth_path));
  if (!out->empty()) {
    PLUMB_RETURN_IF_ERROR(
        checkIncreasing(where, "rgb", out->back().rgb_timestamp_s, previous_line, entry.rgb_timestamp_s));
    PLUMB_RETURN_IF_ERROR(
        checkIncreasing(where, "depth", out->back().depth_timestamp_s, previous_line, entry.depth_timestamp_s));
  }
  out->push_back(std::move(entry));
  return Status::Ok();
}

}  // namespace

Status readTumImageList(const std::string& list_path, std::vector<TumListEntry>* out) {
  out->clear();
  std::vector<TextLine> lines;
  PLUMB_RETURN_IF_ERROR(readTextLines(list_path, &lines));
  for (const TextLine& line : lines) {
    if (line.is_comment) continue;
    const std::string where = fileLine(list_path, line.number);
    if (line.tokens.size() != 2)
      return Status::Error(where + ": expected `timestamp filename`, got " +
                           std::to_string(line.tokens.size()) + " fields");
    TumListEntry entry;
    PLUMB_RETURN_IF_ERROR(parseStamp(where, line.tokens[0], &entry.timestamp_s));
    entry.path = line.tokens[1];
    PLUMB_RETURN_IF_ERROR(checkEntryPath(where, entry.path));
    entry.line = line.number;
    if (!out->empty())
      PLUMB_RETURN_IF_ERROR(
          checkIncreasing(where, "image", out->back().timestamp_s, out->back().line, entry.timestamp_s));
    out->push_back(std::move(entry));
  }
  if (out->empty()) return Status::Error(list_path + ": empty list (no image lines)");
  return Status::Ok();
}

Status readTumAssociations(const std::string& list_path, std::vector<TumFrameEntry>* out, std::size_t max_entries) {
  out->clear();
  int previous_line = 0;
  PLUMB_RETURN_IF_ERROR(forEachTextLine(list_path, [&](const TextLine& line, Status* error) {
    if (line.is_comment) return true;
    *error = parseAssociation(list_path, line, previous_line, out);
    previous_line = line.number;
    return error->ok() && (max_entries == 0 || out->size() < max_entries);
  }));
  if (out->empty()) return Status::Error(list_path + ": empty list (no associations)");
  return Status::Ok();
}

std::vector<TumFrameEntry> associateTumLists(const std::vector<TumListEntry>& rgb,
                                             const std::vector<TumListEntry>& depth) {
  std::vector<double> rgb_stamps, depth_stamps;
  for (const TumListEntry& e : rgb) rgb_stamps.push_back(e.timestamp_s);
  for (const TumListEntry& e : depth) depth_stamps.push_back(e.timestamp_s);
  std::vector<TumFrameEntry> frames;
  for (const IndexPair& pair : associateTimestamps(rgb_stamps, depth_stamps)) {
    const TumListEntry& r = rgb[pair.first];
    const TumListEntry& d = depth[pair.second];
    frames.push_back({r.timestamp_s, r.path, d.timestamp_s, d.path});
  }
  return frames;
}

}  // namespace plumb
