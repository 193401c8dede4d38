#pragma once
// IoPlan: the files a command reads and the files it writes, checked together BEFORE any work, so
// an output never overwrites an input and a bad output path is refused at start, not after an hour
// of computation. Outputs themselves are written through AtomicFile (drivers/common/atomic_file.h).
#include <string>
#include <vector>

#include "platform/status.h"

namespace plumb::tools {

class IoPlan {
 public:
  // A file or a folder the command reads (a folder protects everything that exists inside it).
  // Empty paths and "synth:"-style specs that name no file are ignored.
  void addInput(const std::string& path);
  // A file the command will write; `flag` names it in messages (e.g. "--out").
  void addOutput(const std::string& flag, const std::string& path);
  // Each output: its folder exists and is writable; it is not a folder; it is not an input (same
  // file, compared by device and inode, so links and ../ spellings are caught) and not an existing
  // file inside an input folder; no two outputs are the same file; a probe file can be created
  // where it will be written (drivers/common/atomic_file.h probeOutputPath: through a symlink to
  // its target, so /proc or a read-only mount fail here, before any work).
  Status check() const;

 private:
  struct Output {
    std::string flag, path;
  };
  std::vector<std::string> inputs_;
  std::vector<Output> outputs_;
};

}  // namespace plumb::tools
