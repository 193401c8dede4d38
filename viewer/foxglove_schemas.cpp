#include "viewer/foxglove_schemas.h"

namespace plumb::viewer {
namespace {

// Building blocks, spliced into the schemas below (JSON text).
const std::string kNumber = R"({"type":"number"})";
const std::string kTime =
    R"({"type":"object","title":"time","properties":{"sec":{"type":"integer","minimum":0},)"
    R"("nsec":{"type":"integer","minimum":0,"maximum":999999999}}})";
const std::string kDuration =
    R"({"type":"object","title":"duration","properties":{"sec":{"type":"integer"},)"
    R"("nsec":{"type":"integer","minimum":0,"maximum":999999999}}})";
const std::string kVector3 = R"({"type":"object","title":"foxglove.Vector3","properties":{"x":)" + kNumber +
                             R"(,"y":)" + kNumber + R"(,"z":)" + kNumber + "}}";
const std::string kPoint3 = R"({"type":"object","title":"foxglove.Point3","properties":{"x":)" + kNumber +
                            R"(,"y":)" + kNumber + R"(,"z":)" + kNumber + "}}";
const std::string kQuaternion = R"({"type":"object","title":"foxglove.Quaternion","properties":{"x":)" + kNumber +
                                R"(,"y":)" + kNumber + R"(,"z":)" + kNumber + R"(,"w":)" + kNumber + "}}";
const std::string kPose = R"({"type":"object","title":"foxglove.Pose","properties":{"position":)" + kVector3 +
                          R"(,"orientation":)" + kQuaternion + "}}";
const std::string kColor = R"({"type":"object","title":"foxglove.Color","properties":{"r":)" + kNumber +
                           R"(,"g":)" + kNumber + R"(,"b":)" + kNumber + R"(,"a":)" + kNumber + "}}";
const std::string kBytes = R"({"type":"string","contentEncoding":"base64"})";

std::string object(const std::string& title, const std::string& properties) {
  return R"({"type":"object","title":")" + title + R"(","properties":{)" + properties + "}}";
}

std::string array(const std::string& items) { return R"({"type":"array","items":)" + items + "}"; }

std::string enumOf(const std::string& title, const std::string& one_of) {
  return R"({"title":")" + title + R"(","type":"integer","oneOf":[)" + one_of + "]}";
}

std::string constant(const char* name, int value) {
  return R"({"title":")" + std::string(name) + R"(","const":)" + std::to_string(value) + "}";
}

}  // namespace

std::string poseInFrameSchema() {
  return object("foxglove.PoseInFrame",
                R"("timestamp":)" + kTime + R"(,"frame_id":{"type":"string"},"pose":)" + kPose);
}

std::string frameTransformSchema() {
  return object("foxglove.FrameTransform", R"("timestamp":)" + kTime +
                                               R"(,"parent_frame_id":{"type":"string"},)"
                                               R"("child_frame_id":{"type":"string"},"translation":)" +
                                               kVector3 + R"(,"rotation":)" + kQuaternion);
}

std::string sceneUpdateSchema() {
  const std::string line_type =
      enumOf("foxglove.LineType",
             constant("LINE_STRIP", 0) + "," + constant("LINE_LOOP", 1) + "," + constant("LINE_LIST", 2));
  const std::string line = object(
      "foxglove.LinePrimitive", R"("type":)" + line_type + R"(,"pose":)" + kPose +
                                    R"(,"thickness":{"type":"number","minimum":0},"scale_invariant":{"type":"boolean"},)"
                                    R"("points":)" + array(kPoint3) + R"(,"color":)" + kColor +
                                    R"(,"colors":)" + array(kColor) +
                                    R"(,"indices":{"type":"array","items":{"type":"integer","minimum":0}})");
  const std::string key_value =
      object("foxglove.KeyValuePair", R"("key":{"type":"string"},"value":{"type":"string"})");
  const std::string entity =
      object("foxglove.SceneEntity",
             R"("timestamp":)" + kTime + R"(,"frame_id":{"type":"string"},"id":{"type":"string"},"lifetime":)" +
                 kDuration + R"(,"frame_locked":{"type":"boolean"},"metadata":)" + array(key_value) +
                 R"(,"arrows":{"type":"array"},"cubes":{"type":"array"},"spheres":{"type":"array"},)"
                 R"("cylinders":{"type":"array"},"lines":)" + array(line) +
                 R"(,"triangles":{"type":"array"},"texts":{"type":"array"},"models":{"type":"array"})");
  const std::string deletion_type =
      enumOf("foxglove.SceneEntityDeletionType", constant("MATCHING_ID", 0) + "," + constant("ALL", 1));
  const std::string deletion = object("foxglove.SceneEntityDeletion", R"("timestamp":)" + kTime + R"(,"type":)" +
                                                                          deletion_type + R"(,"id":{"type":"string"})");
  return object("foxglove.SceneUpdate", R"("deletions":)" + array(deletion) + R"(,"entities":)" + array(entity));
}

std::string pointCloudSchema() {
  const std::string numeric_type =
      enumOf("foxglove.NumericType", constant("UNKNOWN", 0) + "," + constant("UINT8", 1) + "," + constant("INT8", 2) +
                                         "," + constant("UINT16", 3) + "," + constant("INT16", 4) + "," +
                                         constant("UINT32", 5) + "," + constant("INT32", 6) + "," +
                                         constant("FLOAT32", 7) + "," + constant("FLOAT64", 8));
  const std::string field = object("foxglove.PackedElementField", R"("name":{"type":"string"},)"
                                                                  R"("offset":{"type":"integer","minimum":0},"type":)" +
                                                                      numeric_type);
  return object("foxglove.PointCloud", R"("timestamp":)" + kTime + R"(,"frame_id":{"type":"string"},"pose":)" + kPose +
                                           R"(,"point_stride":{"type":"integer","minimum":0},"fields":)" +
                                           array(field) + R"(,"data":)" + kBytes);
}

std::string compressedImageSchema() {
  return object("foxglove.CompressedImage", R"("timestamp":)" + kTime + R"(,"frame_id":{"type":"string"},"data":)" +
                                                kBytes + R"(,"format":{"type":"string"})");
}

std::string runStatusSchema() {
  return object("plumb.Status",
                R"("timestamp":)" + kTime +
                    R"(,"mode":{"type":"string"},"state":{"type":"string","enum":["not_initialized","ok","weak","lost","dropped","ended"]},)"
                    R"("frame":{"type":"integer"},"frame_timestamp":{"type":"number"},)"
                    R"("frames":{"type":"integer"},"keyframes":{"type":"integer"},)"
                    R"("point_inliers":{"type":"integer"},"line_inliers":{"type":"integer"},)"
                    R"("landmark_inliers":{"type":"integer"},"latency_ms":{"type":"number"},)"
                    R"("latency_p99_ms":{"type":"number"},"frames_dropped":{"type":"integer"},)"
                    R"("frames_lost":{"type":"integer"},"loops":{"type":"integer"},)"
                    R"("relocalizations":{"type":"integer"},"map_points":{"type":"integer"},)"
                    R"("map_lines":{"type":"integer"},"viewer_records_dropped":{"type":"integer"},)"
                    R"("viewer_messages_dropped":{"type":"integer"},"clients":{"type":"integer"},)"
                    R"("ate_rmse_m":{"type":"number"},"source":{"type":"string"})");
}

}  // namespace plumb::viewer
