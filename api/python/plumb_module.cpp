// The Python module `plumb` (pybind11) over the public API (api/plumb/odometry.h):
//
//   import plumb, numpy as np
//   odo = plumb.Odometry(camera="tum1")                 # preset, camera file, or a dict of values
//   r = odo.track(rgb, depth, t)                         # uint8 HxWx3, uint16 HxW, seconds
//   r.state, r.pose (4x4 or None), r.covariance (6x6 or None)
//   odo.finished()  ->  [(t, 4x4 or None), ...]          # poses refined by local BA, in order
//   plumb.read_trajectory(path), plumb.evaluate(gt, est) # ATE/RPE exactly as `plumb eval`
//
// Arrays are checked before anything runs: a wrong dtype raises TypeError, a wrong shape or a
// non-contiguous array ValueError, each with a message that says what was expected. Errors of the
// library (plumb::api::Status) raise RuntimeError (ValueError for a bad configuration).
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstring>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "api/plumb/odometry.h"

namespace py = pybind11;
namespace api = plumb::api;

namespace {

void throwIfError(const api::Status& st, bool value_error = false) {
  if (st.ok) return;
  if (value_error) throw py::value_error(st.message);
  throw std::runtime_error(st.message);
}

std::string shapeText(const py::array& a) {
  std::string text = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) text += (i ? ", " : "") + std::to_string(a.shape(i));
  return text + (a.ndim() == 1 ? ",)" : ")");
}

// Checks dtype (TypeError), shape and C-contiguity (ValueError) of an image argument.
template <typename T>
void checkImage(const py::array& a, const char* name, const char* dtype, int channels, int width, int height) {
  if (!py::isinstance<py::array_t<T>>(a) || a.dtype().kind() != py::dtype::of<T>().kind() ||
      a.itemsize() != py::ssize_t(sizeof(T))) {
    throw py::type_error(std::string(name) + " must be a numpy array of dtype " + dtype + ", got dtype " +
                         std::string(py::str(a.dtype())));
  }
  const bool shape_ok = channels == 1 ? (a.ndim() == 2 && a.shape(0) == height && a.shape(1) == width)
                                      : (a.ndim() == 3 && a.shape(0) == height && a.shape(1) == width &&
                                         a.shape(2) == channels);
  if (!shape_ok) {
    const std::string expected = channels == 1 ? "(" + std::to_string(height) + ", " + std::to_string(width) + ")"
                                               : "(" + std::to_string(height) + ", " + std::to_string(width) + ", " +
                                                     std::to_string(channels) + ")";
    throw py::value_error(std::string(name) + " must have shape " + expected + " (the camera's HxW" +
                          (channels == 1 ? "" : "x3") + "), got " + shapeText(a));
  }
  if (!(a.flags() & py::array::c_style)) {
    throw py::value_error(std::string(name) + " must be C-contiguous (use numpy.ascontiguousarray)");
  }
}

py::array_t<double> matrixToNumpy(const double* column_major, int rows, int cols) {
  py::array_t<double> out({rows, cols});
  auto m = out.mutable_unchecked<2>();
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) m(r, c) = column_major[c * rows + r];
  return out;
}

py::object poseToNumpy(const Eigen::Isometry3d& T) { return matrixToNumpy(T.matrix().data(), 4, 4); }

// A camera dict's value: a Python int or float (not a bool, not a string), else a TypeError naming
// the key; the values are then checked like a camera file's (sensor/camera.h bounds).
double cameraNumber(const std::string& key, const py::handle& value) {
  if (py::isinstance<py::bool_>(value) || !(py::isinstance<py::int_>(value) || py::isinstance<py::float_>(value))) {
    throw py::type_error("camera value '" + key + "' must be a number, got " +
                         std::string(py::str(value.get_type().attr("__name__"))));
  }
  return value.cast<double>();
}

int cameraInteger(const std::string& key, const py::handle& value) {
  if (py::isinstance<py::bool_>(value) || !py::isinstance<py::int_>(value)) {
    throw py::type_error("camera value '" + key + "' must be an int, got " +
                         std::string(py::str(value.get_type().attr("__name__"))));
  }
  const long long v = value.cast<long long>();
  if (v < 1 || v > 1'000'000) throw py::value_error("camera value '" + key + "' " + std::to_string(v) + " is out of range");
  return int(v);
}

api::CameraValues cameraFromDict(const py::dict& d) {
  api::CameraValues v;
  for (auto item : d) {
    if (!py::isinstance<py::str>(item.first)) throw py::type_error("camera keys must be strings");
    const std::string key = py::str(item.first);
    const py::handle value = item.second;
    if (key == "fx") v.fx = cameraNumber(key, value);
    else if (key == "fy") v.fy = cameraNumber(key, value);
    else if (key == "cx") v.cx = cameraNumber(key, value);
    else if (key == "cy") v.cy = cameraNumber(key, value);
    else if (key == "k1") v.k1 = cameraNumber(key, value);
    else if (key == "k2") v.k2 = cameraNumber(key, value);
    else if (key == "p1") v.p1 = cameraNumber(key, value);
    else if (key == "p2") v.p2 = cameraNumber(key, value);
    else if (key == "k3") v.k3 = cameraNumber(key, value);
    else if (key == "width") v.width = cameraInteger(key, value);
    else if (key == "height") v.height = cameraInteger(key, value);
    else if (key == "depth_factor") v.depth_factor = cameraNumber(key, value);
    else if (key == "baseline") v.baseline_m = cameraNumber(key, value);
    else if (key == "rolling_shutter_readout") v.rolling_shutter_readout_s = cameraNumber(key, value);
    else throw py::value_error("unknown camera key '" + key + "' (fx fy cx cy k1 k2 p1 p2 k3 width height "
                               "depth_factor baseline rolling_shutter_readout)");
  }
  for (const char* required : {"fx", "fy", "cx", "cy"}) {
    if (!d.contains(required)) throw py::value_error(std::string("camera dict needs '") + required + "' (fx fy cx cy are required)");
  }
  return v;
}

py::dict cameraToDict(const api::CameraValues& v) {
  py::dict d;
  d["fx"] = v.fx, d["fy"] = v.fy, d["cx"] = v.cx, d["cy"] = v.cy;
  d["k1"] = v.k1, d["k2"] = v.k2, d["p1"] = v.p1, d["p2"] = v.p2, d["k3"] = v.k3;
  d["width"] = v.width, d["height"] = v.height, d["depth_factor"] = v.depth_factor, d["baseline"] = v.baseline_m;
  d["rolling_shutter_readout"] = v.rolling_shutter_readout_s;
  return d;
}

py::dict countersToDict(const api::Counters& c) {
  py::dict d;
  d["frames"] = c.frames, d["frames_ok"] = c.frames_ok, d["frames_weak"] = c.frames_weak;
  d["frames_lost"] = c.frames_lost, d["keyframes"] = c.keyframes, d["relocalizations"] = c.relocalizations;
  d["map_segments"] = c.map_segments, d["extraction_failures"] = c.extraction_failures;
  return d;
}

// What track() returns: plain Python values and NumPy arrays.
struct PyTrackResult {
  uint64_t sequence = 0;
  double timestamp = 0;
  std::string state;
  bool has_pose = false;
  py::object pose = py::none();        // 4x4 T_world_cam or None
  py::object covariance = py::none();  // 6x6 of [rho; phi] of T_cam_world, or None
  bool keyframe = false, relocalized = false, new_map = false;
};

PyTrackResult toPy(const api::TrackOutput& out) {
  PyTrackResult r;
  r.sequence = out.sequence;
  r.timestamp = out.timestamp_s;
  r.state = api::toString(out.state);
  r.has_pose = out.has_pose;
  if (out.has_pose) r.pose = poseToNumpy(out.T_world_cam);
  if (out.covariance_valid) r.covariance = matrixToNumpy(out.covariance.data(), 6, 6);
  r.keyframe = out.keyframe, r.relocalized = out.relocalized, r.new_map = out.new_map;
  return r;
}

// A trajectory in Python: {"timestamps": (N,), "poses": (N,4,4), "valid": (N,) bool}.
py::dict trajectoryToDict(const std::vector<api::FinishedPose>& poses) {
  const py::ssize_t n = py::ssize_t(poses.size());
  py::array_t<double> t(n);
  py::array_t<double> T({n, py::ssize_t(4), py::ssize_t(4)});
  py::array_t<bool> valid(n);
  auto tm = t.mutable_unchecked<1>();
  auto Tm = T.mutable_unchecked<3>();
  auto vm = valid.mutable_unchecked<1>();
  for (py::ssize_t i = 0; i < n; ++i) {
    tm(i) = poses[i].timestamp_s;
    vm(i) = poses[i].valid;
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) Tm(i, r, c) = poses[i].T_world_cam.matrix()(r, c);
  }
  py::dict d;
  d["timestamps"] = t, d["poses"] = T, d["valid"] = valid;
  return d;
}

std::vector<api::FinishedPose> trajectoryFromObject(const py::handle& object, const char* name) {
  if (!py::isinstance<py::dict>(object)) {
    throw py::type_error(std::string(name) + " must be a trajectory dict (timestamps, poses, valid) as "
                         "read_trajectory returns");
  }
  const py::dict d = py::reinterpret_borrow<py::dict>(object);
  if (!d.contains("timestamps") || !d.contains("poses")) {
    throw py::value_error(std::string(name) + " needs 'timestamps' (N,) and 'poses' (N,4,4)");
  }
  const auto t = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(d["timestamps"]);
  const auto T = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(d["poses"]);
  if (!t || !T || t.ndim() != 1 || T.ndim() != 3 || T.shape(0) != t.shape(0) || T.shape(1) != 4 || T.shape(2) != 4) {
    throw py::value_error(std::string(name) + ": 'timestamps' must be (N,) and 'poses' (N,4,4)");
  }
  py::array_t<bool> valid;
  const bool has_valid = d.contains("valid");  // a default array_t is an empty array, not null
  if (has_valid) {
    valid = py::array_t<bool, py::array::c_style | py::array::forcecast>::ensure(d["valid"]);
    if (!valid || valid.ndim() != 1 || valid.shape(0) != t.shape(0)) throw py::value_error(std::string(name) + ": 'valid' must be (N,)");
  }
  std::vector<api::FinishedPose> poses(std::size_t(t.shape(0)));
  auto tm = t.unchecked<1>();
  auto Tm = T.unchecked<3>();
  for (std::size_t i = 0; i < poses.size(); ++i) {
    poses[i].sequence = i;
    poses[i].timestamp_s = tm(py::ssize_t(i));
    poses[i].valid = has_valid ? valid.at(py::ssize_t(i)) : true;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) poses[i].T_world_cam.matrix()(r, c) = Tm(py::ssize_t(i), r, c);
  }
  return poses;
}

py::object statsToDict(bool valid, const api::ErrorStats& s, std::size_t pairs, const char* unit) {
  if (!valid) return py::none();
  py::dict d;
  d["rmse"] = s.rmse, d["mean"] = s.mean, d["median"] = s.median, d["min"] = s.min, d["max"] = s.max;
  d["pairs"] = pairs, d["unit"] = unit;
  return d;
}

api::PixelFormat parseFormat(const std::string& format) {
  if (format == "rgb") return api::PixelFormat::kRgb;
  if (format == "bgr") return api::PixelFormat::kBgr;
  throw py::value_error("format must be 'rgb' or 'bgr', got '" + format + "'");
}

// One Odometry object serves one thread at a time: track() releases the GIL while it runs, and the
// system behind it is not made for concurrent calls. A second call while one is running (from
// another thread) is REFUSED with a RuntimeError, never run concurrently and never queued silently
// (docs/API.md "Python": use one object per thread, or a lock around the calls).
class BusyGuard {
 public:
  BusyGuard(std::mutex& busy, const char* call) : lock_(busy, std::try_to_lock) {
    if (!lock_.owns_lock()) {
      throw std::runtime_error(std::string("Odometry.") + call +
                               ": this object is in use by another thread (one Odometry serves one thread at a time; "
                               "use one object per thread or a lock around the calls)");
    }
  }

 private:
  std::unique_lock<std::mutex> lock_;
};

class PyOdometry {
 public:
  PyOdometry(const py::object& camera, bool lines, int line_samples, int output_delay, bool loop_closing) {
    api::OdometryConfig config;
    if (py::isinstance<py::str>(camera)) {
      config.camera = api::CameraSpec::named(camera.cast<std::string>());
    } else if (py::isinstance<py::dict>(camera)) {
      config.camera = api::CameraSpec::fromValues(cameraFromDict(camera.cast<py::dict>()));
    } else {
      throw py::type_error("camera must be a preset name (tum1 tum2 tum3 icl), a camera file path or a dict of values");
    }
    config.lines = lines;
    config.line_samples = line_samples;
    config.output_delay_frames = output_delay;
    config.loop_closing = loop_closing;
    throwIfError(api::Odometry::create(config, &odometry_), true);
  }

  PyTrackResult track(const py::array& rgb, const py::array& depth, double t, const std::string& format) {
    const BusyGuard guard(busy_, "track");
    const api::CameraValues& c = odometry_->camera();
    const api::PixelFormat pixel_format = parseFormat(format);
    checkImage<uint8_t>(rgb, "rgb", "uint8", 3, c.width, c.height);
    checkImage<uint16_t>(depth, "depth", "uint16", 1, c.width, c.height);
    api::FrameView frame;
    frame.color = static_cast<const uint8_t*>(rgb.data());
    frame.depth = static_cast<const uint16_t*>(depth.data());
    frame.timestamp_s = t;
    frame.width = c.width;
    frame.height = c.height;
    frame.format = pixel_format;
    api::Status st;
    {
      py::gil_scoped_release release;  // the arrays stay alive: the caller holds them
      st = odometry_->track(frame, &out_);
    }
    // A bad frame (its timestamp: NaN, negative, not after the previous one) is the caller's
    // input: ValueError, like a wrong shape. Failures of the library are RuntimeError.
    throwIfError(st, st.message.rfind("frame:", 0) == 0);
    return toPy(out_);
  }

  py::list finished() {
    const BusyGuard guard(busy_, "finished");
    py::list list;
    api::FinishedPose pose;
    while (odometry_->popFinished(&pose)) {
      list.append(py::make_tuple(pose.timestamp_s, pose.valid ? poseToNumpy(pose.T_world_cam) : py::object(py::none())));
    }
    return list;
  }

  void finish() {
    const BusyGuard guard(busy_, "finish");
    throwIfError(odometry_->finish());
  }
  py::dict counters() {
    const BusyGuard guard(busy_, "counters");
    return countersToDict(odometry_->counters());
  }
  py::dict camera() const { return cameraToDict(odometry_->camera()); }

 private:
  std::unique_ptr<api::Odometry> odometry_;
  api::TrackOutput out_;
  std::mutex busy_;
};

class PyFrameReader {
 public:
  PyFrameReader(const std::string& spec, const std::string& camera) {
    throwIfError(api::FrameReader::open(spec, camera, &reader_), true);
  }
  // (rgb uint8 HxWx3, depth uint16 HxW, t) or None at the end.
  py::object next(const std::string& format) {
    const api::PixelFormat pixel_format = parseFormat(format);
    double t = 0;
    bool got = false;
    throwIfError(reader_->next(&bgr_, &depth_, &t, &got));
    if (!got) return py::none();
    const int w = reader_->camera().width, h = reader_->camera().height;
    if (bgr_.size() != std::size_t(w) * h * 3) throw std::runtime_error("frame size differs from the camera's");
    py::array_t<uint8_t> color({h, w, 3});
    py::array_t<uint16_t> depth({h, w});
    uint8_t* dst = color.mutable_data();
    if (pixel_format == api::PixelFormat::kBgr) {
      std::memcpy(dst, bgr_.data(), bgr_.size());
    } else {
      for (std::size_t p = 0; p < bgr_.size(); p += 3) {
        dst[p] = bgr_[p + 2], dst[p + 1] = bgr_[p + 1], dst[p + 2] = bgr_[p];
      }
    }
    std::memcpy(depth.mutable_data(), depth_.data(), depth_.size() * sizeof(uint16_t));
    return py::make_tuple(color, depth, t);
  }
  py::dict camera() const { return cameraToDict(reader_->camera()); }
  std::size_t frameCount() const { return reader_->frameCount(); }
  py::object groundTruth(long frames) const {
    const std::vector<api::FinishedPose> gt = reader_->groundTruth(frames);
    if (gt.empty()) return py::none();
    return trajectoryToDict(gt);
  }

 private:
  std::unique_ptr<api::FrameReader> reader_;
  std::vector<uint8_t> bgr_;
  std::vector<uint16_t> depth_;
};

}  // namespace

PYBIND11_MODULE(plumb, m) {
  m.doc() = "plumb: point + line RGB-D odometry (C++ library, docs/API.md)";

  py::class_<PyTrackResult>(m, "TrackResult", "The pose of one frame as tracking has it")
      .def_readonly("sequence", &PyTrackResult::sequence)
      .def_readonly("timestamp", &PyTrackResult::timestamp)
      .def_readonly("state", &PyTrackResult::state, "'not_initialized', 'ok', 'weak' or 'lost'")
      .def_readonly("has_pose", &PyTrackResult::has_pose)
      .def_readonly("pose", &PyTrackResult::pose, "4x4 T_world_cam (camera to world), or None")
      .def_readonly("covariance", &PyTrackResult::covariance,
                    "6x6 covariance of the left perturbation [rho; phi] of T_cam_world, or None")
      .def_readonly("keyframe", &PyTrackResult::keyframe)
      .def_readonly("relocalized", &PyTrackResult::relocalized)
      .def_readonly("new_map", &PyTrackResult::new_map)
      .def("__repr__", [](const PyTrackResult& r) {
        return "<plumb.TrackResult frame " + std::to_string(r.sequence) + " " + r.state + ">";
      });

  py::class_<PyOdometry>(m, "Odometry", "Push-style odometry: one track() call per RGB-D frame")
      .def(py::init<const py::object&, bool, int, int, bool>(), py::arg("camera") = "tum1", py::arg("lines") = true,
           py::arg("line_samples") = 5, py::arg("output_delay") = 60, py::arg("loop_closing") = true)
      .def("track", &PyOdometry::track, py::arg("rgb"), py::arg("depth"), py::arg("t"), py::arg("format") = "rgb",
           "rgb: uint8 HxWx3 (format 'rgb' or 'bgr'), depth: uint16 HxW raw units, t: seconds")
      .def("finished", &PyOdometry::finished, "Finished poses [(t, 4x4 or None)], oldest first, since the last call")
      .def("finish", &PyOdometry::finish, "End of input: every held-back pose becomes finished")
      .def_property_readonly("counters", &PyOdometry::counters)
      .def_property_readonly("camera", &PyOdometry::camera);

  py::class_<PyFrameReader>(m, "FrameReader", "Frames of a TUM folder or synth:PRESET[:SEED[:FRAMES]] scene")
      .def(py::init<const std::string&, const std::string&>(), py::arg("spec"), py::arg("camera") = "")
      .def("next", &PyFrameReader::next, py::arg("format") = "rgb", "(rgb, depth, t) or None at the end")
      .def("__iter__", [](py::object self) { return self; })
      .def("__next__",
           [](PyFrameReader& r) {
             py::object frame = r.next("rgb");
             if (frame.is_none()) throw py::stop_iteration();
             return frame;
           })
      .def_property_readonly("camera", &PyFrameReader::camera)
      .def_property_readonly("frame_count", &PyFrameReader::frameCount)
      .def("ground_truth", &PyFrameReader::groundTruth, py::arg("frames"),
           "Exact trajectory of a synthetic scene's first frames (None for other sources)");

  m.def(
      "read_tum_frame",
      [](const std::string& folder, long index, const std::string& camera) {
        PyFrameReader reader(folder, camera);
        for (long i = 0; i < index; ++i) {
          if (reader.next("bgr").is_none()) throw py::index_error("frame " + std::to_string(index) + " is past the end");
        }
        py::object frame = reader.next("rgb");
        if (frame.is_none()) throw py::index_error("frame " + std::to_string(index) + " is past the end");
        return frame;
      },
      py::arg("folder"), py::arg("index"), py::arg("camera") = "",
      "Frame `index` of a TUM folder as (rgb, depth, t); reads the frames before it (use FrameReader to iterate)");

  m.def(
      "read_trajectory",
      [](const std::string& path) {
        std::vector<api::FinishedPose> poses;
        throwIfError(api::readTrajectory(path, &poses));
        return trajectoryToDict(poses);
      },
      py::arg("path"), "TUM trajectory file -> {'timestamps', 'poses' (N,4,4), 'valid'} (lost lines: valid False)");
  m.def(
      "write_trajectory",
      [](const std::string& path, const py::object& trajectory) {
        throwIfError(api::writeTrajectory(path, trajectoryFromObject(trajectory, "trajectory")));
      },
      py::arg("path"), py::arg("trajectory"), "Writes with `plumb run --out`'s writer (same bytes for the same poses)");
  m.def(
      "evaluate",
      [](const py::object& gt, const py::object& est) {
        const api::Evaluation e = api::evaluate(trajectoryFromObject(gt, "gt"), trajectoryFromObject(est, "est"));
        py::dict d;
        d["ate"] = statsToDict(e.ate_valid, e.ate_m, e.ate_pairs, "m");
        d["rpe_translation"] = statsToDict(e.rpe_valid, e.rpe_m_per_s, e.rpe_pairs, "m/s");
        d["rpe_rotation"] = statsToDict(e.rpe_valid, e.rpe_deg_per_s, e.rpe_pairs, "deg/s");
        d["ate_error"] = e.ate_error;
        d["rpe_error"] = e.rpe_error;
        return d;
      },
      py::arg("gt"), py::arg("est"), "ATE and RPE (delta 1 s) exactly as `plumb eval` computes them");
  m.def(
      "run",
      [](const std::string& source, const std::string& mode, const py::object& on_pose, const std::string& camera,
         bool lines, int line_samples, int output_delay, long max_frames) {
        api::RunConfig config;
        config.source = source;
        config.mode = mode;
        config.camera = camera;
        config.lines = lines;
        config.line_samples = line_samples;
        config.output_delay_frames = output_delay;
        config.max_frames = max_frames;
        std::function<void(const api::TrackOutput&)> pose_fn;
        // The first exception of the callback is kept and raised after the run: it must not
        // unwind through the runtime's stage threads.
        std::unique_ptr<py::error_already_set> callback_error;
        if (!on_pose.is_none()) {
          pose_fn = [&on_pose, &callback_error](const api::TrackOutput& out) {
            py::gil_scoped_acquire acquire;  // called on the track stage's thread
            if (callback_error) return;
            try {
              on_pose(toPy(out));
            } catch (py::error_already_set& e) {
              callback_error = std::make_unique<py::error_already_set>(std::move(e));
            }
          };
        }
        std::vector<api::FinishedPose> finished;
        api::RunSummary summary;
        api::Status st;
        {
          py::gil_scoped_release release;
          st = api::runSource(config, pose_fn, [&](const api::FinishedPose& p) { finished.push_back(p); }, &summary);
        }
        if (callback_error) throw std::move(*callback_error);
        throwIfError(st);
        py::dict d;
        d["trajectory"] = trajectoryToDict(finished);
        d["counters"] = countersToDict(summary.counters);
        d["frames_dropped"] = summary.frames_dropped;
        d["frames_per_second"] = summary.frames_per_second;
        return d;
      },
      py::arg("source"), py::arg("mode") = "deterministic", py::arg("on_pose") = py::none(), py::arg("camera") = "",
      py::arg("lines") = true, py::arg("line_samples") = 5, py::arg("output_delay") = 60, py::arg("max_frames") = -1,
      "The staged runtime over a source (TUM folder, synth:...), on_pose(TrackResult) per tracked frame");
}
