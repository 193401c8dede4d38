#include "drivers/common/atomic_file.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace plumb {

AtomicFile::~AtomicFile() { abandon(); }

Status AtomicFile::open(const std::string& path) {
  abandon();
  const std::size_t slash = path.find_last_of('/');
  const std::string folder = slash == std::string::npos ? "" : path.substr(0, slash + 1);
  const std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  if (name.empty()) return Status::Error(path + ": not a file name");
  temp_path_ = folder + "." + name + ".partial-" + std::to_string(::getpid());
  file_ = std::fopen(temp_path_.c_str(), "w");
  if (file_ == nullptr) {
    const std::string reason = std::strerror(errno);
    temp_path_.clear();
    return Status::Error(path + ": cannot write here (" + reason + ")");
  }
  path_ = path;
  return Status::Ok();
}

Status AtomicFile::commit() {
  if (file_ == nullptr) return Status::Error(path_ + ": not open");
  bool ok = std::fflush(file_) == 0 && std::ferror(file_) == 0;
  ok = ::fsync(::fileno(file_)) == 0 && ok;
  ok = std::fclose(file_) == 0 && ok;
  file_ = nullptr;
  if (!ok) {
    const std::string reason = std::strerror(errno);
    std::remove(temp_path_.c_str());
    temp_path_.clear();
    return Status::Error(path_ + ": write failed (" + reason + "); nothing was written under this name");
  }
  if (std::rename(temp_path_.c_str(), path_.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    std::remove(temp_path_.c_str());
    temp_path_.clear();
    return Status::Error(path_ + ": cannot move the finished file into place (" + reason + ")");
  }
  temp_path_.clear();
  return Status::Ok();
}

void AtomicFile::abandon() {
  if (file_ != nullptr) {
    std::fclose(file_);
    file_ = nullptr;
  }
  if (!temp_path_.empty()) {
    std::remove(temp_path_.c_str());
    temp_path_.clear();
  }
}

Status writeFileAtomically(const std::string& path, const std::string& text) {
  AtomicFile file;
  PLUMB_RETURN_IF_ERROR(file.open(path));
  if (std::fwrite(text.data(), 1, text.size(), file.file()) != text.size()) {
    return Status::Error(path + ": write failed");
  }
  return file.commit();
}

}  // namespace plumb
