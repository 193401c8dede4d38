#include "viewer/foxglove_messages.h"

#include <cmath>
#include <cstring>

#include "viewer/json_writer.h"

namespace plumb::viewer {
namespace {

constexpr const char* kWorldFrame = "world";
constexpr const char* kCameraFrame = "camera";
constexpr int kGeometryDigits = 7;  // float positions: 7 significant digits are all they hold

void writeTime(JsonWriter& w, double seconds) {
  double whole = std::floor(seconds);
  int64_t nsec = int64_t(std::llround((seconds - whole) * 1e9));
  if (nsec >= 1000000000) {
    whole += 1;
    nsec -= 1000000000;
  }
  w.beginObject().key("sec").number(uint64_t(std::max(0.0, whole))).key("nsec").number(uint64_t(nsec)).endObject();
}

// q and -q are one rotation: qw >= 0, as the TUM writer prints it.
Eigen::Quaterniond canonical(const Eigen::Quaterniond& q) {
  return q.w() < 0 ? Eigen::Quaterniond(-q.w(), -q.x(), -q.y(), -q.z()) : q;
}

void writeVector(JsonWriter& w, const Eigen::Vector3d& v) {
  w.beginObject().key("x").number(v.x()).key("y").number(v.y()).key("z").number(v.z()).endObject();
}

void writeQuaternion(JsonWriter& w, const Eigen::Quaterniond& q_in) {
  const Eigen::Quaterniond q = canonical(q_in);
  w.beginObject().key("x").number(q.x()).key("y").number(q.y()).key("z").number(q.z()).key("w").number(q.w()).endObject();
}

void writeColor(JsonWriter& w, const Rgba& c) {
  w.beginObject();
  w.key("r").number(double(c.r), 4).key("g").number(double(c.g), 4).key("b").number(double(c.b), 4);
  w.key("a").number(double(c.a), 4);
  w.endObject();
}

void writeIdentityPose(JsonWriter& w) {
  w.beginObject();
  w.key("position").beginObject().key("x").number(0).key("y").number(0).key("z").number(0).endObject();
  w.key("orientation").beginObject().key("x").number(0).key("y").number(0).key("z").number(0).key("w").number(1);
  w.endObject().endObject();
}

}  // namespace

std::string poseInFrameJson(double timestamp_s, const Eigen::Vector3d& t, const Eigen::Quaterniond& q) {
  JsonWriter w;
  w.beginObject();
  w.key("timestamp");
  writeTime(w, timestamp_s);
  w.key("frame_id").string(kWorldFrame);
  w.key("pose").beginObject();
  w.key("position");
  writeVector(w, t);
  w.key("orientation");
  writeQuaternion(w, q);
  w.endObject();
  w.endObject();
  return w.text();
}

std::string frameTransformJson(double timestamp_s, const Eigen::Vector3d& t, const Eigen::Quaterniond& q) {
  JsonWriter w;
  w.beginObject();
  w.key("timestamp");
  writeTime(w, timestamp_s);
  w.key("parent_frame_id").string(kWorldFrame);
  w.key("child_frame_id").string(kCameraFrame);
  w.key("translation");
  writeVector(w, t);
  w.key("rotation");
  writeQuaternion(w, q);
  w.endObject();
  return w.text();
}

std::string sceneUpdateJson(double timestamp_s, const std::vector<LineEntity>& entities) {
  JsonWriter w;
  w.beginObject();
  w.key("deletions").beginArray().beginObject();
  w.key("timestamp");
  writeTime(w, timestamp_s);
  w.key("type").number(1);  // ALL: the entities below replace what the channel drew
  w.key("id").string("");
  w.endObject().endArray();
  w.key("entities").beginArray();
  for (const LineEntity& e : entities) {
    w.beginObject();
    w.key("timestamp");
    writeTime(w, timestamp_s);
    w.key("frame_id").string(kWorldFrame);
    w.key("id").string(e.id);
    w.key("lifetime").beginObject().key("sec").number(0).key("nsec").number(0).endObject();
    w.key("frame_locked").boolean(false);
    w.key("metadata").beginArray().endArray();
    for (const char* empty : {"arrows", "cubes", "spheres", "cylinders", "triangles", "texts", "models"}) {
      w.key(empty).beginArray().endArray();
    }
    w.key("lines").beginArray();
    for (const LinePrimitive& l : e.lines) {
      w.beginObject();
      w.key("type").number(int(l.type));
      w.key("pose");
      writeIdentityPose(w);
      w.key("thickness").number(l.thickness_px);
      w.key("scale_invariant").boolean(true);
      w.key("points").beginArray();
      for (const Eigen::Vector3f& p : l.points) {
        w.beginObject();
        w.key("x").number(double(p.x()), kGeometryDigits);
        w.key("y").number(double(p.y()), kGeometryDigits);
        w.key("z").number(double(p.z()), kGeometryDigits);
        w.endObject();
      }
      w.endArray();
      w.key("color");
      writeColor(w, l.color);
      w.key("colors").beginArray();
      for (const Rgba& c : l.colors) writeColor(w, c);
      w.endArray();
      w.key("indices").beginArray().endArray();
      w.endObject();
    }
    w.endArray();
    w.endObject();
  }
  w.endArray();
  w.endObject();
  return w.text();
}

std::string pointCloudJson(double timestamp_s, const std::vector<Eigen::Vector3f>& points) {
  std::vector<uint8_t> data(points.size() * 12);
  for (std::size_t i = 0; i < points.size(); ++i) {
    // float32 little-endian (the only byte order plumb builds for: x86-64, aarch64).
    std::memcpy(&data[i * 12], points[i].data(), 12);
  }
  JsonWriter w;
  w.beginObject();
  w.key("timestamp");
  writeTime(w, timestamp_s);
  w.key("frame_id").string(kWorldFrame);
  w.key("pose");
  writeIdentityPose(w);
  w.key("point_stride").number(12);
  w.key("fields").beginArray();
  const char* names[3] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i) {
    w.beginObject().key("name").string(names[i]).key("offset").number(4 * i).key("type").number(7).endObject();
  }
  w.endArray();
  w.key("data").string(base64(data.data(), data.size()));
  w.endObject();
  return w.text();
}

std::string compressedImageJson(double timestamp_s, const std::vector<uint8_t>& jpeg) {
  JsonWriter w;
  w.beginObject();
  w.key("timestamp");
  writeTime(w, timestamp_s);
  w.key("frame_id").string(kCameraFrame);
  w.key("data").string(base64(jpeg.data(), jpeg.size()));
  w.key("format").string("jpeg");
  w.endObject();
  return w.text();
}

std::string base64(const uint8_t* bytes, std::size_t size) {
  static const char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((size + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < size; i += 3) {
    const uint32_t v = uint32_t(bytes[i]) << 16 | uint32_t(bytes[i + 1]) << 8 | bytes[i + 2];
    out += kAlphabet[v >> 18];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += kAlphabet[v & 63];
  }
  if (i < size) {
    const bool two = i + 1 < size;
    const uint32_t v = uint32_t(bytes[i]) << 16 | (two ? uint32_t(bytes[i + 1]) << 8 : 0);
    out += kAlphabet[v >> 18];
    out += kAlphabet[(v >> 12) & 63];
    out += two ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

void appendFrustum(const Eigen::Vector3f& t, const Eigen::Quaternionf& q, float depth_m,
                   std::vector<Eigen::Vector3f>* lines) {
  // A 4:3 image plane (z forward, x right, y down: the camera's optical frame).
  const float hx = 0.5f * depth_m, hy = 0.375f * depth_m;
  const Eigen::Vector3f corners_cam[4] = {{-hx, -hy, depth_m}, {hx, -hy, depth_m}, {hx, hy, depth_m}, {-hx, hy, depth_m}};
  Eigen::Vector3f corners[4];
  for (int i = 0; i < 4; ++i) corners[i] = q * corners_cam[i] + t;
  for (int i = 0; i < 4; ++i) {
    lines->push_back(t);
    lines->push_back(corners[i]);
    lines->push_back(corners[i]);
    lines->push_back(corners[(i + 1) % 4]);
  }
}

}  // namespace plumb::viewer
