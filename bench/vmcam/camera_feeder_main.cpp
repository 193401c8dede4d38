// plumb_vmcam_feeder: plays a recording into two v4l2loopback devices the way a UVC depth camera
// presents itself (colour as YUYV, depth as 16-bit millimetres), for the virtual-machine camera
// bench (scripts/vm_camera_test.sh, docs/DRIVERS.md "The virtual-machine camera bench").
//
//   plumb_vmcam_feeder feed --source SPEC --colour DEV --depth DEV --out-dir DIR
//                           [--fps F (10)] [--frames N (all)] [--gt FILE (SPEC/groundtruth.txt)]
//                           [--hold 1] [--wait-for FILE] [--pause-while FILE]
//   plumb_vmcam_feeder match --sent DIR/sent.txt --trajectory TRAJ [--received-out FILE]
//   plumb_vmcam_feeder select --recording REC --indices FILE --out OUT
//
// feed: loads every frame first (a TUM folder, e.g. one `plumb synth` wrote, or a synth: spec) and
// converts colour to YUYV (BT.601 limited range) and depth to millimetres; then, paced at F Hz,
// write()s them to the loopback output nodes (v4l2loopback stamps each write with
// CLOCK_MONOTONIC). Depth goes out as V4L2_PIX_FMT_Y16 because v4l2loopback 0.12 does not list
// Z16; both are 16-bit little-endian, and plumb's depth node accepts either. It also writes, in DIR:
//   replay.plumbrec  the frames exactly as plumb decodes them (YUYV -> BGR, depth in mm), stamped
//                    with the time of their write: "a replay of the same frames";
//   groundtruth.txt  the true poses at those stamps (synth: specs, or a folder's groundtruth.txt
//                    associated to the frames within 20 ms);
//   camera.txt       the source's intrinsics with depth_factor 1000 (millimetres);
//   sent.txt         `index t_colour t_depth t_colour_start` per frame (CLOCK_MONOTONIC seconds: when
//                    each write() returned, and when the colour write() started).
// The stamps of the replay and of groundtruth.txt are when the colour write() returned, within a
// write's duration of the driver's own stamp. Every write has its own index in every output file:
// --wait-for repeats frame 0 until the file exists, --hold 1 repeats the last frame after the
// sequence until SIGTERM (which ends the feed cleanly). --pause-while: while FILE exists nothing is
// written (the camera is unplugged), but the schedule runs on and the frames due meanwhile are
// never sent (the camera was moving): the bench's hot-plug check.
// match: which sent frames the trajectory starts and ends at, and how many sent between them have
// no trajectory line (lost on the way). Prints `first_frame K last_frame J live_frames M matched M
// unmatched U restamped R lost L` (R: see the v4l2loopback REQBUFS quirk in match());
// --received-out lists `index live_stamp` for the frames the trajectory has.
// select: the frames of REC whose sequence numbers FILE lists (`index live_stamp` lines, as match
// writes them), stamped with the live stamps, as recording OUT: the replay of exactly the frames
// a live run received, at the times it received them.
#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "drivers/dataset/camera_file.h"
#include "drivers/open/open_source.h"
#include "drivers/recording/recording_source.h"
#include "drivers/recording/recording_writer.h"
#include "drivers/synth/synth_spec.h"
#include "drivers/trajectory/trajectory_io.h"
#include "drivers/v4l2/pixel_formats.h"

namespace {

using plumb::Status;

volatile std::sig_atomic_t g_stop_requested = 0;
void requestStop(int) { g_stop_requested = 1; }

int64_t monotonicNs() {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  return int64_t(t.tv_sec) * 1000000000 + t.tv_nsec;
}

uint8_t clampByte(int v) { return uint8_t(std::clamp(v, 0, 255)); }

// BGR -> YUYV, BT.601 limited range (the encoding UVC cameras use); chroma from the pixel pair's mean.
void bgrToYuyv(const cv::Mat& bgr, std::vector<uint8_t>* yuyv) {
  yuyv->resize(std::size_t(bgr.cols) * bgr.rows * 2);
  uint8_t* out = yuyv->data();
  for (int r = 0; r < bgr.rows; ++r) {
    const uint8_t* in = bgr.ptr<uint8_t>(r);
    for (int c = 0; c + 1 < bgr.cols; c += 2, in += 6, out += 4) {
      const int b0 = in[0], g0 = in[1], r0 = in[2], b1 = in[3], g1 = in[4], r1 = in[5];
      out[0] = clampByte(((66 * r0 + 129 * g0 + 25 * b0 + 128) >> 8) + 16);
      out[2] = clampByte(((66 * r1 + 129 * g1 + 25 * b1 + 128) >> 8) + 16);
      const int rm = (r0 + r1 + 1) / 2, gm = (g0 + g1 + 1) / 2, bm = (b0 + b1 + 1) / 2;
      out[1] = clampByte(((-38 * rm - 74 * gm + 112 * bm + 128) >> 8) + 128);
      out[3] = clampByte(((112 * rm - 94 * gm - 18 * bm + 128) >> 8) + 128);
    }
  }
}

// Raw depth in `depth_factor` units per metre -> millimetres (what a RealSense sends as Z16).
void depthToMillimetres(const cv::Mat& depth_raw, double depth_factor, cv::Mat* mm) {
  mm->create(depth_raw.rows, depth_raw.cols, CV_16UC1);
  const double scale = 1000.0 / depth_factor;
  for (int r = 0; r < depth_raw.rows; ++r) {
    const uint16_t* in = depth_raw.ptr<uint16_t>(r);
    uint16_t* out = mm->ptr<uint16_t>(r);
    for (int c = 0; c < depth_raw.cols; ++c) out[c] = uint16_t(std::min(65535.0, std::round(in[c] * scale)));
  }
}

Status openOutput(const std::string& path, uint32_t fourcc, int width, int height, int bytes_per_pixel, int* fd) {
  *fd = open(path.c_str(), O_RDWR | O_CLOEXEC);
  if (*fd < 0) return Status::Error(path + ": open failed: " + std::strerror(errno));
  v4l2_format fmt{};
  fmt.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
  fmt.fmt.pix.width = uint32_t(width);
  fmt.fmt.pix.height = uint32_t(height);
  fmt.fmt.pix.pixelformat = fourcc;
  fmt.fmt.pix.field = V4L2_FIELD_NONE;
  fmt.fmt.pix.bytesperline = uint32_t(width * bytes_per_pixel);
  fmt.fmt.pix.sizeimage = uint32_t(width * height * bytes_per_pixel);
  fmt.fmt.pix.colorspace = V4L2_COLORSPACE_SMPTE170M;
  if (ioctl(*fd, VIDIOC_S_FMT, &fmt) != 0)
    return Status::Error(path + ": VIDIOC_S_FMT (output) failed: " + std::strerror(errno));
  if (fmt.fmt.pix.pixelformat != fourcc || int(fmt.fmt.pix.width) != width || int(fmt.fmt.pix.height) != height)
    return Status::Error(path + ": the loopback device refused the output format");
  return Status::Ok();
}

// One write() of a whole frame. The driver stamps the buffer on CLOCK_MONOTONIC inside the call,
// after copying it: between *before_ns and *after_ns, close to the latter.
Status writeFrame(int fd, const std::string& path, const void* data, std::size_t size, int64_t* before_ns,
                  int64_t* after_ns) {
  *before_ns = monotonicNs();
  const ssize_t n = write(fd, data, size);
  *after_ns = monotonicNs();
  if (n != ssize_t(size))
    return Status::Error(path + ": write of " + std::to_string(size) + " bytes returned " + std::to_string(n) +
                         (n < 0 ? std::string(": ") + std::strerror(errno) : std::string()));
  return Status::Ok();
}

struct FeedOptions {
  std::string source, colour, depth, out_dir, gt;
  double fps = 10;
  long frames = -1;
  // After the last frame, keep sending it (the camera goes on looking at its last view) until
  // SIGTERM: the reader never starves, so its stall timeout never reopens the node (v4l2loopback
  // would then hand out an old frame with a new stamp), and v4l2loopback (exclusive_caps) stays a
  // capture device while the reader takes what is queued.
  bool hold = false;
  // Send frame 0 (the first one makes the loopback devices capture devices) again and again until
  // this file exists: the reader then streams and sees the whole sequence, never starving before.
  std::string wait_for;
  // While this file exists, write nothing and skip the frames due (an unplugged camera).
  std::string pause_while;
};

// One frame as it goes out: YUYV colour and depth in millimetres, and its true pose if known.
struct OutgoingFrame {
  std::vector<uint8_t> yuyv;
  cv::Mat depth_mm;
  bool has_truth = false;
  plumb::StampedPose truth;
};

// The ground-truth pose nearest in time to `t` (within 20 ms, the TUM benchmark's association).
const plumb::StampedPose* nearestPose(const std::vector<plumb::StampedPose>& poses, double t) {
  const plumb::StampedPose* best = nullptr;
  for (const plumb::StampedPose& p : poses)
    if (std::fabs(p.timestamp - t) <= 0.02 && (!best || std::fabs(p.timestamp - t) < std::fabs(best->timestamp - t)))
      best = &p;
  return best;
}

// Reads, converts and keeps every frame first, so decoding never disturbs the paced writes.
Status loadFrames(const FeedOptions& o, plumb::PinholeCamera* camera, std::vector<OutgoingFrame>* frames) {
  std::unique_ptr<plumb::FrameSource> source;
  std::vector<plumb::StampedPose> truth;
  if (plumb::isSynthSpec(o.source)) {
    std::unique_ptr<plumb::SyntheticSource> synth;
    PLUMB_RETURN_IF_ERROR(plumb::openSynthSpec(o.source, false, &synth));
    truth = plumb::syntheticGroundTruth(synth->scene(), long(synth->frameCount()));
    source = std::move(synth);
  } else {
    PLUMB_RETURN_IF_ERROR(plumb::openFrameSource(o.source, "", &source));
    const std::string gt = o.gt.empty() ? o.source + "/groundtruth.txt" : o.gt;
    if (std::ifstream(gt).good()) PLUMB_RETURN_IF_ERROR(plumb::readTumTrajectory(gt, &truth));
  }
  *camera = source->camera();
  camera->depth_factor = 1000.0;
  plumb::RgbdImage in;
  for (long index = 0; o.frames < 0 || index < o.frames; ++index) {
    const plumb::SourceResult r = source->next(in);
    if (r == plumb::SourceResult::kEndOfStream) break;
    if (r != plumb::SourceResult::kFrame) return source->lastError();
    OutgoingFrame f;
    bgrToYuyv(in.bgr, &f.yuyv);
    depthToMillimetres(in.depth_raw, in.depth_factor, &f.depth_mm);
    if (const plumb::StampedPose* pose = nearestPose(truth, in.timestamp_s)) {
      f.has_truth = true;
      f.truth = *pose;
    }
    frames->push_back(std::move(f));
  }
  return Status::Ok();
}

Status feed(const FeedOptions& o) {
  plumb::PinholeCamera camera;
  std::vector<OutgoingFrame> frames;
  const int64_t load_start = monotonicNs();
  PLUMB_RETURN_IF_ERROR(loadFrames(o, &camera, &frames));
  const double load_ms = (monotonicNs() - load_start) * 1e-6;
  int colour_fd = -1, depth_fd = -1;
  PLUMB_RETURN_IF_ERROR(openOutput(o.colour, V4L2_PIX_FMT_YUYV, camera.width, camera.height, 2, &colour_fd));
  PLUMB_RETURN_IF_ERROR(openOutput(o.depth, V4L2_PIX_FMT_Y16, camera.width, camera.height, 2, &depth_fd));
  std::unique_ptr<plumb::RecordingWriter> replay;
  plumb::RecordingWriterOptions writer_options;
  writer_options.colour_codec = writer_options.depth_codec = plumb::ImageCodec::kRaw;
  writer_options.fsync = plumb::FsyncPolicy::kNever;
  PLUMB_RETURN_IF_ERROR(plumb::RecordingWriter::open(o.out_dir + "/replay.plumbrec", camera, writer_options, &replay));
  std::FILE* sent = std::fopen((o.out_dir + "/sent.txt").c_str(), "w");
  if (!sent) return Status::Error("cannot write " + o.out_dir + "/sent.txt");
  std::fprintf(sent, "# index t_colour t_depth t_colour_start (CLOCK_MONOTONIC s; write() returned, started)\n");
  // The camera file last: it tells the bench that the feeder is about to write the first frame.
  PLUMB_RETURN_IF_ERROR(plumb::writeCameraFile(o.out_dir + "/camera.txt", camera));
  const int64_t period_ns = int64_t(1e9 / o.fps);
  plumb::RgbdImage decoded;
  std::vector<plumb::StampedPose> truth;
  int64_t due_ns = monotonicNs();
  int64_t late_ns = 0;
  int64_t max_skew_ns = 0;  // between the colour and the depth write of one frame
  // index counts writes; frame is the recording's frame sent with it: frame 0 until --wait-for's
  // file exists (the camera looks at its first view until the reader streams), then one per
  // write, then (--hold) the last one until SIGTERM.
  std::size_t index = 0, frame = 0, first_view_writes = 0, last_view_writes = 0;
  bool started = o.wait_for.empty(), summarised = false;
  std::size_t pauses = 0, frames_not_sent = 0;
  while (!frames.empty() && g_stop_requested == 0) {
    // Absolute schedule: no drift; a late frame goes at once and is counted.
    timespec due{time_t(due_ns / 1000000000), long(due_ns % 1000000000)};
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &due, nullptr);
    late_ns = std::max(late_ns, monotonicNs() - due_ns);
    due_ns += period_ns;
    const auto unplugged = [&] { return started && !o.pause_while.empty() && std::ifstream(o.pause_while).good(); };
    if (unplugged()) {
      // Nothing is written while unplugged, and the frames due meanwhile are never sent (the camera
      // moved on). Polled every 10 ms: once plugged in again the camera streams at once (so the
      // frame a reader that reopens first takes is a new one, not the last one before the outage).
      ++pauses;
      ++frames_not_sent;  // the frame due now
      if (frame + 1 < frames.size()) ++frame;
      for (; unplugged() && g_stop_requested == 0; usleep(10000)) {
        for (; monotonicNs() >= due_ns; due_ns += period_ns) {
          ++frames_not_sent;
          if (frame + 1 < frames.size()) ++frame;
        }
      }
      due_ns = monotonicNs();
      continue;
    }
    const OutgoingFrame& f = frames[frame];
    // Colour and depth are written at the same time, from two threads, like a camera whose
    // sensors are synchronised: their stamps differ by little more than the two copies do.
    int64_t t_colour_start = 0, t_colour = 0, t_depth_start = 0, t_depth = 0;
    Status depth_status;
    std::thread depth_writer([&] {
      depth_status = writeFrame(depth_fd, o.depth, f.depth_mm.data, f.depth_mm.total() * 2, &t_depth_start, &t_depth);
    });
    const Status colour_status =
        writeFrame(colour_fd, o.colour, f.yuyv.data(), f.yuyv.size(), &t_colour_start, &t_colour);
    depth_writer.join();
    PLUMB_RETURN_IF_ERROR(colour_status);
    PLUMB_RETURN_IF_ERROR(depth_status);
    max_skew_ns = std::max<int64_t>(max_skew_ns, std::llabs(t_depth - t_colour));
    std::fprintf(sent, "%zu %.6f %.6f %.6f\n", index, t_colour * 1e-9, t_depth * 1e-9, t_colour_start * 1e-9);
    std::fflush(sent);
    // The replay gets exactly what plumb decodes, stamped like the live frames.
    plumb::yuyvToBgr(f.yuyv.data(), camera.width, camera.height, std::size_t(camera.width) * 2, decoded.bgr);
    f.depth_mm.copyTo(decoded.depth_raw);
    decoded.sequence = uint64_t(index);
    decoded.timestamp_s = t_colour * 1e-9;
    decoded.depth_timestamp_s = t_depth * 1e-9;
    decoded.t_sensor_ns = t_colour;
    decoded.depth_factor = 1000.0;
    PLUMB_RETURN_IF_ERROR(replay->append(decoded));
    ++index;
    if (f.has_truth) {
      plumb::StampedPose pose = f.truth;
      pose.timestamp = t_colour * 1e-9;
      truth.push_back(pose);
    }
    if (frame + 1 == frames.size() && summarised) ++last_view_writes;
    if (frame + 1 == frames.size() && !summarised) {
      std::printf(
          "feeder: wrote %zu frames at %.1f Hz (loading %.0f ms/frame, at most %.1f ms late, colour-depth skew at "
          "most %.1f ms; the first view %zu times)%s\n",
          frames.size(), o.fps, load_ms / double(frames.size()), late_ns * 1e-6, max_skew_ns * 1e-6,
          first_view_writes, o.hold ? "; holding the last view" : "");
      std::fflush(stdout);
      summarised = true;
    }
    if (!started) {
      ++first_view_writes;
      started = std::ifstream(o.wait_for).good();
      if (!started) continue;
    }
    if (frame + 1 < frames.size()) {
      ++frame;
    } else if (!o.hold) {
      break;
    }
  }
  std::fclose(sent);
  close(colour_fd);
  close(depth_fd);
  PLUMB_RETURN_IF_ERROR(replay->close());
  if (!truth.empty()) PLUMB_RETURN_IF_ERROR(plumb::writeTumTrajectory(o.out_dir + "/groundtruth.txt", truth));
  if (last_view_writes > 0) std::printf("feeder: then %zu frames of the last view\n", last_view_writes);
  if (pauses > 0) std::printf("feeder: paused %zu time(s) (unplugged): %zu frame(s) never sent\n", pauses, frames_not_sent);
  return Status::Ok();
}

// Timestamps of a trajectory file, one per input frame: pose lines and `# <t> lost|dropped` markers.
std::vector<double> trajectoryStamps(const std::string& path) {
  std::vector<double> stamps;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    std::string first;
    fields >> first;
    if (first.empty()) continue;
    if (first == "#") {
      std::string t, what;
      fields >> t >> what;
      if (what == "lost" || what == "dropped") stamps.push_back(std::atof(t.c_str()));
      continue;
    }
    stamps.push_back(std::atof(first.c_str()));
  }
  return stamps;
}

int match(const std::string& sent_path, const std::string& trajectory_path, const std::string& received_out) {
  struct Sent {
    double start, end;  // the colour write() call
  };
  std::vector<Sent> sent;
  std::ifstream in(sent_path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    long index = 0;
    double t_colour = 0, t_depth = 0, t_start = 0;
    if (std::sscanf(line.c_str(), "%ld %lf %lf %lf", &index, &t_colour, &t_depth, &t_start) == 4)
      sent.push_back({t_start, t_colour});
  }
  const std::vector<double> live = trajectoryStamps(trajectory_path);
  if (sent.empty() || live.empty()) {
    std::fprintf(stderr, "match: %s has %zu frames, %s %zu\n", sent_path.c_str(), sent.size(),
                 trajectory_path.c_str(), live.size());
    return 1;
  }
  // A live stamp is a sent frame's when the driver took it during that frame's write() (1 ms of
  // slack for the trajectory's microsecond rounding).
  // One exception, a v4l2loopback 0.12 quirk: VIDIOC_REQBUFS re-stamps every buffer with the
  // current time (init_buffers), so the first frame a reader takes after it asked for buffers (at
  // the start, and after a reopen) carries the time of that request. A stamp after write k and
  // before write k+1 is frame k, counted apart as "restamped" (the bench allows one per REQBUFS).
  std::size_t first = sent.size(), last = 0, matched = 0, unmatched = 0, restamped = 0;
  std::FILE* received = received_out.empty() ? nullptr : std::fopen(received_out.c_str(), "w");
  for (const double t : live) {
    std::size_t k = 0;
    while (k < sent.size() && !(t >= sent[k].start - 1e-3 && t <= sent[k].end + 1e-3)) ++k;
    if (k == sent.size()) {
      std::size_t before = 0;
      while (before + 1 < sent.size() && sent[before + 1].start <= t) ++before;
      if (t > sent[before].end && (before + 1 == sent.size() || t < sent[before + 1].start)) {
        k = before;
        ++restamped;
      }
    }
    if (k == sent.size()) {
      if (unmatched++ < 3) std::fprintf(stderr, "match: live stamp %.6f was not taken during a write\n", t);
      continue;
    }
    ++matched;
    first = std::min(first, k);
    last = std::max(last, k);
    if (received) std::fprintf(received, "%zu %.6f\n", k, t);
  }
  if (received) std::fclose(received);
  // Lost: frames sent between the first and the last one received that never arrived (frames after
  // the last one were not lost: the run was stopped).
  const std::size_t span = first <= last ? last - first + 1 : 0;
  std::printf("first_frame %zu last_frame %zu live_frames %zu matched %zu unmatched %zu restamped %zu lost %ld\n",
              first, last, live.size(), matched, unmatched, restamped, long(span) - long(matched));
  return unmatched == 0 ? 0 : 1;
}

// The frames of a recording whose sequence numbers are listed with the stamps the live run saw.
int select(const std::string& recording, const std::string& indices_path, const std::string& out_path) {
  std::vector<std::pair<uint64_t, double>> wanted;  // index, live stamp
  std::ifstream indices(indices_path);
  uint64_t k = 0;
  double stamp = 0;
  while (indices >> k >> stamp) wanted.emplace_back(k, stamp);
  std::unique_ptr<plumb::RecordingSource> source;
  Status st = plumb::RecordingSource::open(recording, &source);
  std::unique_ptr<plumb::RecordingWriter> writer;
  plumb::RecordingWriterOptions options;
  options.colour_codec = options.depth_codec = plumb::ImageCodec::kRaw;
  options.fsync = plumb::FsyncPolicy::kNever;
  if (st.ok()) st = plumb::RecordingWriter::open(out_path, source->camera(), options, &writer);
  plumb::RgbdImage frame;
  std::size_t kept = 0;
  while (st.ok()) {
    const plumb::SourceResult r = source->next(frame);
    if (r == plumb::SourceResult::kEndOfStream) break;
    if (r != plumb::SourceResult::kFrame) {
      st = source->lastError();
      break;
    }
    const auto it = std::find_if(wanted.begin(), wanted.end(),
                                 [&](const std::pair<uint64_t, double>& w) { return w.first == frame.sequence; });
    if (it == wanted.end()) continue;
    frame.depth_timestamp_s += it->second - frame.timestamp_s;  // keep the colour-depth offset
    frame.timestamp_s = it->second;
    st = writer->append(frame);
    ++kept;
  }
  if (st.ok()) st = writer->close();
  if (!st.ok()) {
    std::fprintf(stderr, "select: %s\n", st.message().c_str());
    return 1;
  }
  std::printf("select: %zu of the listed %zu frames written to %s\n", kept, wanted.size(), out_path.c_str());
  return kept == wanted.size() ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string command = argc > 1 ? argv[1] : "";
  FeedOptions feed_options;
  std::string sent, trajectory, received_out, recording, indices, out;
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string key = argv[i], value = argv[i + 1];
    if (key == "--source") feed_options.source = value;
    else if (key == "--colour") feed_options.colour = value;
    else if (key == "--depth") feed_options.depth = value;
    else if (key == "--out-dir") feed_options.out_dir = value;
    else if (key == "--fps") feed_options.fps = std::atof(value.c_str());
    else if (key == "--frames") feed_options.frames = std::atol(value.c_str());
    else if (key == "--gt") feed_options.gt = value;
    else if (key == "--hold") feed_options.hold = value == "1";
    else if (key == "--wait-for") feed_options.wait_for = value;
    else if (key == "--pause-while") feed_options.pause_while = value;
    else if (key == "--sent") sent = value;
    else if (key == "--trajectory") trajectory = value;
    else if (key == "--received-out") received_out = value;
    else if (key == "--recording") recording = value;
    else if (key == "--indices") indices = value;
    else if (key == "--out") out = value;
    else {
      std::fprintf(stderr, "feeder: unknown option %s\n", key.c_str());
      return 2;
    }
  }
  if (command == "feed" && !feed_options.source.empty() && !feed_options.colour.empty() &&
      !feed_options.depth.empty() && !feed_options.out_dir.empty() && feed_options.fps > 0) {
    std::signal(SIGTERM, requestStop);
    const Status st = feed(feed_options);
    if (!st.ok()) std::fprintf(stderr, "feeder: %s\n", st.message().c_str());
    return st.ok() ? 0 : 1;
  }
  if (command == "match" && !sent.empty() && !trajectory.empty()) return match(sent, trajectory, received_out);
  if (command == "select" && !recording.empty() && !indices.empty() && !out.empty())
    return select(recording, indices, out);
  std::fprintf(stderr,
               "usage: %s feed --source SPEC --colour DEV --depth DEV --out-dir DIR [--fps F] [--frames N] [--hold 1]\n"
               "                [--wait-for FILE] [--pause-while FILE]\n"
               "       %s match --sent FILE --trajectory FILE [--received-out FILE]\n"
               "       %s select --recording FILE --indices FILE --out FILE\n",
               argv[0], argv[0], argv[0]);
  return 2;
}
