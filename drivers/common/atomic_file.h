#pragma once
// AtomicFile: an output file that appears under its name only when it is complete. Writing goes to
// a temporary file in the same folder (`.<name>.partial-<pid>`), and commit() flushes, syncs and
// renames it into place, atomically replacing an older file of that name. Until then the final
// path is untouched; abandoned (destroyed without commit) the temporary file is removed. So a
// crash, a full disk or a stop never leaves a partial file that looks whole.
#include <cstdio>
#include <string>

#include "platform/status.h"

namespace plumb {

class AtomicFile {
 public:
  AtomicFile() = default;
  ~AtomicFile();  // abandons an uncommitted file
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  Status open(const std::string& path);
  std::FILE* file() const { return file_; }
  bool isOpen() const { return file_ != nullptr; }
  // Flush, fsync, close and rename into place. Errors name the path.
  Status commit();
  // Close and remove the temporary file; the final path stays as it was.
  void abandon();

 private:
  std::string path_, temp_path_;
  std::FILE* file_ = nullptr;
};

// The whole of `text` into `path` through an AtomicFile.
Status writeFileAtomically(const std::string& path, const std::string& text);

}  // namespace plumb
