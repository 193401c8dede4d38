#pragma once
// Helpers shared by the libFuzzer targets (fuzz/*_fuzzer.cpp): the parsers read files by path,
// so an input becomes an in-memory file (memfd) reachable as /proc/self/fd/N; and a failed
// invariant aborts with a message, which libFuzzer reports as a crash with the input saved.
#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace plumb::fuzz {

// An anonymous in-memory file holding `size` bytes; closed on destruction.
class MemFile {
 public:
  MemFile(const uint8_t* data, std::size_t size) : fd_(memfd_create("plumb_fuzz", 0)) {
    if (fd_ >= 0 && size > 0 && write(fd_, data, size) != static_cast<ssize_t>(size)) {
      close(fd_);
      fd_ = -1;
    }
  }
  explicit MemFile(const std::string& text)
      : MemFile(reinterpret_cast<const uint8_t*>(text.data()), text.size()) {}
  ~MemFile() {
    if (fd_ >= 0) close(fd_);
  }
  MemFile(const MemFile&) = delete;
  MemFile& operator=(const MemFile&) = delete;

  bool ok() const { return fd_ >= 0; }
  std::string path() const { return "/proc/self/fd/" + std::to_string(fd_); }

 private:
  int fd_;
};

// A broken invariant: print what and where, then abort (libFuzzer saves the input as a crash).
[[noreturn]] inline void invariantFailed(const char* what, const char* file, int line) {
  std::fprintf(stderr, "INVARIANT FAILED at %s:%d: %s\n", file, line, what);
  std::abort();
}

}  // namespace plumb::fuzz

#define FUZZ_CHECK(condition)                                                   \
  do {                                                                          \
    if (!(condition)) ::plumb::fuzz::invariantFailed(#condition, __FILE__, __LINE__); \
  } while (0)
