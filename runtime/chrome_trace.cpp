#include "runtime/chrome_trace.h"

#include "platform/input_file.h"

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

#include "runtime/json_reader.h"

namespace plumb::runtime {

namespace {

constexpr int kPid = 1;

std::string escapeJson(const std::string& text) {
  std::string out;
  for (const char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof(buf), "\\u%04x", static_cast<unsigned>(c));
      out += buf;
    } else {
      out += c;
    }
  }
  return out;
}

// Microseconds with nanosecond resolution, as the format expects.
std::string micros(int64_t ns) {
  char buf[40];
  std::snprintf(buf, sizeof(buf), "%.3f", static_cast<double>(ns) * 1e-3);
  return buf;
}

int64_t earliestTimeNs(const std::vector<TraceTrack>& tracks) {
  int64_t earliest = std::numeric_limits<int64_t>::max();
  for (const TraceTrack& track : tracks) {
    for (const TraceRecord& r : track.records()) earliest = std::min({earliest, r.t_sensor_ns, r.t_start_ns});
  }
  return earliest == std::numeric_limits<int64_t>::max() ? 0 : earliest;
}

}  // namespace

std::string formatChromeTrace(const std::vector<TraceTrack>& tracks, const RunReport& report) {
  const int64_t t0 = earliestTimeNs(tracks);
  uint64_t overflow = 0;
  for (const TraceTrack& track : tracks) overflow += track.overflow();
  std::ostringstream out;
  out << "{\"displayTimeUnit\":\"ms\",\"otherData\":{\"producer\":\"plumb\",\"mode\":\""
      << escapeJson(report.mode) << "\",\"frames_read\":" << report.frames_read
      << ",\"frames_completed\":" << report.frames_completed
      << ",\"frames_dropped\":" << report.frames_dropped
      << ",\"frames_late\":" << report.frames_late << ",\"wall_ns\":" << report.wall_ns
      << ",\"records_not_kept\":" << overflow << "},\n\"traceEvents\":[\n";
  out << "{\"name\":\"process_name\",\"ph\":\"M\",\"pid\":" << kPid
      << ",\"tid\":0,\"args\":{\"name\":\"plumb pipeline\"}}";
  for (std::size_t tid = 0; tid < tracks.size(); ++tid) {
    out << ",\n{\"name\":\"thread_name\",\"ph\":\"M\",\"pid\":" << kPid << ",\"tid\":" << tid
        << ",\"args\":{\"name\":\"" << escapeJson(tracks[tid].name()) << "\"}}";
    out << ",\n{\"name\":\"thread_sort_index\",\"ph\":\"M\",\"pid\":" << kPid << ",\"tid\":" << tid
        << ",\"args\":{\"sort_index\":" << tid << "}}";
  }
  for (std::size_t tid = 0; tid < tracks.size(); ++tid) {
    const std::string name = escapeJson(tracks[tid].name());
    // The end-to-end spans hang on the track whose completion ends them (the last by default).
    const bool last = report.end_to_end_stage > 0 ? tid == std::size_t(report.end_to_end_stage)
                                                  : tid + 1 == tracks.size();
    for (const TraceRecord& r : tracks[tid].records()) {
      if (r.kind != TraceRecord::Kind::kSpan) {
        const char* what = r.kind == TraceRecord::Kind::kDrop ? "drop" : "late";
        out << ",\n{\"name\":\"" << what << "\",\"cat\":\"drop\",\"ph\":\"i\",\"s\":\"t\",\"pid\":" << kPid
            << ",\"tid\":" << tid << ",\"ts\":" << micros(r.t_start_ns - t0)
            << ",\"args\":{\"frame\":" << r.frame_index << "}}";
        continue;
      }
      out << ",\n{\"name\":\"" << name << "\",\"cat\":\"stage\",\"ph\":\"X\",\"pid\":" << kPid
          << ",\"tid\":" << tid << ",\"ts\":" << micros(r.t_start_ns - t0)
          << ",\"dur\":" << micros(r.t_end_ns - r.t_start_ns) << ",\"args\":{\"frame\":"
          << r.frame_index << "}}";
      if (last) {
        out << ",\n{\"name\":\"end_to_end\",\"cat\":\"end_to_end\",\"ph\":\"b\",\"id\":"
            << r.frame_index << ",\"pid\":" << kPid << ",\"tid\":" << tid
            << ",\"ts\":" << micros(r.t_sensor_ns - t0) << ",\"args\":{\"frame\":" << r.frame_index
            << "}}";
        out << ",\n{\"name\":\"end_to_end\",\"cat\":\"end_to_end\",\"ph\":\"e\",\"id\":"
            << r.frame_index << ",\"pid\":" << kPid << ",\"tid\":" << tid
            << ",\"ts\":" << micros(r.t_end_ns - t0) << "}";
      }
    }
  }
  out << "\n]}\n";
  return out.str();
}

Status writeChromeTrace(const std::string& path, const std::vector<TraceTrack>& tracks,
                        const RunReport& report) {
  std::ofstream file(path, std::ios::binary);
  if (!file) return Status::Error("cannot write trace file " + path);
  file << formatChromeTrace(tracks, report);
  file.close();
  if (!file) return Status::Error("error while writing trace file " + path);
  return Status::Ok();
}

namespace {

int64_t nsFromMicros(double us) { return static_cast<int64_t>(us * 1e3 + (us >= 0 ? 0.5 : -0.5)); }

uint64_t counter(const JsonValue* other, const char* name) {
  const JsonValue* v = other != nullptr ? other->find(name) : nullptr;
  return v != nullptr && v->isNumber() ? static_cast<uint64_t>(v->number) : 0;
}

}  // namespace

Status parseChromeTrace(const std::string& text, RunReport* report) {
  JsonValue root;
  PLUMB_RETURN_IF_ERROR(parseJson(text, &root));
  const JsonValue* events = root.find("traceEvents");
  if (events == nullptr || events->type != JsonValue::Type::kArray) {
    return Status::Error("no \"traceEvents\" array: not a Chrome trace object");
  }
  *report = RunReport{};
  std::map<int, std::string> track_names;
  std::map<int, LatencyHistogram> track_latency;
  std::map<int64_t, int64_t> e2e_begin_ns;  // frame -> begin time
  uint64_t drop_events = 0;
  uint64_t late_events = 0;
  for (std::size_t i = 0; i < events->items.size(); ++i) {
    const JsonValue& e = events->items[i];
    const JsonValue* ph = e.find("ph");
    const JsonValue* tid = e.find("tid");
    if (ph == nullptr || !ph->isString() || tid == nullptr || !tid->isNumber()) {
      return Status::Error("trace event " + std::to_string(i) + " lacks \"ph\" or \"tid\"");
    }
    const int track = static_cast<int>(tid->number);
    const JsonValue* ts = e.find("ts");
    if (ph->string == "M") {
      const JsonValue* name = e.find("name");
      const JsonValue* args = e.find("args");
      const JsonValue* arg_name = args != nullptr ? args->find("name") : nullptr;
      if (name != nullptr && name->string == "thread_name" && arg_name != nullptr) {
        track_names[track] = arg_name->string;
      }
      continue;
    }
    if (ts == nullptr || !ts->isNumber()) {
      return Status::Error("trace event " + std::to_string(i) + " lacks a numeric \"ts\"");
    }
    if (ph->string == "X") {
      const JsonValue* dur = e.find("dur");
      if (dur == nullptr || !dur->isNumber()) {
        return Status::Error("complete event " + std::to_string(i) + " lacks a numeric \"dur\"");
      }
      track_latency[track].add(nsFromMicros(dur->number));
    } else if (ph->string == "i") {
      const JsonValue* name = e.find("name");
      const bool late = name != nullptr && name->isString() && name->string == "late";
      ++(late ? late_events : drop_events);
    } else if (ph->string == "b" || ph->string == "e") {
      const JsonValue* id = e.find("id");
      if (id == nullptr || !id->isNumber()) {
        return Status::Error("async event " + std::to_string(i) + " lacks a numeric \"id\"");
      }
      const int64_t frame = static_cast<int64_t>(id->number);
      if (ph->string == "b") {
        e2e_begin_ns[frame] = nsFromMicros(ts->number);
      } else {
        auto begin = e2e_begin_ns.find(frame);
        if (begin == e2e_begin_ns.end()) {
          return Status::Error("end_to_end end without begin for frame " + std::to_string(frame));
        }
        report->end_to_end.add(nsFromMicros(ts->number) - begin->second);
        e2e_begin_ns.erase(begin);
      }
    }
  }
  for (const auto& [tid, name] : track_names) {
    report->stages.push_back({name, track_latency[tid]});
  }
  const JsonValue* other = root.find("otherData");
  const JsonValue* mode = other != nullptr ? other->find("mode") : nullptr;
  report->mode = mode != nullptr && mode->isString() ? mode->string : "?";
  report->frames_read = counter(other, "frames_read");
  report->frames_completed = counter(other, "frames_completed");
  report->frames_dropped = std::max(counter(other, "frames_dropped"), drop_events);
  report->frames_late = std::max(counter(other, "frames_late"), late_events);
  report->wall_ns = static_cast<int64_t>(counter(other, "wall_ns"));
  return Status::Ok();
}

Status readChromeTrace(const std::string& path, RunReport* report) {
  // Opened the one way (platform/input_file.h): regular files only, size bounded before reading.
  // A trace holds at most 8192 events per stage (RunOptions::trace_capacity_per_stage): a few MB.
  constexpr uint64_t kMaxTraceBytes = uint64_t(256) << 20;
  std::string text;
  PLUMB_RETURN_IF_ERROR(readInputFile(path, kMaxTraceBytes, "trace file", &text));
  return parseChromeTrace(text, report).withContext(path);
}

}  // namespace plumb::runtime
