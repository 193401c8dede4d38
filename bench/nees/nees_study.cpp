// plumb_nees_study: Monte Carlo NEES of the published covariances on synthetic scenes with known
// sensor noise (docs/UNCERTAINTY.md). One line per seed, then the pooled table row per quantity.
//
//   plumb_nees_study [--preset textured] [--seeds 50] [--first-seed 1] [--frames 150] [--no-lines]
//                    [--map-error | --no-map-error] [--no-variance-factor] [--pooled-variance-factor]
//                    [--relative-scale S] [--tracked-scale S] [--motion-scale S]
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "tests/support/nees_run.h"

namespace {

void printRow(const char* name, const plumb::test::PooledNees& p) {
  std::printf("%-18s n %6zu  NEES/dof %.3f  (translation %.3f, rotation %.3f)  inside 95%% %.1f%%\n", name, p.count,
              p.meanPerDof(), p.translationPerDof(), p.rotationPerDof(), 100.0 * p.inside95());
}

}  // namespace

int main(int argc, char** argv) {
  std::string preset = "textured";
  int seeds = 50, first_seed = 1, frames = 150;
  plumb::SystemOptions system_options;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--preset" && has_value) preset = argv[++i];
    else if (a == "--seeds" && has_value) seeds = std::atoi(argv[++i]);
    else if (a == "--first-seed" && has_value) first_seed = std::atoi(argv[++i]);
    else if (a == "--frames" && has_value) frames = std::atoi(argv[++i]);
    else if (a == "--no-lines") system_options.odometry.tracker.use_lines = false;
    else if (a == "--map-error") system_options.odometry.uncertainty.tracked_map_error = true;
    else if (a == "--no-map-error") system_options.odometry.uncertainty.tracked_map_error = false;
    else if (a == "--no-variance-factor") system_options.odometry.uncertainty.use_variance_factor = false;
    else if (a == "--pooled-variance-factor") system_options.odometry.uncertainty.variance_components = false;
    else if (a == "--relative-scale" && has_value) system_options.odometry.uncertainty.relative_scale = std::atof(argv[++i]);
    else if (a == "--tracked-scale" && has_value) system_options.odometry.uncertainty.tracked_scale = std::atof(argv[++i]);
    else if (a == "--motion-scale" && has_value) system_options.odometry.uncertainty.motion_scale = std::atof(argv[++i]);
    else {
      std::fprintf(stderr, "plumb_nees_study: unknown or incomplete option %s\n", a.c_str());
      return 2;
    }
  }
  plumb::test::PooledNees relative, world, motion;
  double ate_sum = 0;
  int runs = 0;
  for (int seed = first_seed; seed < first_seed + seeds; ++seed) {
    const plumb::test::NeesRun run =
        plumb::test::runSyntheticNees(plumb::test::kinectSynth(preset, uint64_t(seed), frames), system_options);
    if (!run.status.ok()) {
      std::printf("seed %d: %s\n", seed, run.status.message().c_str());
      continue;
    }
    const plumb::NeesResult& n = run.nees;
    std::printf("seed %3d: ATE %.4f m, frames %zu; NEES/dof keyframe %.3f (n %zu), tracked %.3f (n %zu), motion %.3f (n %zu)\n",
                seed, run.ate_m, run.frames_with_pose, n.keyframe_relative.mean_per_dof, n.keyframe_relative.count,
                n.tracked_world.mean_per_dof, n.tracked_world.count, n.frame_motion.mean_per_dof, n.frame_motion.count);
    std::fflush(stdout);
    relative.add(n.keyframe_relative);
    world.add(n.tracked_world);
    motion.add(n.frame_motion);
    ate_sum += run.ate_m;
    ++runs;
  }
  std::printf("pooled over %d runs of synth:%s, %d frames, Kinect-like noise, lines %s (mean ATE %.4f m):\n", runs,
              preset.c_str(), frames, system_options.odometry.tracker.use_lines ? "on" : "off",
              runs ? ate_sum / runs : 0.0);
  printRow("keyframe_relative", relative);
  printRow("tracked_world", world);
  printRow("frame_motion", motion);
  return runs > 0 ? 0 : 1;
}
