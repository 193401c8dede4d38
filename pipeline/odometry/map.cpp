#include "pipeline/odometry/map.h"

#include <algorithm>
#include <type_traits>

#include "solver/zero_page_allocator.h"

namespace plumb {

static_assert(std::is_trivially_destructible_v<Keyframe> && std::is_trivially_destructible_v<MapPoint> &&
                  std::is_trivially_destructible_v<MapLine>,
              "Map::Storage is released without running destructors");

void Map::StorageDeleter::operator()(Storage* s) const { ZeroPageAllocator<Storage>().deallocate(s, 1); }

// Zero bytes are the cleared state (see Storage), so only the free lists are written here: the
// slot arrays cost resident memory as the map uses them, not at start.
Map::Map() : s_(ZeroPageAllocator<Storage>().allocate(1)) { fillFreeLists(); }

void Map::fillFreeLists() {
  s_->free_points.clear();
  s_->free_lines.clear();
  // Highest slot pushed first so that pop (from the back) hands out slot 0, 1, 2, ...
  for (std::size_t i = kMaxMapPoints; i-- > 0;) (void)s_->free_points.push_back(uint32_t(i));
  for (std::size_t i = kMaxMapLines; i-- > 0;) (void)s_->free_lines.push_back(uint32_t(i));
}

void Map::clear() {
  // Only what was ever handed out: a free keyframe slot already has empty lists (addKeyframe and
  // removeKeyframe clear them), and landmark slots at or above the high-water mark are in a
  // cleared state already (zero bytes, or MapPoint{} / MapLine{} from an earlier clear()). Clearing the whole arrays made all of them resident (~2 MiB of
  // landmarks and pages of every keyframe slot) at the first keyframe, which calls clear().
  for (auto& kf : s_->keyframes) {
    if (kf.id == 0) continue;
    kf.id = 0;
    kf.points.clear();
    kf.lines.clear();
  }
  for (uint32_t i = 0; i < points_high_water_; ++i) s_->points[i] = MapPoint{};
  for (uint32_t i = 0; i < lines_high_water_; ++i) s_->lines[i] = MapLine{};
  points_high_water_ = 0;
  lines_high_water_ = 0;
  fillFreeLists();
  // Ids keep growing across clear() (a new map segment): a stale message never matches a new id.
}

int Map::addKeyframe() {
  for (std::size_t i = 0; i < kMaxMapKeyframes; ++i) {
    Keyframe& kf = s_->keyframes[i];
    if (kf.id != 0) continue;
    kf.id = next_keyframe_id_++;
    kf.points.clear();
    kf.lines.clear();
    kf.covariance.setZero();
    kf.covariance_valid = false;
    kf.uncertainty = KeyframeUncertainty{};
    return int(i);
  }
  return -1;
}

int Map::addPoint() {
  if (s_->free_points.empty()) return -1;
  const uint32_t slot = s_->free_points.back();
  s_->free_points.pop_back();
  points_high_water_ = std::max(points_high_water_, slot + 1);
  s_->points[slot] = MapPoint{};
  s_->points[slot].id = next_point_id_++;
  return int(slot);
}

int Map::addLine() {
  if (s_->free_lines.empty()) return -1;
  const uint32_t slot = s_->free_lines.back();
  s_->free_lines.pop_back();
  lines_high_water_ = std::max(lines_high_water_, slot + 1);
  s_->lines[slot] = MapLine{};
  s_->lines[slot].id = next_line_id_++;
  return int(slot);
}

void Map::removeKeyframe(int kf_slot) {
  Keyframe& kf = s_->keyframes[kf_slot];
  if (kf.id == 0) return;
  // Detach every landmark; free the ones this keyframe was the last observer of.
  for (const auto& obs : kf.points) {
    MapPoint& p = s_->points[obs.point_slot];
    p.observers.mask &= ~(KeyframeMask(1) << kf_slot);
    if (p.observers.mask == 0) removePoint(int(obs.point_slot));
  }
  for (const auto& obs : kf.lines) {
    MapLine& l = s_->lines[obs.line_slot];
    l.observers.mask &= ~(KeyframeMask(1) << kf_slot);
    if (l.observers.mask == 0) removeLine(int(obs.line_slot));
  }
  kf.points.clear();
  kf.lines.clear();
  kf.id = 0;
}

void Map::removePoint(int point_slot) {
  MapPoint& p = s_->points[point_slot];
  if (p.id == 0) return;
  for (std::size_t k = 0; k < kMaxMapKeyframes; ++k) {
    if (p.observers.has(int(k))) removePointObservation(int(k), point_slot);
  }
  p.id = 0;
  (void)s_->free_points.push_back(uint32_t(point_slot));
}

void Map::removeLine(int line_slot) {
  MapLine& l = s_->lines[line_slot];
  if (l.id == 0) return;
  for (std::size_t k = 0; k < kMaxMapKeyframes; ++k) {
    if (l.observers.has(int(k))) removeLineObservation(int(k), line_slot);
  }
  l.id = 0;
  (void)s_->free_lines.push_back(uint32_t(line_slot));
}

bool Map::addPointObservation(int kf_slot, const KeyframePointObservation& obs) {
  Keyframe& kf = s_->keyframes[kf_slot];
  MapPoint& p = s_->points[obs.point_slot];
  if (p.observers.has(kf_slot) || kf.points.full()) return false;
  p.observers.obs_index[kf_slot] = uint16_t(kf.points.size());
  p.observers.mask |= KeyframeMask(1) << kf_slot;
  (void)kf.points.push_back(obs);
  return true;
}

bool Map::addLineObservation(int kf_slot, const KeyframeLineObservation& obs) {
  Keyframe& kf = s_->keyframes[kf_slot];
  MapLine& l = s_->lines[obs.line_slot];
  if (l.observers.has(kf_slot) || kf.lines.full()) return false;
  l.observers.obs_index[kf_slot] = uint16_t(kf.lines.size());
  l.observers.mask |= KeyframeMask(1) << kf_slot;
  (void)kf.lines.push_back(obs);
  return true;
}

// Swap-remove from the keyframe's list; the landmark that moved into the hole gets its index fixed.
void Map::removePointObservation(int kf_slot, int point_slot) {
  MapPoint& p = s_->points[point_slot];
  if (!p.observers.has(kf_slot)) return;
  Keyframe& kf = s_->keyframes[kf_slot];
  const uint16_t index = p.observers.obs_index[kf_slot];
  const std::size_t last = kf.points.size() - 1;
  if (index != last) {
    kf.points[index] = kf.points[last];
    s_->points[kf.points[index].point_slot].observers.obs_index[kf_slot] = index;
  }
  kf.points.pop_back();
  p.observers.mask &= ~(KeyframeMask(1) << kf_slot);
}

void Map::removeLineObservation(int kf_slot, int line_slot) {
  MapLine& l = s_->lines[line_slot];
  if (!l.observers.has(kf_slot)) return;
  Keyframe& kf = s_->keyframes[kf_slot];
  const uint16_t index = l.observers.obs_index[kf_slot];
  const std::size_t last = kf.lines.size() - 1;
  if (index != last) {
    kf.lines[index] = kf.lines[last];
    s_->lines[kf.lines[index].line_slot].observers.obs_index[kf_slot] = index;
  }
  kf.lines.pop_back();
  l.observers.mask &= ~(KeyframeMask(1) << kf_slot);
}

int Map::findKeyframeSlot(uint32_t id) const {
  if (id == 0) return -1;
  for (std::size_t i = 0; i < kMaxMapKeyframes; ++i) {
    if (s_->keyframes[i].id == id) return int(i);
  }
  return -1;
}

int Map::oldestKeyframeSlot() const {
  int best = -1;
  for (std::size_t i = 0; i < kMaxMapKeyframes; ++i) {
    const uint32_t id = s_->keyframes[i].id;
    if (id != 0 && (best < 0 || id < s_->keyframes[best].id)) best = int(i);
  }
  return best;
}

int Map::newestKeyframeSlot() const {
  int best = -1;
  for (std::size_t i = 0; i < kMaxMapKeyframes; ++i) {
    const uint32_t id = s_->keyframes[i].id;
    if (id != 0 && (best < 0 || id > s_->keyframes[best].id)) best = int(i);
  }
  return best;
}

void Map::covisibility(int kf_slot, std::array<int, kMaxMapKeyframes>& shared) const {
  shared.fill(0);
  const Keyframe& kf = s_->keyframes[kf_slot];
  auto accumulate = [&shared](KeyframeMask mask) {
    while (mask) {
      const int bit = __builtin_ctz(mask);
      ++shared[bit];
      mask &= mask - 1;
    }
  };
  for (const auto& obs : kf.points) accumulate(s_->points[obs.point_slot].observers.mask);
  for (const auto& obs : kf.lines) accumulate(s_->lines[obs.line_slot].observers.mask);
  shared[kf_slot] = 0;
}

MapCounts Map::counts() const {
  MapCounts c;
  for (const auto& kf : s_->keyframes) {
    if (kf.id == 0) continue;
    ++c.keyframes;
    c.point_observations += kf.points.size();
    c.line_observations += kf.lines.size();
  }
  c.points = kMaxMapPoints - s_->free_points.size();
  c.lines = kMaxMapLines - s_->free_lines.size();
  return c;
}

}  // namespace plumb
