#include "platform/input_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <vector>

namespace plumb {
namespace {

const char* kindText(mode_t mode) {
  if (S_ISDIR(mode)) return "a folder";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

std::string named(const char* what, const std::string& path) {
  return (what != nullptr && *what != '\0') ? std::string(what) + " " + path : path;
}

}  // namespace

PathKind pathKind(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return errno == ENOENT || errno == ENOTDIR ? PathKind::kMissing : PathKind::kError;
  if (S_ISREG(st.st_mode)) return PathKind::kRegular;
  if (S_ISDIR(st.st_mode)) return PathKind::kDirectory;
  return PathKind::kOther;
}

Status requireRegularFile(const std::string& path, const char* what) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return Status::Error(named(what, path) + ": " + openErrorText(errno));
  if (!S_ISREG(st.st_mode)) return Status::Error(named(what, path) + ": " + kindText(st.st_mode) + ", not a regular file");
  return Status::Ok();
}

std::string openErrorText(int error_number) {
  switch (error_number) {
    case ENOENT: return "missing (no such file)";
    case ELOOP: return "symlink loop (a link that points back to itself)";
    case EACCES: return "permission denied";
    case ENOTDIR: return "a part of the path is not a folder";
    case ENAMETOOLONG: return "path too long";
    default: return std::strerror(error_number);
  }
}

InputFile::~InputFile() { close(); }

void InputFile::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

Status InputFile::open(const std::string& path, uint64_t max_bytes, const char* what) {
  close();
  path_ = path;
  if (path.empty()) return Status::Error(named(what, "''") + ": empty path");
  // O_NONBLOCK: opening a FIFO without a writer would block forever (and swallow the first
  // signal); with it the open returns at once and fstat says what the path is.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) return Status::Error(named(what, path) + ": cannot open: " + openErrorText(errno));
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    const int e = errno;
    ::close(fd);
    return Status::Error(named(what, path) + ": cannot read: " + std::strerror(e));
  }
  if (!S_ISREG(st.st_mode)) {
    ::close(fd);
    return Status::Error(named(what, path) + ": " + kindText(st.st_mode) + ", not a regular file");
  }
  if (uint64_t(st.st_size) > max_bytes) {
    ::close(fd);
    return Status::Error(named(what, path) + ": " + std::to_string(uint64_t(st.st_size)) +
                         " bytes, beyond the limit of " + std::to_string(max_bytes) + " bytes");
  }
  // Back to blocking reads (a regular file never blocks long, but EAGAIN must not appear).
  const int flags = ::fcntl(fd, F_GETFL);
  if (flags >= 0) (void)::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK);
  fd_ = fd;
  size_ = uint64_t(st.st_size);
  return Status::Ok();
}

bool InputFile::readExactly(void* buffer, std::size_t n) {
  auto* out = static_cast<unsigned char*>(buffer);
  std::size_t got = 0;
  while (got < n) {
    const ssize_t r = ::read(fd_, out + got, n - got);
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) return false;
    got += std::size_t(r);
  }
  return true;
}

Status readInputFile(const std::string& path, uint64_t max_bytes, const char* what, std::string* bytes) {
  InputFile file;
  PLUMB_RETURN_IF_ERROR(file.open(path, max_bytes, what));
  bytes->assign(std::size_t(file.size()), '\0');
  if (!bytes->empty() && !file.readExactly(&(*bytes)[0], bytes->size())) {
    bytes->clear();
    return Status::Error(named(what, path) + ": read error (the file shrank while being read?)");
  }
  return Status::Ok();
}

Status forEachInputLine(const std::string& path, uint64_t max_bytes, const char* what, const TextLineFn& on_line,
                        std::size_t max_line_bytes) {
  InputFile file;
  PLUMB_RETURN_IF_ERROR(file.open(path, max_bytes, what));
  std::vector<char> buffer(64 * 1024);
  std::string line;
  int number = 1;
  bool first_chunk = true;
  uint64_t total = 0;
  auto deliver = [&](Status* error) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const bool more = on_line(number, line, error);
    line.clear();
    ++number;
    return more;
  };
  for (;;) {
    const ssize_t n = ::read(file.fd(), buffer.data(), buffer.size());
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return Status::Error(named(what, path) + ": read error: " + std::strerror(errno));
    if (n == 0) break;
    total += uint64_t(n);
    // A file that grows past its bound while being read (an append) is refused too.
    if (total > max_bytes) return Status::Error(named(what, path) + ": grew beyond " + std::to_string(max_bytes) + " bytes while being read");
    std::size_t begin = 0;
    if (first_chunk) {
      first_chunk = false;
      // A UTF-8 byte-order mark (Windows editors write one) is not part of the first token.
      if (n >= 3 && std::memcmp(buffer.data(), "\xEF\xBB\xBF", 3) == 0) begin = 3;
    }
    for (std::size_t i = begin; i < std::size_t(n); ++i) {
      const char c = buffer[i];
      if (c == '\n') {
        Status error;
        if (!deliver(&error)) return error;
        if (!error.ok()) return error;
        continue;
      }
      if (c == '\0') return Status::Error(path + ":" + std::to_string(number) + ": binary data (a NUL byte) in a text file");
      if (line.size() >= max_line_bytes) {
        return Status::Error(path + ":" + std::to_string(number) + ": line longer than " + std::to_string(max_line_bytes) +
                             " bytes (not a text file of this kind?)");
      }
      line.push_back(c);
    }
  }
  if (!line.empty()) {
    Status error;
    deliver(&error);
    if (!error.ok()) return error;
  }
  return Status::Ok();
}

}  // namespace plumb
