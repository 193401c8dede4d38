#include "drivers/recording/tum_folder_writer.h"

#include <cstdlib>
#include <filesystem>


#include "drivers/dataset/camera_file.h"
#include "drivers/image/png_encoder.h"

namespace plumb {
namespace {

Status openList(const std::string& path, const char* header, std::FILE** file) {
  *file = std::fopen(path.c_str(), "w");
  if (!*file) return Status::Error(path + ": cannot create");
  std::fputs(header, *file);
  return Status::Ok();
}

}  // namespace

std::string formatTimestamp(double t) {
  char text[64];
  for (int decimals = 6; decimals <= 17; ++decimals) {
    std::snprintf(text, sizeof text, "%.*f", decimals, t);
    if (std::strtod(text, nullptr) == t) return text;
  }
  std::snprintf(text, sizeof text, "%.17g", t);
  return text;
}

Status TumFolderWriter::open(const std::string& dir, const PinholeCamera& camera,
                             std::unique_ptr<TumFolderWriter>* out) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(dir + "/rgb.txt", ec))
    return Status::Error(dir + ": already holds a dataset (rgb.txt); refusing to overwrite");
  fs::create_directories(dir + "/rgb", ec);
  if (!ec) fs::create_directories(dir + "/depth", ec);
  if (ec) return Status::Error(dir + ": cannot create folders: " + ec.message());
  std::unique_ptr<TumFolderWriter> writer(new TumFolderWriter());
  writer->dir_ = dir;
  PLUMB_RETURN_IF_ERROR(writeCameraFile(dir + "/camera.txt", camera));
  PLUMB_RETURN_IF_ERROR(openList(dir + "/rgb.txt", "# color images\n# timestamp filename\n",
                                 &writer->rgb_list_));
  PLUMB_RETURN_IF_ERROR(openList(dir + "/depth.txt", "# depth maps\n# timestamp filename\n",
                                 &writer->depth_list_));
  PLUMB_RETURN_IF_ERROR(openList(dir + "/associations.txt", "", &writer->associations_));
  *out = std::move(writer);
  return Status::Ok();
}

TumFolderWriter::~TumFolderWriter() { (void)close(); }

Status TumFolderWriter::append(const RgbdImage& frame) {
  if (!rgb_list_) return Status::Error(dir_ + ": append after close");
  const std::string rgb_t = formatTimestamp(frame.timestamp_s);
  const std::string depth_t = formatTimestamp(frame.depth_timestamp_s);
  const std::string rgb_name = "rgb/" + rgb_t + ".png";
  const std::string depth_name = "depth/" + depth_t + ".png";
  // Lossless PNG both ways; level 1 keeps conversion fast.
  PngEncodeOptions png;
  png.compression_level = 1;
  PLUMB_RETURN_IF_ERROR(writePngFile(dir_ + "/" + rgb_name, frame.bgr, png));
  PLUMB_RETURN_IF_ERROR(writePngFile(dir_ + "/" + depth_name, frame.depth_raw, png));
  std::fprintf(rgb_list_, "%s %s\n", rgb_t.c_str(), rgb_name.c_str());
  std::fprintf(depth_list_, "%s %s\n", depth_t.c_str(), depth_name.c_str());
  std::fprintf(associations_, "%s %s %s %s\n", rgb_t.c_str(), rgb_name.c_str(), depth_t.c_str(),
               depth_name.c_str());
  ++frames_;
  return Status::Ok();
}

Status TumFolderWriter::close() {
  bool ok = true;
  for (std::FILE** f : {&rgb_list_, &depth_list_, &associations_}) {
    if (*f && std::fclose(*f) != 0) ok = false;
    *f = nullptr;
  }
  return ok ? Status::Ok() : Status::Error(dir_ + ": writing the image lists failed");
}

}  // namespace plumb
