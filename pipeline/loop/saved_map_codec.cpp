#include "pipeline/loop/saved_map_codec.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "platform/byte_io.h"

namespace plumb::loop {

namespace {

constexpr std::size_t kPoseBytes = 12 * 8;
constexpr std::size_t kMat6Bytes = 36 * 8;
constexpr std::size_t kDescriptorBytes = 32;
constexpr std::size_t kPointBytes = 6 * 4 + 1 + kDescriptorBytes;
constexpr std::size_t kLineFixedBytes = 3 * 4 + 1 + 1 + kDescriptorBytes;  // without samples
// A keyframe without points or lines: the smallest a record can be (bounds the count by the bytes).
constexpr std::size_t kKeyframeFixedBytes =
    4 + 8 + 8 + 1 + 4 + 2 * kPoseBytes + kMat6Bytes + 1 + kPoseBytes + 1 + kPoseBytes + kMat6Bytes + 8 + 4 + 4 + 4;
constexpr std::size_t kLoopEdgeBytes = 4 + 4 + kPoseBytes + kMat6Bytes;
constexpr std::size_t kCameraBytes = 9 * 8 + 2 * 4 + 3 * 8;

void writePose(ByteWriter& w, const Eigen::Isometry3d& T) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) w.f64(T.linear()(r, c));
  for (int r = 0; r < 3; ++r) w.f64(T.translation()(r));
}

void writeMat6(ByteWriter& w, const Matrix6d& m) {
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) w.f64(m(r, c));
}

void writeDescriptor(ByteWriter& w, const Descriptor256& d) {
  for (uint64_t word : d.words) w.u64(word);
}

// Reads fields and remembers the first problem (a truncated field or a bad value).
class Decoder {
 public:
  Decoder(const std::vector<uint8_t>& bytes, const char* section) : r_(bytes.data(), bytes.size()), section_(section) {}

  bool ok() const { return r_.ok() && error_.empty(); }
  std::size_t remaining() const { return r_.remaining(); }
  void fail(const std::string& what) {
    if (error_.empty()) error_ = what;
  }
  Status status() const {
    if (!error_.empty()) return Status::Error(std::string("map section ") + section_ + ": " + error_);
    if (!r_.ok()) return Status::Error(std::string("map section ") + section_ + ": ends inside a field");
    return Status::Ok();
  }
  Status finish() {
    if (ok() && r_.remaining() != 0) fail(std::to_string(r_.remaining()) + " bytes after the last field");
    return status();
  }

  uint8_t u8() { return r_.u8(); }
  uint32_t u32() { return r_.u32(); }
  uint64_t u64() { return r_.u64(); }
  int32_t i32() { return r_.i32(); }
  bool flag(const char* what) {
    const uint8_t v = r_.u8();
    if (v > 1) fail(std::string(what) + " is neither 0 nor 1");
    return v == 1;
  }
  double f64(const char* what) {
    const double v = r_.f64();
    if (!std::isfinite(v)) fail(std::string(what) + " is not finite");
    return v;
  }
  float f32(const char* what) {
    const float v = r_.f32();
    if (!std::isfinite(v)) fail(std::string(what) + " is not finite");
    return v;
  }
  Eigen::Isometry3d pose(const char* what) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    Eigen::Matrix3d R;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) R(r, c) = f64(what);
    for (int r = 0; r < 3; ++r) T.translation()(r) = f64(what);
    if (ok() && ((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-6 || R.determinant() < 0)) {
      fail(std::string(what) + " has no rotation matrix");
    }
    T.linear() = R;
    return T;
  }
  Matrix6d mat6(const char* what) {
    Matrix6d m;
    for (int r = 0; r < 6; ++r)
      for (int c = 0; c < 6; ++c) m(r, c) = f64(what);
    return m;
  }
  Descriptor256 descriptor() {
    Descriptor256 d;
    for (uint64_t& word : d.words) word = r_.u64();
    return d;
  }
  // A count bounded by `max` and by what `each` bytes per item leave room for.
  std::size_t count(const char* what, std::size_t max, std::size_t each) {
    const uint32_t n = r_.u32();
    if (!ok()) return 0;
    if (n > max) {
      fail(std::string(what) + " count " + std::to_string(n) + " exceeds the bound " + std::to_string(max));
      return 0;
    }
    if (each > 0 && n > r_.remaining() / each) {
      fail(std::string(what) + " count " + std::to_string(n) + " needs more bytes than the section has");
      return 0;
    }
    return n;
  }

 private:
  ByteReader r_;
  const char* section_;
  std::string error_;
};

void encodeCamera(const PinholeCamera& c, ByteWriter& w) {
  for (double v : {c.fx, c.fy, c.cx, c.cy, c.k1, c.k2, c.p1, c.p2, c.k3}) w.f64(v);
  w.i32(c.width);
  w.i32(c.height);
  w.f64(c.depth_factor);
  w.f64(c.baseline_m);
  w.f64(c.rolling_shutter_readout_s);
}

Status decodeCamera(const std::vector<uint8_t>& bytes, PinholeCamera* c) {
  Decoder d(bytes, "CAMR");
  for (double* v : {&c->fx, &c->fy, &c->cx, &c->cy, &c->k1, &c->k2, &c->p1, &c->p2, &c->k3}) *v = d.f64("camera");
  c->width = d.i32();
  c->height = d.i32();
  c->depth_factor = d.f64("depth factor");
  c->baseline_m = d.f64("baseline");
  c->rolling_shutter_readout_s = d.f64("rolling shutter readout");
  PLUMB_RETURN_IF_ERROR(d.finish());
  const std::string problem = c->validate();
  if (!problem.empty()) return Status::Error("map camera: " + problem);
  return Status::Ok();
}

void encodeKeyframe(const SavedKeyframe& k, ByteWriter& w) {
  const LoopKeyframe& r = k.record;
  w.u32(r.id);
  w.u64(r.frame_sequence);
  w.f64(r.timestamp_s);
  w.u8(r.new_segment);
  w.u32(r.previous_id);
  writePose(w, r.T_previous_this);
  writePose(w, r.T_world_cam);
  writeMat6(w, r.covariance);
  w.u8(r.covariance_valid);
  writePose(w, k.T_world_cam);
  w.u8(k.has_edge);
  writePose(w, k.T_previous_this);
  writeMat6(w, k.edge_covariance);
  w.f64(k.edge_length_m);
  w.u32(k.previous_map_id);
  w.u32(uint32_t(r.points.size()));
  for (std::size_t i = 0; i < r.points.size(); ++i) {
    const LoopPoint& p = r.points[i];
    for (int j = 0; j < 3; ++j) w.f32(p.P_cam[j]);
    w.f32(p.px.x());
    w.f32(p.px.y());
    w.f32(p.u_right);
    w.u8(uint8_t(p.octave));
    writeDescriptor(w, r.point_descriptors[i]);
  }
  w.u32(uint32_t(r.lines.size()));
  for (std::size_t i = 0; i < r.lines.size(); ++i) {
    const LoopLine& l = r.lines[i];
    for (int j = 0; j < 3; ++j) w.f32(l.l[j]);
    w.u8(uint8_t(l.octave));
    w.u8(l.num_samples);
    for (std::size_t s = 0; s < l.num_samples; ++s)
      for (int j = 0; j < 3; ++j) w.f32(l.samples_cam[s][j]);
    writeDescriptor(w, r.line_descriptors[i]);
  }
}

int8_t octave(Decoder& d) {
  const int8_t o = int8_t(d.u8());
  if (o < 0 || o >= kPyramidLevels) d.fail("octave " + std::to_string(o) + " outside 0.." + std::to_string(kPyramidLevels - 1));
  return o;
}

void decodeKeyframe(Decoder& d, SavedKeyframe* k) {
  LoopKeyframe& r = k->record;
  r.id = d.u32();
  r.frame_sequence = d.u64();
  r.timestamp_s = d.f64("timestamp");
  r.new_segment = d.flag("new_segment");
  r.previous_id = d.u32();
  r.T_previous_this = d.pose("record T_previous_this");
  r.T_world_cam = d.pose("record T_world_cam");
  r.covariance = d.mat6("covariance");
  r.covariance_valid = d.flag("covariance_valid");
  k->T_world_cam = d.pose("graph T_world_cam");
  k->has_edge = d.flag("has_edge");
  k->T_previous_this = d.pose("edge T_previous_this");
  k->edge_covariance = d.mat6("edge covariance");
  k->edge_length_m = d.f64("edge length");
  k->previous_map_id = d.u32();
  r.clearFeatures();
  const std::size_t points = d.count("points", kMaxLoopPoints, kPointBytes);
  for (std::size_t i = 0; i < points && d.ok(); ++i) {
    LoopPoint p;
    for (int j = 0; j < 3; ++j) p.P_cam[j] = d.f32("point");
    p.px.x() = d.f32("pixel");
    p.px.y() = d.f32("pixel");
    p.u_right = d.f32("u_right");
    p.octave = octave(d);
    (void)r.points.push_back(p);
    (void)r.point_descriptors.push_back(d.descriptor());
  }
  const std::size_t lines = d.count("lines", kMaxLoopLines, kLineFixedBytes);
  for (std::size_t i = 0; i < lines && d.ok(); ++i) {
    LoopLine l;
    for (int j = 0; j < 3; ++j) l.l[j] = d.f32("line");
    l.octave = octave(d);
    l.num_samples = d.u8();
    if (l.num_samples > kMaxLineSamples) {
      d.fail("line samples " + std::to_string(l.num_samples) + " exceed " + std::to_string(kMaxLineSamples));
      break;
    }
    for (std::size_t s = 0; s < l.num_samples; ++s)
      for (int j = 0; j < 3; ++j) l.samples_cam[s][j] = d.f32("line sample");
    (void)r.lines.push_back(l);
    (void)r.line_descriptors.push_back(d.descriptor());
  }
}

Status decodeKeyframes(const std::vector<uint8_t>& bytes, const SavedMapLimits& limits, SavedMap* map) {
  Decoder d(bytes, "KFRM");
  const std::size_t n = d.count("keyframe", limits.max_keyframes, kKeyframeFixedBytes);
  map->keyframes.clear();
  map->keyframes.reserve(n);
  uint32_t previous_id = 0;
  for (std::size_t i = 0; i < n && d.ok(); ++i) {
    auto k = std::make_unique<SavedKeyframe>();
    decodeKeyframe(d, k.get());
    // The run that loads the map numbers its new keyframes after the largest loaded id: an id near
    // 2^32 would wrap them to small ids that never join the loop closer (and vanish on re-save).
    if (d.ok() && k->record.id > kMaxSavedKeyframeId) {
      d.fail("keyframe id " + std::to_string(k->record.id) + " beyond " + std::to_string(kMaxSavedKeyframeId) +
             " (ids must leave room for the keyframes of the runs that load the map)");
    }
    if (d.ok() && k->record.id <= previous_id) {
      d.fail("keyframe ids are not strictly ascending (" + std::to_string(k->record.id) + " after " +
             std::to_string(previous_id) + ")");
    }
    previous_id = k->record.id;
    map->keyframes.push_back(std::move(k));
  }
  return d.finish();
}

Status decodeLoopEdges(const std::vector<uint8_t>& bytes, const SavedMapLimits& limits, SavedMap* map) {
  Decoder d(bytes, "LOOP");
  const std::size_t n = d.count("loop edge", limits.max_loop_edges, kLoopEdgeBytes);
  map->loop_edges.clear();
  map->loop_edges.reserve(n);
  auto known = [&](uint32_t id) {
    for (const auto& k : map->keyframes)
      if (k->record.id == id) return true;
    return false;
  };
  for (std::size_t i = 0; i < n && d.ok(); ++i) {
    SavedLoopEdge e;
    e.candidate_id = d.u32();
    e.query_id = d.u32();
    e.T_candidate_query = d.pose("loop edge");
    e.information = d.mat6("loop edge information");
    if (d.ok() && (!known(e.candidate_id) || !known(e.query_id))) {
      d.fail("loop edge " + std::to_string(e.candidate_id) + "-" + std::to_string(e.query_id) +
             " names a keyframe the map does not hold");
    }
    map->loop_edges.push_back(e);
  }
  return d.finish();
}

}  // namespace

void encodeSavedMap(const SavedMap& map, std::vector<MapSectionBytes>* sections) {
  sections->clear();
  sections->resize(3);
  (*sections)[0].tag = kSectionCamera;
  ByteWriter camera((*sections)[0].bytes);
  encodeCamera(map.camera, camera);
  (*sections)[1].tag = kSectionKeyframes;
  ByteWriter keyframes((*sections)[1].bytes);
  keyframes.u32(uint32_t(map.keyframes.size()));
  for (const auto& k : map.keyframes) encodeKeyframe(*k, keyframes);
  (*sections)[2].tag = kSectionLoopEdges;
  ByteWriter edges((*sections)[2].bytes);
  edges.u32(uint32_t(map.loop_edges.size()));
  for (const SavedLoopEdge& e : map.loop_edges) {
    edges.u32(e.candidate_id);
    edges.u32(e.query_id);
    writePose(edges, e.T_candidate_query);
    writeMat6(edges, e.information);
  }
}

Status decodeSavedMap(const std::vector<MapSectionBytes>& sections, const SavedMapLimits& limits, SavedMap* map) {
  static_assert(kCameraBytes == 104, "camera section layout");
  const uint32_t order[3] = {kSectionCamera, kSectionKeyframes, kSectionLoopEdges};
  if (sections.size() != 3) {
    return Status::Error("a map has 3 sections (camera, keyframes, loop edges), this one " +
                         std::to_string(sections.size()));
  }
  for (int i = 0; i < 3; ++i) {
    if (sections[std::size_t(i)].tag != order[i]) {
      return Status::Error("map section " + std::to_string(i) + " has an unexpected tag 0x" + [&] {
        char hex[16];
        std::snprintf(hex, sizeof hex, "%08x", sections[std::size_t(i)].tag);
        return std::string(hex);
      }());
    }
  }
  PLUMB_RETURN_IF_ERROR(decodeCamera(sections[0].bytes, &map->camera));
  PLUMB_RETURN_IF_ERROR(decodeKeyframes(sections[1].bytes, limits, map));
  return decodeLoopEdges(sections[2].bytes, limits, map);
}

std::string cameraMismatch(const PinholeCamera& saved, const PinholeCamera& run) {
  auto differ = [](double a, double b) { return std::abs(a - b) > 1e-9 * std::max(1.0, std::abs(a)); };
  auto text = [](const char* name, double a, double b) {
    char buffer[160];
    std::snprintf(buffer, sizeof buffer, "%s %.9g in the map, %.9g in this run", name, a, b);
    return std::string(buffer);
  };
  if (saved.width != run.width || saved.height != run.height) {
    return "image size " + std::to_string(saved.width) + "x" + std::to_string(saved.height) + " in the map, " +
           std::to_string(run.width) + "x" + std::to_string(run.height) + " in this run";
  }
  const struct {
    const char* name;
    double a, b;
  } fields[] = {{"fx", saved.fx, run.fx},       {"fy", saved.fy, run.fy},
                {"cx", saved.cx, run.cx},       {"cy", saved.cy, run.cy},
                {"k1", saved.k1, run.k1},       {"k2", saved.k2, run.k2},
                {"p1", saved.p1, run.p1},       {"p2", saved.p2, run.p2},
                {"k3", saved.k3, run.k3},       {"depth factor", saved.depth_factor, run.depth_factor},
                {"baseline", saved.baseline_m, run.baseline_m}};
  for (const auto& f : fields) {
    if (differ(f.a, f.b)) return text(f.name, f.a, f.b);
  }
  return "";
}

}  // namespace plumb::loop
