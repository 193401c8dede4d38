#include "platform/process_memory.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace plumb {

bool readRss(long* peak_kib, long* current_kib) {
  *peak_kib = *current_kib = -1;
  std::FILE* f = std::fopen("/proc/self/status", "r");
  if (f == nullptr) return false;
  char line[256];
  while (std::fgets(line, sizeof(line), f)) {
    if (std::strncmp(line, "VmHWM:", 6) == 0) *peak_kib = std::strtol(line + 6, nullptr, 10);
    if (std::strncmp(line, "VmRSS:", 6) == 0) *current_kib = std::strtol(line + 6, nullptr, 10);
  }
  std::fclose(f);
  return *peak_kib >= 0 && *current_kib >= 0;
}

}  // namespace plumb
