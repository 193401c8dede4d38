// plumb_vmcam_v4l2ctl: lists and sets a V4L2 node's controls by name, for the virtual-machine
// camera bench (scripts/vm_camera_test.sh), whose guest has no v4l-utils. It is how the bench pulls
// vivid's error-injection controls while plumb captures from the same node.
//   plumb_vmcam_v4l2ctl list DEV          one line per control: id type name min max value
//   plumb_vmcam_v4l2ctl set DEV NAME VAL  sets (or, for a button, presses) the control NAME
// Exit 0 done, 1 the node or the control failed (message on stderr), 2 usage.
#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "retry_ioctl.h"

namespace {

const char* typeName(uint32_t type) {
  switch (type) {
    case V4L2_CTRL_TYPE_INTEGER: return "int";
    case V4L2_CTRL_TYPE_BOOLEAN: return "bool";
    case V4L2_CTRL_TYPE_MENU: return "menu";
    case V4L2_CTRL_TYPE_BUTTON: return "button";
    case V4L2_CTRL_TYPE_INTEGER64: return "int64";
    case V4L2_CTRL_TYPE_CTRL_CLASS: return "class";
    case V4L2_CTRL_TYPE_STRING: return "string";
    case V4L2_CTRL_TYPE_BITMASK: return "bitmask";
    case V4L2_CTRL_TYPE_INTEGER_MENU: return "intmenu";
    default: return "other";
  }
}

bool isPlainValue(uint32_t type) {
  return type == V4L2_CTRL_TYPE_INTEGER || type == V4L2_CTRL_TYPE_BOOLEAN ||
         type == V4L2_CTRL_TYPE_MENU || type == V4L2_CTRL_TYPE_BITMASK ||
         type == V4L2_CTRL_TYPE_INTEGER_MENU;
}

using plumb::vmcam::retryIoctl;

// Calls `visit` for every control the node has (VIDIOC_QUERY_EXT_CTRL with NEXT_CTRL).
template <typename Visit>
void forEachControl(int fd, Visit visit) {
  v4l2_query_ext_ctrl query{};
  query.id = V4L2_CTRL_FLAG_NEXT_CTRL | V4L2_CTRL_FLAG_NEXT_COMPOUND;
  while (retryIoctl(fd, VIDIOC_QUERY_EXT_CTRL, &query) == 0) {
    if (!visit(query)) return;
    query.id |= V4L2_CTRL_FLAG_NEXT_CTRL | V4L2_CTRL_FLAG_NEXT_COMPOUND;
  }
}

int list(int fd) {
  forEachControl(fd, [fd](const v4l2_query_ext_ctrl& q) {
    long long value = 0;
    if (isPlainValue(q.type) && !(q.flags & V4L2_CTRL_FLAG_WRITE_ONLY)) {
      v4l2_control c{q.id, 0};
      if (retryIoctl(fd, VIDIOC_G_CTRL, &c) == 0) value = c.value;
    }
    std::printf("0x%08x %-7s \"%s\" min %lld max %lld value %lld%s\n", q.id, typeName(q.type), q.name,
                static_cast<long long>(q.minimum), static_cast<long long>(q.maximum), value,
                (q.flags & V4L2_CTRL_FLAG_DISABLED) ? " (disabled)" : "");
    return true;
  });
  return 0;
}

int set(int fd, const char* device, const std::string& name, long value) {
  bool found = false;
  uint32_t id = 0;
  forEachControl(fd, [&](const v4l2_query_ext_ctrl& q) {
    if (name != q.name) return true;
    found = true;
    id = q.id;
    return false;
  });
  if (!found) {
    std::fprintf(stderr, "%s: no control named \"%s\" (list shows them)\n", device, name.c_str());
    return 1;
  }
  v4l2_control c{id, static_cast<int32_t>(value)};
  if (retryIoctl(fd, VIDIOC_S_CTRL, &c) != 0) {
    std::fprintf(stderr, "%s: setting \"%s\" to %ld failed: %s\n", device, name.c_str(), value,
                 std::strerror(errno));
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string command = argc > 1 ? argv[1] : "";
  if (!((command == "list" && argc == 3) || (command == "set" && argc == 5))) {
    std::fprintf(stderr, "usage: %s list DEV | set DEV NAME VALUE\n", argv[0]);
    return 2;
  }
  const int fd = open(argv[2], O_RDWR | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    std::fprintf(stderr, "%s: open failed: %s\n", argv[2], std::strerror(errno));
    return 1;
  }
  const int status = command == "list" ? list(fd) : set(fd, argv[2], argv[3], std::strtol(argv[4], nullptr, 0));
  close(fd);
  return status;
}
