#include "drivers/common/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace plumb {
namespace {

constexpr int kMaxSymlinkHops = 40;  // Linux's own limit (MAXSYMLINKS)

std::string folderPart(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? "" : path.substr(0, slash + 1);
}

std::string namePart(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

std::string temporaryPathFor(const std::string& target) {
  return folderPart(target) + "." + namePart(target) + ".partial-" + std::to_string(::getpid());
}

std::string writeErrorText(int error_number) {
  if (error_number == ENOSPC) return "no space left on the device";
  if (error_number == EDQUOT) return "disk quota exceeded";
  return std::strerror(error_number);
}

}  // namespace

// /dev/stdout, /dev/fd/N, /proc/self/fd/N, /proc/<pid>/fd/N: a stream of this process, not a
// file. An output cannot be written aside and renamed onto a stream (renaming onto the file behind
// a redirected stdout would also swap the file from under the shell), so it is refused.
bool namesProcessStream(const std::string& path) {
  if (path.rfind("/dev/fd/", 0) == 0 || path == "/dev/stdout" || path == "/dev/stderr" || path == "/dev/stdin") return true;
  if (path.rfind("/proc/", 0) != 0) return false;
  const std::size_t fd = path.find("/fd/");
  return fd != std::string::npos && path.find('/', fd + 4) == std::string::npos;
}

Status resolveOutputTarget(const std::string& path, std::string* target) {
  std::string current = path;
  for (int hop = 0; hop <= kMaxSymlinkHops; ++hop) {
    if (namesProcessStream(current)) {
      return Status::Error(path + ": names a stream of this process (" + current +
                           "), not a file; outputs are written aside and renamed into place: give a file path");
    }
    struct stat st {};
    if (::lstat(current.c_str(), &st) != 0) {
      if (errno == ENOENT) break;  // a new file (possibly a dangling link's target)
      if (errno == ELOOP) return Status::Error(path + ": symlink loop (a link that points back to itself)");
      return Status::Error(path + ": " + std::strerror(errno));
    }
    if (!S_ISLNK(st.st_mode)) break;
    char buffer[4096];
    const ssize_t n = ::readlink(current.c_str(), buffer, sizeof buffer - 1);
    if (n < 0) return Status::Error(path + ": unreadable symlink (" + std::string(std::strerror(errno)) + ")");
    std::string link(buffer, std::size_t(n));
    current = (!link.empty() && link[0] == '/') ? link : folderPart(current) + link;
    if (hop == kMaxSymlinkHops) return Status::Error(path + ": symlink loop (more than 40 links in a chain)");
  }
  *target = current;
  return Status::Ok();
}

Status probeOutputPath(const std::string& path) {
  std::string target;
  PLUMB_RETURN_IF_ERROR(resolveOutputTarget(path, &target));
  if (namePart(target).empty()) return Status::Error(path + ": not a file name");
  const std::string probe = temporaryPathFor(target);
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) {
    return Status::Error(path + ": cannot write in " + (folderPart(target).empty() ? "." : folderPart(target)) + " (" +
                         writeErrorText(errno) + ")");
  }
  ::close(fd);
  ::unlink(probe.c_str());
  return Status::Ok();
}

AtomicFile::~AtomicFile() { abandon(); }

Status AtomicFile::open(const std::string& path) {
  abandon();
  std::string target;
  PLUMB_RETURN_IF_ERROR(resolveOutputTarget(path, &target));
  if (namePart(target).empty()) return Status::Error(path + ": not a file name");
  temp_path_ = temporaryPathFor(target);
  file_ = std::fopen(temp_path_.c_str(), "w");
  if (file_ == nullptr) {
    const std::string reason = writeErrorText(errno);
    temp_path_.clear();
    return Status::Error(path + ": cannot write here (" + reason + ")");
  }
  path_ = path;
  target_path_ = target;
  return Status::Ok();
}

Status AtomicFile::commit() {
  if (file_ == nullptr) return Status::Error(path_ + ": not open");
  int error_number = 0;
  auto check = [&error_number](bool ok) {
    if (!ok && error_number == 0) error_number = errno != 0 ? errno : EIO;
    return ok;
  };
  errno = 0;
  bool ok = check(std::fflush(file_) == 0 && std::ferror(file_) == 0);
  ok = check(::fsync(::fileno(file_)) == 0) && ok;
  ok = check(std::fclose(file_) == 0) && ok;
  file_ = nullptr;
  if (!ok) {
    std::remove(temp_path_.c_str());
    temp_path_.clear();
    return Status::Error(path_ + ": write failed (" + writeErrorText(error_number) +
                         "); nothing was written under this name");
  }
  if (std::rename(temp_path_.c_str(), target_path_.c_str()) != 0) {
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

Status writeFileAtomically(const std::string& path, const void* bytes, std::size_t size) {
  AtomicFile file;
  PLUMB_RETURN_IF_ERROR(file.open(path));
  if (size > 0 && std::fwrite(bytes, 1, size, file.file()) != size) {
    const std::string reason = writeErrorText(errno);
    return Status::Error(path + ": write failed (" + reason + "); nothing was written under this name");
  }
  return file.commit();
}

Status writeFileAtomically(const std::string& path, const std::string& text) {
  return writeFileAtomically(path, text.data(), text.size());
}

}  // namespace plumb
