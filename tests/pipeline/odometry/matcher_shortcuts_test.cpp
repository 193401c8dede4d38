// Shortcuts in the projection matcher must not change a match:
// - matchLines' direction bins (pipeline/odometry/line_direction_bins.h) must return exactly what
//   testing every line returns. The reference below is the matcher's loop before the bins (every
//   candidate against every line); random frames with lines near the angle limit, across the
//   0/180 deg wrap, degenerate and non-finite ones, compare both.
// - matchPoints' octave test on grid-ordered octaves must equal the |octave difference| test on
//   each keypoint (the reference: the loop before it), for several tolerances.
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "pipeline/odometry/line_direction_bins.h"
#include "pipeline/frontend/matcher_grid.h"
#include "pipeline/odometry/matcher.h"

namespace plumb {
namespace {

struct RefMatch {
  int candidate, line, distance;
};

std::vector<RefMatch> referenceMatchLines(const LineMatcherOptions& o, const LineCandidate* candidates, int count,
                                          const FrameFeatures& frame) {
  const int num_lines = static_cast<int>(frame.lines.size());
  std::vector<int> best_candidate(num_lines, -1), best_distance(num_lines, 1 << 20);
  const float cos_max_angle = std::cos(o.max_angle_deg * static_cast<float>(M_PI) / 180.f);
  for (int c = 0; c < count; ++c) {
    const LineCandidate& cand = candidates[c];
    const Eigen::Vector2f span = cand.end_px - cand.start_px;
    const float length = span.norm();
    if (length < 1e-3f) continue;
    const Eigen::Vector2f u = span / length;
    const Eigen::Vector2f n(-u.y(), u.x());
    int best = 1 << 20, second = 1 << 20, best_line = -1;
    for (int k = 0; k < num_lines; ++k) {
      const LineObservation& obs = frame.lines[k];
      const Eigen::Vector2f obs_span = obs.end_px - obs.start_px;
      const float obs_length = obs_span.norm();
      if (obs_length < 1e-3f) continue;
      if (std::abs(u.dot(obs_span)) < cos_max_angle * obs_length) continue;
      const Eigen::Vector2f ds = obs.start_px - cand.start_px, de = obs.end_px - cand.start_px;
      if (std::abs(n.dot(ds)) > o.max_endpoint_distance_px || std::abs(n.dot(de)) > o.max_endpoint_distance_px) continue;
      const float t0 = std::min(u.dot(ds), u.dot(de)), t1 = std::max(u.dot(ds), u.dot(de));
      const float overlap = std::min(t1, length) - std::max(t0, 0.f);
      if (overlap < o.min_overlap * std::min(length, obs_length)) continue;
      const int d = hammingDistance(cand.descriptor, frame.line_descriptors[k]);
      if (d < best) {
        second = best;
        best = d;
        best_line = k;
      } else if (d < second) {
        second = d;
      }
    }
    if (best_line < 0 || best > o.lbd_threshold || best > o.ratio * second) continue;
    if (best < best_distance[best_line]) {
      best_distance[best_line] = best;
      best_candidate[best_line] = c;
    }
  }
  std::vector<RefMatch> out;
  for (int k = 0; k < num_lines; ++k) {
    if (best_candidate[k] >= 0) out.push_back({best_candidate[k], k, best_distance[k]});
  }
  return out;
}

Eigen::Vector2f direction(float deg) {
  const float r = deg * static_cast<float>(M_PI) / 180.f;
  return {std::cos(r), std::sin(r)};
}

// Lines in a few bundles of nearly parallel, nearly collinear segments, so many candidates see
// several geometric inliers; descriptors share bits so that distances tie and ratio tests bite.
void randomFrame(std::mt19937& rng, int num_lines, FrameFeatures* frame, std::vector<LineCandidate>* candidates) {
  std::uniform_real_distribution<float> pos(0.f, 640.f), deg(0.f, 360.f), len(0.f, 120.f), jitter(-1.f, 1.f);
  std::uniform_int_distribution<int> bit(0, 255), pick(0, 5);
  frame->lines.clear();
  frame->line_descriptors.clear();
  candidates->clear();
  auto descriptor = [&](int flips) {
    Descriptor256 d;
    d.words = {0x0123456789abcdefull, 0xfedcba9876543210ull, 0x0f0f0f0f0f0f0f0full, 0x5555aaaa5555aaaaull};
    for (int i = 0; i < flips; ++i) {
      const int b = bit(rng);
      d.words[b / 64] ^= uint64_t(1) << (b % 64);
    }
    return d;
  };
  std::vector<float> bundle_deg = {deg(rng), 0.3f, 179.8f, 90.f, deg(rng)};
  for (int k = 0; k < num_lines; ++k) {
    LineObservation* obs = frame->lines.emplace_back();
    const int kind = pick(rng);
    const Eigen::Vector2f start(pos(rng), pos(rng) * 0.75f);
    if (kind == 5) {  // degenerate: zero or tiny length, or not finite
      obs->start_px = start;
      obs->end_px = k % 3 == 0 ? start : (k % 3 == 1 ? Eigen::Vector2f(start.x() + 1e-4f, start.y())
                                                     : Eigen::Vector2f(NAN, start.y()));
    } else {
      const float a = bundle_deg[kind] + 12.f * jitter(rng);  // spread across the 10 deg limit
      obs->start_px = start;
      obs->end_px = start + len(rng) * direction(a);
    }
    (void)frame->line_descriptors.push_back(descriptor(pick(rng) * 10));
  }
  for (int k = 0; k < num_lines; ++k) {
    const LineObservation& obs = frame->lines[k];
    LineCandidate* c = &candidates->emplace_back();
    // A perturbed copy of a line: its direction rotated by up to +-13 deg about its start.
    const Eigen::Vector2f span = obs.end_px - obs.start_px;
    const float a = std::atan2(span.y(), span.x()) * 180.f / static_cast<float>(M_PI) + 13.f * jitter(rng);
    c->start_px = obs.start_px + Eigen::Vector2f(3.f * jitter(rng), 3.f * jitter(rng));
    c->end_px = c->start_px + span.norm() * (1.f + 0.2f * jitter(rng)) * direction(a);
    if (k % 17 == 0) c->end_px = c->start_px;  // degenerate candidate
    if (k % 23 == 0) c->end_px.x() = INFINITY;
    c->descriptor = descriptor(pick(rng) * 8);
  }
}

void expectSameAsReference(const LineMatcherOptions& line_options, unsigned seed) {
  std::mt19937 rng(seed);
  MatcherOptions options;
  options.lines = line_options;
  ProjectionMatcher matcher(options);
  auto frame = std::make_unique<FrameFeatures>();
  auto out = std::make_unique<LineMatches>();
  std::vector<LineCandidate> candidates;
  int total = 0;
  for (int trial = 0; trial < 40; ++trial) {
    randomFrame(rng, 20 + trial * 4, frame.get(), &candidates);
    const std::vector<RefMatch> expected =
        referenceMatchLines(line_options, candidates.data(), static_cast<int>(candidates.size()), *frame);
    ASSERT_EQ(matcher.matchLines(candidates.data(), static_cast<int>(candidates.size()), *frame, *out),
              static_cast<int>(expected.size()))
        << "trial " << trial;
    for (std::size_t i = 0; i < expected.size(); ++i) {
      EXPECT_EQ((*out)[i].candidate, expected[i].candidate) << "trial " << trial;
      EXPECT_EQ((*out)[i].line, expected[i].line) << "trial " << trial;
      EXPECT_EQ((*out)[i].distance, expected[i].distance) << "trial " << trial;
    }
    total += static_cast<int>(expected.size());
  }
  EXPECT_GT(total, 100) << "the random frames must produce matches for the comparison to mean anything";
}

TEST(LineMatcherBins, MatchesEqualTestingEveryLine) {
  expectSameAsReference(LineMatcherOptions(), 1);
  expectSameAsReference(LineMatcherOptions(), 2);
}

TEST(LineMatcherBins, MatchesEqualTestingEveryLineForOtherAngleLimits) {
  for (float max_angle : {0.f, 3.f, 25.f, 80.f, 88.f, 120.f, -10.f}) {
    LineMatcherOptions o;
    o.max_angle_deg = max_angle;
    o.max_endpoint_distance_px = 40;  // more geometric inliers, so the wide angles are exercised
    SCOPED_TRACE(max_angle);
    std::mt19937 rng(7);
    MatcherOptions options;
    options.lines = o;
    ProjectionMatcher matcher(options);
    auto frame = std::make_unique<FrameFeatures>();
    auto out = std::make_unique<LineMatches>();
    std::vector<LineCandidate> candidates;
    for (int trial = 0; trial < 10; ++trial) {
      randomFrame(rng, 150, frame.get(), &candidates);
      const std::vector<RefMatch> expected =
          referenceMatchLines(o, candidates.data(), static_cast<int>(candidates.size()), *frame);
      ASSERT_EQ(matcher.matchLines(candidates.data(), static_cast<int>(candidates.size()), *frame, *out),
                static_cast<int>(expected.size()));
      for (std::size_t i = 0; i < expected.size(); ++i) {
        EXPECT_EQ((*out)[i].candidate, expected[i].candidate);
        EXPECT_EQ((*out)[i].line, expected[i].line);
      }
    }
  }
}

// The bins alone: every line that passes the matcher's angle test for a direction is in that
// direction's bin (directions swept finely, including the wrap at 0/180 deg), and the bins are
// selective (the point of them).
TEST(LineMatcherBins, BinsHoldEveryLineThatPassesTheAngleTest) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> deg(0.f, 360.f), len(0.01f, 200.f);
  const int num_lines = static_cast<int>(kMaxLines);
  std::vector<Eigen::Vector2f> spans(kMaxLines);
  std::vector<float> lengths(kMaxLines);
  for (int k = 0; k < num_lines; ++k) {
    spans[k] = len(rng) * direction(k < 20 ? 180.f * k / 20.f : deg(rng));
    lengths[k] = spans[k].norm();
  }
  const float max_angle = 10.f;
  const float cos_max_angle = std::cos(max_angle * static_cast<float>(M_PI) / 180.f);
  LineDirectionBins bins;
  bins.build(spans.data(), lengths.data(), num_lines, 1e-3f, max_angle);
  long passing = 0, listed = 0;
  for (int i = 0; i < 36000; ++i) {
    const Eigen::Vector2f u = direction(i * 0.01f);
    const LineDirectionBins::Mask& mask = bins.near(u * 37.f);
    for (int k = 0; k < num_lines; ++k) {
      const bool in_bin = (mask[k / 64] >> (k % 64)) & 1;
      listed += in_bin;
      if (std::abs(u.dot(spans[k])) < cos_max_angle * lengths[k]) continue;
      ++passing;
      ASSERT_TRUE(in_bin) << "line " << k << " passes at " << i * 0.01f << " deg but is not in its bin";
    }
  }
  EXPECT_GT(passing, 0);
  EXPECT_LT(listed, passing * 2) << "the bins should hold few more lines than pass";
}

struct RefPointMatch {
  int candidate, keypoint, distance;
};

// matchPoints before the grid-ordered octaves, without the orientation check.
std::vector<RefPointMatch> referenceMatchPoints(const PointMatcherOptions& o, float scale_factor,
                                                const PointCandidate* candidates, int count,
                                                const FrameFeatures& frame) {
  const int num_keypoints = static_cast<int>(frame.keypoints.size());
  std::vector<int> best_candidate(num_keypoints, -1), best_distance(num_keypoints, 1 << 20);
  for (int c = 0; c < count; ++c) {
    const PointCandidate& cand = candidates[c];
    const float radius = o.search_radius_px * std::pow(scale_factor, static_cast<float>(cand.octave));
    const float radius2 = radius * radius;
    int best = 1 << 20, second = 1 << 20, best_kp = -1, best_octave = -1, second_octave = -1;
    frame.keypoint_grid.forEachNear(cand.px_undist.x(), cand.px_undist.y(), radius, [&](int k) {
      const KeypointObservation& kp = frame.keypoints[k];
      if (std::abs(kp.octave - cand.octave) > o.octave_tolerance) return;
      if ((kp.px_undist - cand.px_undist).squaredNorm() > radius2) return;
      const int d = hammingDistance(cand.descriptor, frame.keypoint_descriptors[k]);
      if (d < best) {
        second = best;
        second_octave = best_octave;
        best = d;
        best_kp = k;
        best_octave = kp.octave;
      } else if (d < second) {
        second = d;
        second_octave = kp.octave;
      }
    });
    if (best_kp < 0 || best > o.hamming_threshold) continue;
    if (second_octave == best_octave && best > o.ratio * second) continue;
    if (best < best_distance[best_kp]) {
      best_distance[best_kp] = best;
      best_candidate[best_kp] = c;
    }
  }
  std::vector<RefPointMatch> out;
  for (int k = 0; k < num_keypoints; ++k) {
    if (best_candidate[k] >= 0) out.push_back({best_candidate[k], k, best_distance[k]});
  }
  return out;
}

TEST(PointMatcherOctaves, MatchesEqualTheOctaveDifferenceTest) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.f, 640.f), v(0.f, 480.f), jitter(-12.f, 12.f);
  std::uniform_int_distribution<int> octave(0, 7), bit(0, 255), flips(0, 30);
  auto frame = std::make_unique<FrameFeatures>();
  auto out = std::make_unique<PointMatches>();
  std::vector<PointCandidate> candidates;
  int total = 0;
  for (int tolerance : {1, 0, 2, 300, -1}) {
    SCOPED_TRACE(tolerance);
    MatcherOptions options;
    options.points.check_orientation = false;
    options.points.octave_tolerance = tolerance;
    ProjectionMatcher matcher(options);
    for (int trial = 0; trial < 10; ++trial) {
      frame->clear();
      candidates.clear();
      auto descriptor = [&](int n) {
        Descriptor256 d;
        d.words = {0x0123456789abcdefull, 0xfedcba9876543210ull, 0x0f0f0f0f0f0f0f0full, 0x5555aaaa5555aaaaull};
        for (int i = 0; i < n; ++i) {
          const int b = bit(rng);
          d.words[b / 64] ^= uint64_t(1) << (b % 64);
        }
        return d;
      };
      const int num_keypoints = 300 + 60 * trial;
      for (int k = 0; k < num_keypoints; ++k) {
        KeypointObservation* kp = frame->keypoints.emplace_back();
        kp->px_undist = Eigen::Vector2f(u(rng), v(rng));
        kp->octave = static_cast<int8_t>(octave(rng));
        (void)frame->keypoint_descriptors.push_back(descriptor(flips(rng)));
      }
      frame->keypoint_grid.setBounds(0, 0, 640, 480);
      frame->keypoint_grid.build(num_keypoints, [&](int i) { return frame->keypoints[i].px_undist; });
      for (int k = 0; k < num_keypoints; k += 2) {
        PointCandidate c;
        c.px_undist = frame->keypoints[k].px_undist + Eigen::Vector2f(jitter(rng), jitter(rng));
        c.octave = static_cast<int8_t>(octave(rng));
        c.descriptor = descriptor(flips(rng));
        candidates.push_back(c);
      }
      const std::vector<RefPointMatch> expected = referenceMatchPoints(
          options.points, options.scale_factor, candidates.data(), static_cast<int>(candidates.size()), *frame);
      ASSERT_EQ(matcher.matchPoints(candidates.data(), static_cast<int>(candidates.size()), *frame, *out),
                static_cast<int>(expected.size()));
      for (std::size_t i = 0; i < expected.size(); ++i) {
        EXPECT_EQ((*out)[i].candidate, expected[i].candidate);
        EXPECT_EQ((*out)[i].keypoint, expected[i].keypoint);
        EXPECT_EQ((*out)[i].distance, expected[i].distance);
      }
      total += static_cast<int>(expected.size());
    }
  }
  EXPECT_GT(total, 500) << "the random frames must produce matches for the comparison to mean anything";
}

}  // namespace
}  // namespace plumb
