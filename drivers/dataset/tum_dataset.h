#pragma once
// TumDatasetSource: replays a folder in the TUM RGB-D layout (also ICL-NUIM in TUM format):
//   rgb/*.png  depth/*.png  rgb.txt  depth.txt  [associations.txt]  [groundtruth.txt]
// Frames are the lines of associations.txt (`t_rgb rgb/X.png t_depth depth/Y.png`); without it,
// rgb.txt and depth.txt are paired with the benchmark's rule (greedy unique pairs by smallest
// |dt|, |dt| < 0.02 s), see drivers/common/timestamp_association.h.
//
// Every list problem (missing/empty/unparsable list, non-monotonic or duplicate timestamps) and
// every listed image file that does not exist is reported by open(); image content problems
// (corrupt or truncated PNG, wrong size or bit depth, a file gone since open) by next()/load().
// Messages name the file and, for lists, the line.
//
// Buffers: image files are read into a reused byte buffer (POSIX read) and PNGs decoded by libpng
// straight into the caller's RgbdImage Mats (PngDecoder, its structures in a fixed arena), so a
// replayed frame allocates nothing once the Mats have their size. JPEG colour images are decoded
// by libjpeg (drivers/image/jpeg_decoder.h; allocates per image); other formats are an error.
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "drivers/common/frame_source.h"
#include "platform/input_file.h"

namespace plumb {

class PngDecoder;

// One associated RGB-D pair; paths are relative to the dataset folder.
struct TumFrameEntry {
  double rgb_timestamp_s = 0;
  std::string rgb_path;
  double depth_timestamp_s = 0;
  std::string depth_path;
};

class TumDatasetSource : public FrameSource {
 public:
  ~TumDatasetSource() override;
  // Reads the lists of `dir` and checks them; `camera` must already be valid and its size is the
  // size every image must have. max_frames > 0: only the first max_frames frames are read and
  // checked (associations.txt is not read past them: a run of 5 frames over a million-line list
  // costs 5 lines).
  static Status open(const std::string& dir, const PinholeCamera& camera,
                     std::unique_ptr<TumDatasetSource>* out, std::size_t max_frames = 0);

  // Sequential replay: frame 0, 1, ... then kEndOfStream. kError sets lastError(); the cursor
  // still advances, so the next call tries the following frame.
  SourceResult next(RgbdImage& out) override;
  const PinholeCamera& camera() const override { return camera_; }
  std::string describe() const override { return "tum:" + dir_; }
  const Status& lastError() const override { return last_error_; }

  // Random access (does not move the replay cursor). Fills out.sequence = i.
  Status load(std::size_t i, RgbdImage& out);
  std::size_t size() const { return frames_.size(); }
  std::size_t frameCount() const override { return frames_.size(); }
  double timestamp(std::size_t i) const { return frames_[i].rgb_timestamp_s; }
  const TumFrameEntry& entry(std::size_t i) const { return frames_[i]; }
  // True when the pairs were read from associations.txt (false: associated here).
  bool usedAssociationsFile() const { return used_associations_file_; }
  void rewind() { cursor_ = 0; }

 private:
  TumDatasetSource();
  Status loadImage(const std::string& path, bool is_depth, cv::Mat& dst);

  std::string dir_;
  PinholeCamera camera_;
  std::vector<TumFrameEntry> frames_;
  bool used_associations_file_ = false;
  std::size_t cursor_ = 0;
  Status last_error_;
  std::vector<std::string> rgb_files_, depth_files_;  // full paths, per frame
  // Reused read buffer for image files, grown with headroom by new[] (not zero-filled: the
  // headroom costs address space, not resident memory).
  std::unique_ptr<unsigned char[]> file_bytes_;
  std::size_t file_capacity_ = 0;
  InputFile image_file_;  // the opener of each image file, reused (no allocation per frame)
  std::unique_ptr<PngDecoder> png_;
};

}  // namespace plumb
