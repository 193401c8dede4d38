#pragma once
// Map: the bounded storage of keyframes, map points and map lines, and the bookkeeping that links
// them (observations, covisibility). One owner: the LocalMapper. The tracker never sees a Map, only
// LocalMap snapshots built from it.
//
// Storage is fixed-size slot arrays (heap-allocated once at construction). Ids grow forever and
// are never reused; slots are. Iteration is always in slot order, so everything downstream is
// deterministic. Removing a keyframe removes its observations; a landmark left with no observer is
// freed at once (it could never be optimised again).
#include <array>
#include <cstdint>
#include <memory>

#include "pipeline/odometry/keyframe.h"
#include "pipeline/odometry/map_capacities.h"
#include "pipeline/odometry/map_landmarks.h"
#include "platform/fixed_vector.h"

namespace plumb {

struct MapCounts {
  std::size_t keyframes = 0, points = 0, lines = 0;
  std::size_t point_observations = 0, line_observations = 0;
};

class Map {
 public:
  Map();
  void clear();
  // Ids of keyframes added from now on start at `id` (a run continuing a loaded map numbers its
  // keyframes after the map's). Only forward: ids are never reused.
  void setNextKeyframeId(uint32_t id) { next_keyframe_id_ = id > next_keyframe_id_ ? id : next_keyframe_id_; }

  // --- slots ------------------------------------------------------------------------------------
  // Each returns the new slot, or -1 when the arrays are full (the caller retires something first).
  int addKeyframe();
  int addPoint();
  int addLine();
  void removeKeyframe(int kf_slot);
  void removePoint(int point_slot);
  void removeLine(int line_slot);

  // --- observations -----------------------------------------------------------------------------
  // false when the keyframe's list is full or the landmark is already observed by that keyframe.
  bool addPointObservation(int kf_slot, const KeyframePointObservation& obs);
  bool addLineObservation(int kf_slot, const KeyframeLineObservation& obs);
  void removePointObservation(int kf_slot, int point_slot);
  void removeLineObservation(int kf_slot, int line_slot);

  // --- queries ----------------------------------------------------------------------------------
  Keyframe& keyframe(int slot) { return s_->keyframes[slot]; }
  const Keyframe& keyframe(int slot) const { return s_->keyframes[slot]; }
  MapPoint& point(int slot) { return s_->points[slot]; }
  const MapPoint& point(int slot) const { return s_->points[slot]; }
  MapLine& line(int slot) { return s_->lines[slot]; }
  const MapLine& line(int slot) const { return s_->lines[slot]; }
  bool keyframeAlive(int slot) const { return s_->keyframes[slot].id != 0; }
  bool pointAlive(int slot) const { return s_->points[slot].id != 0; }
  bool lineAlive(int slot) const { return s_->lines[slot].id != 0; }

  int findKeyframeSlot(uint32_t id) const;  // -1 when not in the map
  int oldestKeyframeSlot() const;           // smallest id; -1 when empty
  int newestKeyframeSlot() const;           // largest id; -1 when empty

  // Number of landmarks (points and lines) each keyframe slot shares with `kf_slot`.
  void covisibility(int kf_slot, std::array<int, kMaxMapKeyframes>& shared) const;

  MapCounts counts() const;
  std::size_t freePointSlots() const { return s_->free_points.size(); }
  std::size_t freeLineSlots() const { return s_->free_lines.size(); }

 private:
  // Keyframes are ~130 KB each and the landmark arrays a few MB: one heap block, allocated once,
  // from kernel zero pages (solver/zero_page_allocator.h): all-zero bytes are the empty map (every
  // id 0 = free slot, every list empty), and a page becomes resident only when a slot or an
  // observation list reaches it. Free slots are never read beyond their id (a removed slot keeps
  // stale values too), and every slot is assigned whole when it is taken (addPoint, addLine) or
  // has the fields it is read by set (addKeyframe + the mapper's insertion).
  struct Storage {
    std::array<Keyframe, kMaxMapKeyframes> keyframes;
    std::array<MapPoint, kMaxMapPoints> points;
    std::array<MapLine, kMaxMapLines> lines;
    // Free-slot stacks, popped from the back; filled so that low slots are used first.
    FixedVector<uint32_t, kMaxMapPoints> free_points;
    FixedVector<uint32_t, kMaxMapLines> free_lines;
  };

  uint32_t next_keyframe_id_ = 1;
  uint32_t next_point_id_ = 1;
  uint32_t next_line_id_ = 1;
  // One past the highest landmark slot handed out since the last clear(): clear() resets only
  // those (slots above were never written, see Storage).
  uint32_t points_high_water_ = 0;
  uint32_t lines_high_water_ = 0;
  struct StorageDeleter {
    void operator()(Storage* s) const;
  };
  void fillFreeLists();
  std::unique_ptr<Storage, StorageDeleter> s_;
};

}  // namespace plumb
