#pragma once
// Turns the renderer's exact colour and depth into what an RGB-D sensor delivers: 8-bit colour
// with optional Gaussian pixel noise, and 16-bit raw depth with an optional Kinect-like model.
//
// Depth model (all optional, off = exact depth rounded to the raw unit):
//  - range: z outside [min_depth_m, max_depth_m] reads 0 (decided on the true z, so range
//    dropouts do not flicker with noise);
//  - axial noise: z + sigma(z) * N(0,1), sigma(z) = k * z^2 (Khoshelham & Elberink 2012);
//  - edge holes: a pixel reads 0 when a neighbour within 1 px (2 px for a pseudo-random half of
//    the pixels, in the row) is nearer by more than 0.05 m + 0.03 z: the far side of every depth
//    discontinuity loses 1-2 px, like the shadow band of a structured-light sensor.
// Noise is a hash of (seed, frame, pixel): the same for every run and any visiting order.
#include <cstdint>

#include <opencv2/core.hpp>

namespace plumb::synth {

struct SensorModelOptions {
  double pixel_noise_sigma = 0;  // grey levels
  bool depth_noise = false;
  double depth_noise_k = 0.0014;  // 1/m
  bool depth_edge_holes = false;
  double min_depth_m = 0.3, max_depth_m = 8.0;
  double depth_factor = 5000;  // raw units per metre
};

// colour_bgr: CV_32FC3 (0..255, clamped here). bgr_out: CV_8UC3, (re)allocated only if needed.
void quantiseColour(const cv::Mat& colour_bgr, const SensorModelOptions& options, uint64_t seed, int frame,
                    cv::Mat& bgr_out);

// depth_m: CV_32FC1, z in metres (+inf = nothing). depth_raw_out: CV_16UC1, reallocated only if needed.
void quantiseDepth(const cv::Mat& depth_m, const SensorModelOptions& options, uint64_t seed, int frame,
                   cv::Mat& depth_raw_out);

}  // namespace plumb::synth
