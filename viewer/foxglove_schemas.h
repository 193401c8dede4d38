#pragma once
// JSON Schemas of the Foxglove message types the viewer publishes (JSON encoding, schemaEncoding
// "jsonschema"), written from Foxglove's published message definitions: field names and enum
// values as Foxglove and Lichtblick expect them, bytes as base64 strings. And plumb.Status, the
// run's state. Each function returns one schema as JSON text.
#include <string>

namespace plumb::viewer {

std::string poseInFrameSchema();     // foxglove.PoseInFrame
std::string frameTransformSchema();  // foxglove.FrameTransform
std::string sceneUpdateSchema();     // foxglove.SceneUpdate (entities with line primitives)
std::string pointCloudSchema();      // foxglove.PointCloud
std::string compressedImageSchema(); // foxglove.CompressedImage
std::string runStatusSchema();       // plumb.Status

}  // namespace plumb::viewer
