#include "tools/io_plan.h"

#include <sys/stat.h>
#include <unistd.h>

#include <climits>
#include <cstdlib>

#include "drivers/common/atomic_file.h"

namespace plumb::tools {
namespace {

struct FileId {
  dev_t dev = 0;
  ino_t ino = 0;
  bool operator==(const FileId& o) const { return dev == o.dev && ino == o.ino; }
};

bool fileId(const std::string& path, FileId* id, bool* is_dir = nullptr, bool* is_regular = nullptr) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return false;
  id->dev = st.st_dev;
  id->ino = st.st_ino;
  if (is_dir) *is_dir = S_ISDIR(st.st_mode);
  if (is_regular) *is_regular = S_ISREG(st.st_mode);
  return true;
}

std::string folderOf(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

std::string realPath(const std::string& path) {
  char buffer[PATH_MAX];
  return ::realpath(path.c_str(), buffer) != nullptr ? std::string(buffer) : std::string();
}

// True when `inner` (a real path) lies inside the folder `outer` (a real path).
bool isInside(const std::string& inner, const std::string& outer) {
  return !outer.empty() && inner.size() > outer.size() && inner.compare(0, outer.size(), outer) == 0 &&
         (outer.back() == '/' || inner[outer.size()] == '/');
}

}  // namespace

void IoPlan::addInput(const std::string& path) {
  if (!path.empty()) inputs_.push_back(path);
}

void IoPlan::addOutput(const std::string& flag, const std::string& path) {
  if (!path.empty()) outputs_.push_back(Output{flag, path});
}

Status IoPlan::check() const {
  for (std::size_t i = 0; i < outputs_.size(); ++i) {
    const Output& out = outputs_[i];
    // Outputs are written through symlinks (AtomicFile): the folder that matters is the target's.
    std::string target;
    const Status resolved = resolveOutputTarget(out.path, &target);
    if (!resolved.ok()) return Status::Error(out.flag + " " + resolved.message());
    const std::string folder = folderOf(target);
    bool folder_is_dir = false;
    FileId folder_id;
    if (!fileId(folder, &folder_id, &folder_is_dir) || !folder_is_dir) {
      return Status::Error(out.flag + " " + out.path + ": folder " + folder + " does not exist");
    }
    if (::access(folder.c_str(), W_OK) != 0) {
      return Status::Error(out.flag + " " + out.path + ": folder " + folder + " is not writable");
    }
    FileId out_id;
    bool out_is_dir = false, out_is_regular = false;
    const bool exists = fileId(out.path, &out_id, &out_is_dir, &out_is_regular);
    if (exists && out_is_dir) return Status::Error(out.flag + " " + out.path + ": is a folder, not a file");
    // A finished output replaces its path by rename: never a device, pipe or socket (/dev/null).
    if (exists && !out_is_regular) {
      return Status::Error(out.flag + " " + out.path + ": not a regular file (outputs replace their path when complete)");
    }
    if (exists) {
      // The same file first (the clearest message), then a file inside an input folder.
      for (const std::string& input : inputs_) {
        FileId in_id;
        if (fileId(input, &in_id) && in_id == out_id) {
          return Status::Error(out.flag + " " + out.path + " is an input of this command (" + input +
                               "): refusing to overwrite it");
        }
      }
      const std::string out_real = realPath(out.path);
      for (const std::string& input : inputs_) {
        FileId in_id;
        bool in_is_dir = false;
        if (fileId(input, &in_id, &in_is_dir) && in_is_dir && isInside(out_real, realPath(input))) {
          return Status::Error(out.flag + " " + out.path + " would overwrite a file of the input folder " + input +
                               ": refusing to overwrite it; write it elsewhere");
        }
      }
    }
    // Finally write a probe file where the output will be written (through a symlink to its
    // target): /proc, a read-only mount or a symlink loop fail here, before any work.
    const Status writable = probeOutputPath(out.path);
    if (!writable.ok()) return Status::Error(out.flag + " " + writable.message());
    for (std::size_t j = 0; j < i; ++j) {
      const Output& other = outputs_[j];
      FileId other_id;
      std::string other_target;
      if (!resolveOutputTarget(other.path, &other_target).ok()) other_target = other.path;
      const bool same_name = realPath(folderOf(other_target)) == realPath(folder) &&
                             other_target.substr(other_target.find_last_of('/') + 1) ==
                                 target.substr(target.find_last_of('/') + 1);
      if (same_name || (exists && fileId(other.path, &other_id) && other_id == out_id)) {
        return Status::Error(out.flag + " and " + other.flag + " name the same file " + out.path);
      }
    }
  }
  return Status::Ok();
}

}  // namespace plumb::tools
