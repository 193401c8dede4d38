#include "pipeline/loop/loop_audit.h"

namespace plumb::loop {

LoopAudit::LoopAudit(std::size_t max_entries, std::size_t max_keyframes) {
  entries_.reserve(max_entries);
  keyframes_.reserve(max_keyframes);
}

LoopAuditEntry* LoopAudit::add(const LoopAuditEntry& entry) {
  if (entries_.size() == entries_.capacity()) {
    ++entries_dropped_;
    return nullptr;
  }
  entries_.push_back(entry);  // within the reserved capacity: no allocation
  return &entries_.back();
}

void LoopAudit::addKeyframe(uint32_t id, double timestamp_s) {
  if (keyframes_.size() == keyframes_.capacity()) {
    ++keyframes_dropped_;
    return;
  }
  keyframes_.push_back(LoopAuditKeyframe{id, timestamp_s});
}

}  // namespace plumb::loop
