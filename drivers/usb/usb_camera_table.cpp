#include "drivers/usb/usb_camera_table.h"

namespace plumb {
namespace {

constexpr uint16_t kPrimeSense = 0x1d27;  // PrimeSense (also Asus Xtion, which uses its ids)
constexpr uint16_t kMicrosoft = 0x045e;
constexpr uint16_t kIntel = 0x8086;
constexpr uint16_t kOrbbec = 0x2bc5;

// Specific entries before the vendor-wide Orbbec range, so lookups find the most precise match.
constexpr UsbCameraModel kTable[] = {
    {kPrimeSense, 0x0600, 0x0600, "PrimeSense Carmine / Asus Xtion", CameraAccess::kOpenNI2,
     "OpenNI2 PS1080 driver"},
    {kPrimeSense, 0x0601, 0x0601, "Asus Xtion (PRO / PRO LIVE)", CameraAccess::kOpenNI2,
     "OpenNI2 PS1080 driver"},
    {kPrimeSense, 0x0609, 0x0609, "PrimeSense Carmine 1.09", CameraAccess::kOpenNI2,
     "OpenNI2 PS1080 driver"},
    {kMicrosoft, 0x02ae, 0x02ae, "Kinect for Xbox 360 (v1) camera", CameraAccess::kUnsupported,
     "needs libfreenect (OpenNI2 bridge not in Debian's OpenNI2)"},
    {kMicrosoft, 0x02bf, 0x02bf, "Kinect for Windows (v1) camera", CameraAccess::kUnsupported,
     "needs libfreenect (OpenNI2 bridge not in Debian's OpenNI2)"},
    {kMicrosoft, 0x02c4, 0x02c4, "Kinect for Windows v2", CameraAccess::kUnsupported,
     "needs libfreenect2"},
    {kMicrosoft, 0x02d8, 0x02d8, "Kinect for Xbox One (v2)", CameraAccess::kUnsupported,
     "needs libfreenect2"},
    {kIntel, 0x0ad1, 0x0ad1, "Intel RealSense D400", CameraAccess::kV4l2, "uvcvideo: colour + Z16 nodes"},
    {kIntel, 0x0ad2, 0x0ad2, "Intel RealSense D410", CameraAccess::kV4l2, "uvcvideo: Z16 depth node"},
    {kIntel, 0x0ad3, 0x0ad3, "Intel RealSense D415", CameraAccess::kV4l2, "uvcvideo: colour + Z16 nodes"},
    {kIntel, 0x0ad4, 0x0ad4, "Intel RealSense D430", CameraAccess::kV4l2, "uvcvideo: Z16 depth node"},
    {kIntel, 0x0ad5, 0x0ad5, "Intel RealSense D430 (MM)", CameraAccess::kV4l2, "uvcvideo: Z16 depth node"},
    {kIntel, 0x0ad6, 0x0ad6, "Intel RealSense D4xx on USB2", CameraAccess::kV4l2, "uvcvideo, reduced modes"},
    {kIntel, 0x0b07, 0x0b07, "Intel RealSense D435", CameraAccess::kV4l2, "uvcvideo: colour + Z16 nodes"},
    {kIntel, 0x0b3a, 0x0b3a, "Intel RealSense D435i", CameraAccess::kV4l2, "uvcvideo: colour + Z16 nodes"},
    {kIntel, 0x0b5b, 0x0b5b, "Intel RealSense D405", CameraAccess::kV4l2, "uvcvideo: colour + Z16 nodes"},
    {kIntel, 0x0b5c, 0x0b5c, "Intel RealSense D455", CameraAccess::kV4l2, "uvcvideo: colour + Z16 nodes"},
    {kIntel, 0x0b64, 0x0b64, "Intel RealSense L515", CameraAccess::kV4l2, "uvcvideo: colour + Z16 nodes"},
    {kOrbbec, 0x0000, 0xffff, "Orbbec depth camera (Astra family and later)", CameraAccess::kOpenNI2,
     "Orbbec's OpenNI2 driver (not in Debian)"},
};

}  // namespace

const UsbCameraModel* lookupUsbCamera(uint16_t vendor_id, uint16_t product_id) {
  for (const UsbCameraModel& m : kTable) {
    if (m.vendor_id == vendor_id && product_id >= m.product_id_first &&
        product_id <= m.product_id_last)
      return &m;
  }
  return nullptr;
}

const char* cameraAccessName(CameraAccess access) {
  switch (access) {
    case CameraAccess::kOpenNI2: return "openni2";
    case CameraAccess::kV4l2: return "v4l2";
    case CameraAccess::kUnsupported: return "none";
  }
  return "?";
}

const UsbCameraModel* usbCameraTable(std::size_t* count) {
  *count = sizeof kTable / sizeof kTable[0];
  return kTable;
}

}  // namespace plumb
