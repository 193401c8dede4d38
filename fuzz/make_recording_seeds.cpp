// Writes the seed corpus of fuzz_recording_reader (fuzz/corpus/recording_reader/): tiny 8x6
// recordings with the real RecordingWriter, raw and PNG codecs, with and without index chunks, and
// one of an unregistered 4x3 depth camera (format version 3).
// Built on request only: cmake --build build-fuzz --target make_recording_seeds, then
//   ./build-fuzz/make_recording_seeds fuzz/corpus/recording_reader
#include <cstdio>
#include <memory>
#include <string>

#include <opencv2/core.hpp>

#include "drivers/recording/recording_writer.h"

namespace {

plumb::Status writeSeed(const std::string& path, plumb::ImageCodec codec, uint32_t index_interval, int frames,
                        bool depth_camera) {
  plumb::PinholeCamera camera;
  camera.fx = camera.fy = 10;
  camera.cx = 4;
  camera.cy = 3;
  camera.width = 8;
  camera.height = 6;
  if (depth_camera) {
    plumb::DepthCamera d;
    d.fx = d.fy = 5;
    d.cx = 2;
    d.cy = 1.5;
    d.width = 4;
    d.height = 3;
    d.tx = 0.01;
    camera.depth_camera = d;
  }
  plumb::RecordingWriterOptions options;
  options.colour_codec = options.depth_codec = codec;
  options.index_interval_frames = index_interval;
  options.fsync = plumb::FsyncPolicy::kNever;
  std::unique_ptr<plumb::RecordingWriter> writer;
  PLUMB_RETURN_IF_ERROR(plumb::RecordingWriter::open(path, camera, options, &writer));
  cv::RNG rng(7);
  for (int i = 0; i < frames; ++i) {
    plumb::RgbdImage frame;
    frame.sequence = uint64_t(i);
    frame.timestamp_s = frame.depth_timestamp_s = 1.0 + i / 30.0;
    frame.bgr.create(camera.height, camera.width, CV_8UC3);
    frame.depth_raw.create(camera.depthHeight(), camera.depthWidth(), CV_16UC1);
    rng.fill(frame.bgr, cv::RNG::UNIFORM, 0, 256);
    rng.fill(frame.depth_raw, cv::RNG::UNIFORM, 0, 20000);
    PLUMB_RETURN_IF_ERROR(writer->append(frame));
  }
  return writer->close();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_recording_seeds DIR\n");
    return 2;
  }
  const std::string dir = argv[1];
  struct {
    const char* name;
    plumb::ImageCodec codec;
    uint32_t index_interval;
    int frames;
    bool depth_camera;
  } seeds[] = {{"raw_3_frames.plumbrec", plumb::ImageCodec::kRaw, 300, 3, false},
               {"png_3_frames.plumbrec", plumb::ImageCodec::kPng, 300, 3, false},
               {"raw_index_every_frame.plumbrec", plumb::ImageCodec::kRaw, 1, 4, false},
               {"png_1_frame.plumbrec", plumb::ImageCodec::kPng, 300, 1, false},
               {"raw_depth_camera_2_frames.plumbrec", plumb::ImageCodec::kRaw, 300, 2, true}};
  for (const auto& s : seeds) {
    const plumb::Status status = writeSeed(dir + "/" + s.name, s.codec, s.index_interval, s.frames, s.depth_camera);
    if (!status.ok()) {
      std::fprintf(stderr, "%s\n", status.message().c_str());
      return 1;
    }
  }
  return 0;
}
