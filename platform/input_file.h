#pragma once
// The one way plumb opens a file it reads (camera files, lists, trajectories, traces, maps, images,
// recordings). Every reader goes through here so that hostile paths fail the same way everywhere:
//   - the open never blocks: O_NONBLOCK first, then fstat; a FIFO, a device (/dev/zero), a socket
//     or a folder is refused with a message saying what it is (a live source opens its device
//     itself; nothing here is for live sources);
//   - the size is bounded before a byte is read (each reader states its own bound);
//   - a symlink loop is reported as a symlink loop, a missing file as missing, a permission as a
//     permission: the message names the path and the reason;
//   - text is read line by line through a fixed buffer, each line bounded, so a file of zeros or
//     one endless line costs a bounded amount of memory and fails at once.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>

#include "platform/status.h"

namespace plumb {

// What is at a path, found with stat() (never open(): opening a FIFO blocks).
enum class PathKind { kMissing, kRegular, kDirectory, kOther, kError };
PathKind pathKind(const std::string& path);
inline bool isRegularFile(const std::string& path) { return pathKind(path) == PathKind::kRegular; }
// Ok when `path` is a regular file; otherwise why not, naming it: "missing", "symlink
// loop", "a FIFO (named pipe), not a regular file", ... (`what` prefixes the path: "image file").
Status requireRegularFile(const std::string& path, const char* what);

// Bounds of the text and binary inputs (docs/DATA_FORMATS.md "Inputs are bounded").
constexpr uint64_t kMaxTextInputBytes = uint64_t(1) << 30;  // lists, trajectories, traces: 1 GiB
constexpr uint64_t kMaxCameraFileBytes = 1 << 20;          // a camera file: 1 MiB
constexpr std::size_t kMaxTextLineBytes = 64 * 1024;       // one line of any text input

// An open regular file (closed by the destructor).
class InputFile {
 public:
  InputFile() = default;
  ~InputFile();
  InputFile(const InputFile&) = delete;
  InputFile& operator=(const InputFile&) = delete;

  // Opens `path` for reading: refuses what is not a regular file and a file above max_bytes.
  // `what` names the input in messages ("camera file", "map", ...).
  Status open(const std::string& path, uint64_t max_bytes, const char* what);
  int fd() const { return fd_; }
  uint64_t size() const { return size_; }
  const std::string& path() const { return path_; }
  // Reads exactly `n` bytes (false at a short read or an error; EINTR retried).
  bool readExactly(void* buffer, std::size_t n);
  void close();

 private:
  int fd_ = -1;
  uint64_t size_ = 0;
  std::string path_;
};

// Why `path` cannot be opened, from an errno: "missing (no such file)", "symlink loop", ...
std::string openErrorText(int error_number);

// Reads a whole regular file of at most max_bytes into `bytes`.
Status readInputFile(const std::string& path, uint64_t max_bytes, const char* what, std::string* bytes);

// Calls on_line(number, text) for each line of a text file (1-based; the '\n' and a '\r' before it
// removed; a UTF-8 byte-order mark at the start of the file is skipped). A line longer than
// max_line_bytes or holding a NUL byte is an error naming file:line. on_line returns false to stop
// reading early (the rest of the file is not read), or sets *error to fail.
using TextLineFn = std::function<bool(int number, const std::string& text, Status* error)>;
Status forEachInputLine(const std::string& path, uint64_t max_bytes, const char* what, const TextLineFn& on_line,
                        std::size_t max_line_bytes = kMaxTextLineBytes);

}  // namespace plumb
