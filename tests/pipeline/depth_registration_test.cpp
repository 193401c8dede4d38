// Depth registration (pipeline/frontend/depth_registration.h) against analytic scenes: depth
// images are ray-cast from the depth camera onto planes, and every colour pixel's expected reading
// is ray-cast from the colour camera, independently of the code under test.
//   - a plane facing the colour camera reads its exact colour-camera z everywhere the depth camera
//     sees it (no cracks, also from a half-resolution depth camera);
//   - a tilted plane reads the analytic z of each colour pixel, within its change over one pixel;
//   - a card in front of a wall: the card wins wherever both land (z-buffer), the wall reads its
//     own z where both cameras see it, and the card's shadow in the depth camera reads 0;
//   - the same card test with the extrinsic left out fails (so the test can fail);
//   - identity geometry gives the input back; nothing is allocated per frame.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <vector>

#include "drivers/synth/synthetic_scene.h"
#include "pipeline/frontend/depth_registration.h"
#include "platform/allocation_counter.h"

namespace plumb {
namespace {

constexpr double kFactor = 5000.0;

PinholeCamera colourCamera(bool distorted) {
  PinholeCamera c;
  c.fx = 525;
  c.fy = 525;
  c.cx = 319.5;
  c.cy = 239.5;
  if (distorted) {  // the tum1 preset's lens
    c.k1 = 0.262383;
    c.k2 = -0.953104;
    c.p1 = -0.005358;
    c.p2 = 0.002628;
    c.k3 = 1.163314;
  }
  return c;
}

// Kinect-like: other focal length and principal point, 2.5 cm to the side, a few mm up and back,
// turned about half a degree (the synthetic scenes' offset depth camera, 640x480 or 320x240).
DepthCamera offsetDepthCamera(int width = 640) {
  return width == 640 ? synthOffsetDepthCamera() : synthOffsetDepthCameraQvga();
}

// A rectangle (or an unbounded plane) in the colour camera's frame: points origin + a u + b v,
// 0 <= a <= len_u, 0 <= b <= len_v.
struct Patch {
  Eigen::Vector3d origin, u, v;
  double len_u = 1e9, len_v = 1e9;
};

Patch frontoParallel(double z) { return {Eigen::Vector3d(-1e8, -1e8, z), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), 2e9, 2e9}; }

// Distance along the ray (as a multiple of `ray`, so z when ray.z() = 1) from `eye` to the patch;
// nullopt when missed.
std::optional<double> hit(const Patch& p, const Eigen::Vector3d& eye, const Eigen::Vector3d& ray) {
  const Eigen::Vector3d n = p.u.cross(p.v).normalized();
  const double denominator = n.dot(ray);
  if (std::abs(denominator) < 1e-12) return std::nullopt;
  const double s = n.dot(p.origin - eye) / denominator;
  if (s <= 0) return std::nullopt;
  const Eigen::Vector3d offset = eye + s * ray - p.origin;
  const double a = offset.dot(p.u) / p.u.squaredNorm(), b = offset.dot(p.v) / p.v.squaredNorm();
  if (a < 0 || b < 0 || a > p.len_u || b > p.len_v) return std::nullopt;
  return s;
}

// Nearest patch along the ray: its index and the parameter; -1 when nothing.
int nearest(const std::vector<Patch>& scene, const Eigen::Vector3d& eye, const Eigen::Vector3d& ray, double* s) {
  int best = -1;
  *s = 1e30;
  for (std::size_t i = 0; i < scene.size(); ++i) {
    const std::optional<double> h = hit(scene[i], eye, ray);
    if (h && *h < *s) {
      *s = *h;
      best = int(i);
    }
  }
  return best;
}

// What the depth camera delivers: its z of the nearest patch per pixel, raw units.
cv::Mat renderDepthCamera(const DepthCamera& d, const std::vector<Patch>& scene) {
  const PinholeCamera lens = depthCameraLens(d);
  const Eigen::Isometry3d T_colour_depth = d.T_colour_depth();
  const Eigen::Vector3d eye = T_colour_depth.translation();
  cv::Mat depth(d.height, d.width, CV_16UC1, cv::Scalar(0));
  for (int y = 0; y < d.height; ++y) {
    for (int x = 0; x < d.width; ++x) {
      const Eigen::Vector2d ideal = lens.undistortPoint(x, y);
      const Eigen::Vector3d ray_depth((ideal.x() - d.cx) / d.fx, (ideal.y() - d.cy) / d.fy, 1.0);
      double z = 0;
      if (nearest(scene, eye, T_colour_depth.linear() * ray_depth, &z) >= 0) {
        depth.at<uint16_t>(y, x) = uint16_t(std::lround(z * kFactor));  // parameter of a z=1 ray = z
      }
    }
  }
  return depth;
}

// The colour camera's ray through a (distorted) colour pixel, z = 1.
Eigen::Vector3d colourRay(const PinholeCamera& c, double x, double y) {
  const Eigen::Vector2d ideal = c.undistortPoint(x, y);
  return {(ideal.x() - c.cx) / c.fx, (ideal.y() - c.cy) / c.fy, 1.0};
}

// Whether the depth camera sees the colour-frame point P (inside its image, and nothing nearer).
bool depthCameraSees(const DepthCamera& d, const std::vector<Patch>& scene, const Eigen::Vector3d& P, double margin_px) {
  const Eigen::Isometry3d T_depth_colour = d.T_colour_depth().inverse();
  const Eigen::Vector3d P_depth = T_depth_colour * P;
  if (P_depth.z() <= 0) return false;
  const PinholeCamera lens = depthCameraLens(d);
  const Eigen::Vector2d px = lens.distortPoint(lens.fx * P_depth.x() / P_depth.z() + lens.cx,
                                               lens.fy * P_depth.y() / P_depth.z() + lens.cy);
  if (!lens.inImage(px.x() + 0.5, px.y() + 0.5, margin_px)) return false;
  const Eigen::Vector3d eye = d.T_colour_depth().translation();
  double s = 0;
  if (nearest(scene, eye, P - eye, &s) < 0) return false;
  return s > 1 - 1e-6;  // nothing in front of P on the way from the depth camera
}

PinholeCamera withDepthCamera(PinholeCamera colour, const DepthCamera& d) {
  colour.depth_camera = d;
  return colour;
}

TEST(DepthRegistration, IdentityGeometryGivesTheInputBack) {
  DepthCamera same;
  same.fx = same.fy = 525;
  same.cx = 319.5;
  same.cy = 239.5;
  same.width = 640;
  same.height = 480;
  const PinholeCamera camera = withDepthCamera(colourCamera(false), same);
  ASSERT_EQ(camera.validate(), "");
  cv::Mat depth(480, 640, CV_16UC1);
  cv::randu(depth, 100, 40000);  // 2 cm .. 8 m (nearer than 1 cm is dropped)
  for (int i = 0; i < 640 * 480; i += 7) depth.at<uint16_t>(i) = 0;  // holes stay holes
  DepthRegistration registration(camera);
  ASSERT_TRUE(registration.active());
  cv::Mat out;
  ASSERT_TRUE(registration.registerInto(depth, kFactor, out));
  EXPECT_EQ(cv::countNonZero(out != depth), 0);
}

TEST(DepthRegistration, InactiveForRegisteredCamerasAndWrongSizes) {
  DepthRegistration none(colourCamera(false));
  cv::Mat depth(480, 640, CV_16UC1, cv::Scalar(1000)), out;
  EXPECT_FALSE(none.active());
  EXPECT_FALSE(none.registerInto(depth, kFactor, out));
  DepthRegistration qvga(withDepthCamera(colourCamera(false), offsetDepthCamera(320)));
  EXPECT_FALSE(qvga.registerInto(depth, kFactor, out));  // 640x480 is not the depth camera's size
  EXPECT_TRUE(out.empty());
  cv::Mat wrong_type(240, 320, CV_32FC1, cv::Scalar(1));
  EXPECT_FALSE(qvga.registerInto(wrong_type, kFactor, out));
}

// A plane facing the colour camera at 2 m: every colour pixel the depth camera sees reads exactly
// 2 m (within the raw unit the input was rounded to), none is left empty.
void expectFrontoParallelPlane(const DepthCamera& d, bool distorted) {
  const PinholeCamera camera = withDepthCamera(colourCamera(distorted), d);
  ASSERT_EQ(camera.validate(), "");
  const std::vector<Patch> scene = {frontoParallel(2.0)};
  const cv::Mat depth = renderDepthCamera(d, scene);
  DepthRegistration registration(camera);
  cv::Mat out;
  ASSERT_TRUE(registration.registerInto(depth, kFactor, out));
  int checked = 0, wrong = 0, empty = 0;
  for (int y = 0; y < camera.height; ++y) {
    for (int x = 0; x < camera.width; ++x) {
      const Eigen::Vector3d P = 2.0 * colourRay(camera, x, y);
      if (!depthCameraSees(d, scene, P, 1.0)) continue;
      ++checked;
      const int raw = out.at<uint16_t>(y, x);
      if (raw == 0) {
        ++empty;
      } else if (std::abs(raw - 10000) > 1) {
        ++wrong;
      }
    }
  }
  EXPECT_GT(checked, 200000);
  EXPECT_EQ(wrong, 0);
  EXPECT_EQ(empty, 0) << "cracks between footprints";
}

TEST(DepthRegistration, PlaneFacingTheColourCameraReadsItsExactDepth) {
  expectFrontoParallelPlane(offsetDepthCamera(), false);
}

TEST(DepthRegistration, HalfResolutionDepthCameraLeavesNoCracks) {
  expectFrontoParallelPlane(offsetDepthCamera(320), false);
}

TEST(DepthRegistration, DistortedLensesAreApplied) {
  DepthCamera d = offsetDepthCamera();
  d.k1 = -0.05;  // a mild depth lens distortion too
  d.k2 = 0.01;
  expectFrontoParallelPlane(d, true);
}

// A plane tilted 30 degrees about y and 15 about x: each colour pixel reads the analytic z of its
// own ray, within how much z changes across the pixel's neighbourhood (a footprint holds one
// depth sample) plus one raw unit.
TEST(DepthRegistration, TiltedPlaneReadsTheAnalyticDepthPerPixel) {
  const DepthCamera d = offsetDepthCamera();
  const PinholeCamera camera = withDepthCamera(colourCamera(false), d);
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(0.52, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(0.26, Eigen::Vector3d::UnitX())).toRotationMatrix();
  Patch plane{Eigen::Vector3d(0, 0, 2.5) - 1e3 * (R.col(0) + R.col(1)), R.col(0), R.col(1), 2e3, 2e3};
  const std::vector<Patch> scene = {plane};
  const cv::Mat depth = renderDepthCamera(d, scene);
  DepthRegistration registration(camera);
  cv::Mat out;
  ASSERT_TRUE(registration.registerInto(depth, kFactor, out));
  int checked = 0, wrong = 0;
  double worst_excess_m = 0;
  for (int y = 1; y + 1 < camera.height; ++y) {
    for (int x = 1; x + 1 < camera.width; ++x) {
      double z = 0;
      if (nearest(scene, Eigen::Vector3d::Zero(), colourRay(camera, x, y), &z) < 0) continue;
      if (!depthCameraSees(d, scene, z * colourRay(camera, x, y), 1.0)) continue;
      double z_lo = z, z_hi = z;
      for (const int dx : {-1, 1}) {
        for (const int dy : {-1, 1}) {
          double zn = 0;
          if (nearest(scene, Eigen::Vector3d::Zero(), colourRay(camera, x + dx, y + dy), &zn) < 0) continue;
          z_lo = std::min(z_lo, zn);
          z_hi = std::max(z_hi, zn);
        }
      }
      ++checked;
      const double read = out.at<uint16_t>(y, x) / kFactor;
      const double excess = std::max(z_lo - 1 / kFactor - read, read - z_hi - 1 / kFactor);
      if (excess > 0) {
        ++wrong;
        worst_excess_m = std::max(worst_excess_m, excess);
      }
    }
  }
  EXPECT_GT(checked, 200000);
  EXPECT_EQ(wrong, 0) << "worst excess " << worst_excess_m << " m";
}

// A 40 x 30 cm card 1.2 m away in front of a wall at 3 m. Colour pixels are classified from their
// own ray: the card; the wall where the depth camera sees it too; the wall in the card's shadow
// (hidden from the depth camera). Pixels whose 3x3 neighbourhood mixes classes are not checked.
struct CardResult {
  int card = 0, card_wrong = 0, wall = 0, wall_wrong = 0, shadow = 0, shadow_wrong = 0;
  int wall_samples_landing_on_card = 0;  // z-buffer collisions the card must win
};

CardResult registerCard(const PinholeCamera& colour, const DepthCamera& true_depth_camera,
                        const DepthCamera& assumed_depth_camera) {
  const Patch card{Eigen::Vector3d(-0.2, -0.15, 1.2), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), 0.4, 0.3};
  const std::vector<Patch> scene = {card, frontoParallel(3.0)};
  const cv::Mat depth = renderDepthCamera(true_depth_camera, scene);
  const PinholeCamera camera = withDepthCamera(colour, assumed_depth_camera);
  DepthRegistration registration(camera);
  cv::Mat out;
  CardResult r;
  if (!registration.registerInto(depth, kFactor, out)) return r;
  enum Class { kNone, kCard, kWall, kShadow };
  cv::Mat classes(camera.height, camera.width, CV_8UC1, cv::Scalar(kNone));
  for (int y = 0; y < camera.height; ++y) {
    for (int x = 0; x < camera.width; ++x) {
      const Eigen::Vector3d ray = colourRay(camera, x, y);
      double z = 0;
      const int which = nearest(scene, Eigen::Vector3d::Zero(), ray, &z);
      if (which < 0) continue;
      const Eigen::Vector3d P = z * ray;
      if (!depthCameraSees(true_depth_camera, {frontoParallel(3.0)}, P, 1.0)) continue;  // outside its view
      classes.at<uint8_t>(y, x) = which == 0 ? kCard : depthCameraSees(true_depth_camera, scene, P, 1.0) ? kWall : kShadow;
    }
  }
  for (int y = 1; y + 1 < camera.height; ++y) {
    for (int x = 1; x + 1 < camera.width; ++x) {
      const uint8_t c = classes.at<uint8_t>(y, x);
      bool uniform = c != kNone;
      for (int dy = -1; dy <= 1 && uniform; ++dy)
        for (int dx = -1; dx <= 1 && uniform; ++dx) uniform = classes.at<uint8_t>(y + dy, x + dx) == c;
      if (!uniform) continue;
      const int raw = out.at<uint16_t>(y, x);
      if (c == kCard) {
        ++r.card;
        r.card_wrong += std::abs(raw - 6000) > 1;
      } else if (c == kWall) {
        ++r.wall;
        r.wall_wrong += std::abs(raw - 15000) > 1;
      } else {
        ++r.shadow;
        r.shadow_wrong += raw != 0;
      }
    }
  }
  // Wall samples of the depth camera whose colour projection falls on the card: the card must
  // win those pixels in the z-buffer.
  const PinholeCamera lens = depthCameraLens(true_depth_camera);
  const Eigen::Isometry3d T = true_depth_camera.T_colour_depth();
  for (int y = 0; y < depth.rows; ++y) {
    for (int x = 0; x < depth.cols; ++x) {
      if (depth.at<uint16_t>(y, x) < 10000) continue;  // the card (~1.2 m), not the wall (~3 m)
      const Eigen::Vector2d ideal = lens.undistortPoint(x, y);
      const Eigen::Vector3d P_depth = (depth.at<uint16_t>(y, x) / kFactor) *
                                      Eigen::Vector3d((ideal.x() - lens.cx) / lens.fx, (ideal.y() - lens.cy) / lens.fy, 1);
      const Eigen::Vector3d P_colour = T * P_depth;
      const Eigen::Vector2d px = camera.distortPoint(camera.fx * P_colour.x() / P_colour.z() + camera.cx,
                                                     camera.fy * P_colour.y() / P_colour.z() + camera.cy);
      const int cx = int(std::lround(px.x())), cy = int(std::lround(px.y()));
      if (cx > 0 && cy > 0 && cx + 1 < camera.width && cy + 1 < camera.height && classes.at<uint8_t>(cy, cx) == kCard)
        ++r.wall_samples_landing_on_card;
    }
  }
  return r;
}

TEST(DepthRegistration, CardInFrontOfAWallNearestWinsAndTheShadowStaysEmpty) {
  for (const bool distorted : {false, true}) {
    SCOPED_TRACE(distorted ? "distorted colour lens" : "pinhole colour lens");
    const DepthCamera d = offsetDepthCamera();
    const CardResult r = registerCard(colourCamera(distorted), d, d);
    EXPECT_GT(r.card, 20000);
    EXPECT_GT(r.wall, 150000);
    EXPECT_GT(r.shadow, 300);  // 2.5 cm baseline, card at 1.2 m, wall at 3 m: a ~6.6 px band
    EXPECT_GT(r.wall_samples_landing_on_card, 500) << "the scene does not test the z-buffer";
    EXPECT_EQ(r.card_wrong, 0);
    EXPECT_EQ(r.wall_wrong, 0);
    EXPECT_EQ(r.shadow_wrong, 0);
  }
}

// The same scene registered as if T_colour_depth were the identity (the extrinsic ignored): the
// card lands ~11 px off and many pixels read the wrong surface. If this did not fail, the test
// above could not catch an implementation that ignored the extrinsic.
TEST(DepthRegistration, IgnoringTheExtrinsicIsCaught) {
  const DepthCamera d = offsetDepthCamera();
  DepthCamera no_extrinsic = d;
  no_extrinsic.qx = no_extrinsic.qy = no_extrinsic.qz = 0;
  no_extrinsic.qw = 1;
  no_extrinsic.tx = no_extrinsic.ty = no_extrinsic.tz = 0;
  const CardResult r = registerCard(colourCamera(false), d, no_extrinsic);
  std::printf("extrinsic ignored: card %d/%d wrong, wall %d/%d wrong, shadow %d/%d wrong\n", r.card_wrong, r.card,
              r.wall_wrong, r.wall, r.shadow_wrong, r.shadow);
  EXPECT_GT(r.card_wrong + r.wall_wrong + r.shadow_wrong, 5000);
  DepthCamera no_rotation = d;  // the rotation alone matters too: 0.5 degrees is ~5 px
  no_rotation.qx = no_rotation.qy = no_rotation.qz = 0;
  no_rotation.qw = 1;
  const CardResult r2 = registerCard(colourCamera(false), d, no_rotation);
  std::printf("rotation ignored: card %d/%d wrong, wall %d/%d wrong, shadow %d/%d wrong\n", r2.card_wrong, r2.card,
              r2.wall_wrong, r2.wall, r2.shadow_wrong, r2.shadow);
  EXPECT_GT(r2.card_wrong + r2.wall_wrong + r2.shadow_wrong, 2000);
}

TEST(DepthRegistration, AllocatesNothingPerFrame) {
  const DepthCamera d = offsetDepthCamera();
  const PinholeCamera camera = withDepthCamera(colourCamera(true), d);
  const cv::Mat depth = renderDepthCamera(d, {frontoParallel(2.0)});
  DepthRegistration registration(camera);
  cv::Mat out;
  ASSERT_TRUE(registration.registerInto(depth, kFactor, out));  // sizes `out` once
  const AllocationScope scope;
  for (int i = 0; i < 5; ++i) ASSERT_TRUE(registration.registerInto(depth, kFactor, out));
  EXPECT_EQ(scope.count(), 0u);
}

}  // namespace
}  // namespace plumb
