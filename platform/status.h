#pragma once
// Status: the error type of plumb. Loading, parsing and device code return a Status (or fill an
// output and return one) instead of throwing, so a bad input becomes one clear message and a
// non-zero exit at the top, never a crash. Messages name the file (and line) they are about.
#include <string>
#include <utility>

namespace plumb {

class [[nodiscard]] Status {
 public:
  Status() = default;  // OK
  static Status Ok() { return Status(); }
  static Status Error(std::string message) { return Status(std::move(message)); }

  bool ok() const { return !failed_; }
  explicit operator bool() const { return ok(); }
  const std::string& message() const { return message_; }

  // Prefix context, e.g. st.withContext("reading rgb.txt") -> "reading rgb.txt: <message>".
  Status withContext(const std::string& context) const {
    return failed_ ? Status(context + ": " + message_) : *this;
  }

 private:
  explicit Status(std::string message) : failed_(true), message_(std::move(message)) {}
  bool failed_ = false;
  std::string message_;
};

// Propagate an error Status to the caller.
#define PLUMB_RETURN_IF_ERROR(expr)            \
  do {                                         \
    ::plumb::Status plumb_status_ = (expr);    \
    if (!plumb_status_.ok()) return plumb_status_; \
  } while (0)

}  // namespace plumb
