#pragma once
// KeypointGrid: a bucket grid over a frame's undistorted keypoint positions, built once per frame
// during extraction, so matching by projection looks only at keypoints near a predicted pixel
// (O(candidates x local) instead of O(candidates x keypoints)).
//
// Storage is a counting-sort layout: keypoint indices sorted by cell, and for each cell the start
// of its run. Fixed capacity, no allocation. Bounds cover the undistorted image (which spills
// outside [0,w)x[0,h) with barrel distortion); positions outside are clamped to border cells.
#include <array>
#include <cstdint>

#include <Eigen/Core>

#include "pipeline/frontend/capacities.h"

namespace plumb {

struct KeypointGrid {
  static constexpr int kCols = 64;
  static constexpr int kRows = 48;

  float min_u = 0, min_v = 0;            // undistorted-pixel bounds of the grid
  float inv_cell_w = 0, inv_cell_h = 0;  // cells per pixel
  std::array<uint16_t, kCols * kRows + 1> cell_start{};
  std::array<uint16_t, kMaxKeypoints> indices{};  // keypoint indices ordered by cell
  bool built = false;

  int cellCol(float u) const {
    const int c = static_cast<int>((u - min_u) * inv_cell_w);
    return c < 0 ? 0 : (c >= kCols ? kCols - 1 : c);
  }
  int cellRow(float v) const {
    const int r = static_cast<int>((v - min_v) * inv_cell_h);
    return r < 0 ? 0 : (r >= kRows ? kRows - 1 : r);
  }

  // Sets the bounds (undistorted pixels) the kCols x kRows cells cover.
  void setBounds(float u0, float v0, float u1, float v1) {
    min_u = u0;
    min_v = v0;
    inv_cell_w = kCols / (u1 - u0);
    inv_cell_h = kRows / (v1 - v0);
  }

  // Buckets `count` positions (px_undist of the keypoints, in order) into the grid.
  template <typename PositionFn>
  void build(int count, PositionFn position_of) {
    std::array<uint16_t, kCols * kRows> counts{};
    for (int i = 0; i < count; ++i) {
      const Eigen::Vector2f p = position_of(i);
      ++counts[cellRow(p.y()) * kCols + cellCol(p.x())];
    }
    cell_start[0] = 0;
    for (int c = 0; c < kCols * kRows; ++c) cell_start[c + 1] = cell_start[c] + counts[c];
    for (int c = 0; c < kCols * kRows; ++c) counts[c] = cell_start[c];
    for (int i = 0; i < count; ++i) {
      const Eigen::Vector2f p = position_of(i);
      indices[counts[cellRow(p.y()) * kCols + cellCol(p.x())]++] = static_cast<uint16_t>(i);
    }
    built = true;
  }

  // Calls fn(keypoint_index) for every keypoint in the cells overlapping the square window
  // centred at (u, v) with half-size `radius` (callers check the exact distance).
  template <typename Fn>
  void forEachNear(float u, float v, float radius, Fn fn) const {
    forEachSlotNear(u, v, radius, [&](int slot) { fn(indices[slot]); });
  }
  // The same visiting order, calling fn(slot) with the position in `indices` (for callers that
  // keep per-keypoint data in grid order).
  template <typename Fn>
  void forEachSlotNear(float u, float v, float radius, Fn fn) const {
    const int c0 = cellCol(u - radius), c1 = cellCol(u + radius);
    const int r0 = cellRow(v - radius), r1 = cellRow(v + radius);
    for (int r = r0; r <= r1; ++r) {
      const int row = r * kCols;
      for (int i = cell_start[row + c0]; i < cell_start[row + c1 + 1]; ++i) fn(i);
    }
  }
};

}  // namespace plumb
