#pragma once
// AtomicFile: the one way plumb writes an output file. The file appears under its name only when it
// is complete. Writing goes to a temporary file in the target's folder (`.<name>.partial-<pid>`),
// and commit() flushes, syncs and renames it into place, atomically replacing an older file of that
// name. Until then the final path is untouched; abandoned (destroyed without commit) the temporary
// file is removed. So a crash, a full disk or a stop never leaves a partial file that looks whole.
//
// A path that is a symlink is written THROUGH the link: the chain is followed to its final target
// (which may not exist yet) and the temporary file and the rename happen there, so the link stays a
// link (`--out /dev/stdout` as root used to replace the /dev/stdout link by a regular file). A link
// chain longer than 40 hops or pointing back to itself is refused as a symlink loop, and a path
// that is (or leads to) a stream of the process (/dev/stdout, /dev/fd/N, /proc/self/fd/N) is
// refused: an output that appears whole by rename cannot be a stream.
#include <cstddef>
#include <cstdio>
#include <string>

#include "platform/status.h"

namespace plumb {

// The file `path` finally names: itself, or the end of its symlink chain (relative links resolved
// against the link's folder). Errors: a symlink loop, an unreadable link.
Status resolveOutputTarget(const std::string& path, std::string* target);

// Creates and removes the temporary file an AtomicFile for `path` would write: proves, before any
// work, that the output can be written there (catches /proc, read-only mounts, full inode tables,
// missing permissions, which a writable-folder check alone misses).
Status probeOutputPath(const std::string& path);

class AtomicFile {
 public:
  AtomicFile() = default;
  ~AtomicFile();  // abandons an uncommitted file
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  Status open(const std::string& path);
  std::FILE* file() const { return file_; }
  bool isOpen() const { return file_ != nullptr; }
  // Flush, fsync, close and rename into place. Errors name the path and say that nothing was
  // written under its name (a full disk says "no space left on the device").
  Status commit();
  // Close and remove the temporary file; the final path stays as it was.
  void abandon();
  // The temporary file's path while open ('' otherwise): for writers that write by name.
  const std::string& temporaryPath() const { return temp_path_; }

 private:
  std::string path_, target_path_, temp_path_;
  std::FILE* file_ = nullptr;
};

// The whole of `text` (or `size` bytes) into `path` through an AtomicFile.
Status writeFileAtomically(const std::string& path, const std::string& text);
Status writeFileAtomically(const std::string& path, const void* bytes, std::size_t size);

}  // namespace plumb
