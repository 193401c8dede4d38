#!/usr/bin/env python3
"""ctest `hostile`: the hostile-input cases of issue 23 replayed as a table.

Each row of CASES is one careless or hostile use of plumb: a command, the exit code it must end
with, a fragment its message must contain, and the checks every case gets for free:
  - inputs unchanged: every file of the case's scratch folder that the row does not list as an
    output has the same SHA-256 after the command as before (links are compared as links);
  - no partial output: no `.partial-` file is left anywhere in the scratch folder;
  - bounded: the command ends within its time limit, and where the row says so (the /dev/zero-like
    cases) its peak resident memory stays below the limit (ru_maxrss of the child, from wait4);
  - no crash: a signal death or exit code 70 fails every row that does not expect it.
Rows may add a `check(folder, result)` for what a table cannot say (a link still a link, the
lines of a trajectory).

Usage: hostile_suite.py --plumb BIN [--datasets DIR] [--python PY --python-dir DIR]
                        [--jpeg-helper BIN] [--only SUBSTRING] [--list]
Exit 0 when every row passes, 1 otherwise (one line per row: PASS/FAIL/SKIP, class, name, why).
Run against an older plumb binary it shows which rows that binary fails (the demonstration that
each class's test fails before its fix). Network rows send to 127.0.0.1 only.
"""

import argparse
import hashlib
import os
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import time
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))


# ----------------------------------------------------------------------------------------------
# Helpers to build inputs.

def write_png(path, width, height, bit_depth, colour_type, row):
    """A PNG whose every row is `row` (filter byte included)."""
    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)
    data = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, bit_depth, colour_type, 0, 0, 0))
    data += chunk(b"IDAT", zlib.compress(row * height, 1)) + chunk(b"IEND", b"")
    with open(path, "wb") as f:
        f.write(data)


def write_png16(path, width, height, value=0):
    """A 16-bit greyscale PNG, every pixel `value` (e.g. a depth map with no reading)."""
    write_png(path, width, height, 16, 0, b"\x00" + struct.pack(">H", value) * width)


def write_png8_rgb(path, width, height, grey=128):
    write_png(path, width, height, 8, 2, b"\x00" + bytes([grey, grey, grey]) * width)


def read_lines(path):
    with open(path, "r", encoding="utf-8", errors="replace") as f:
        return f.read().splitlines()


def data_lines(path):
    return [l for l in read_lines(path) if l and not l.startswith("#")]


def write_text(path, text):
    with open(path, "w") as f:
        f.write(text)


def crc32(data):
    return zlib.crc32(data) & 0xFFFFFFFF


class Env:
    """What the rows need: the binary under test and cached base inputs."""

    def __init__(self, args, work):
        self.plumb = os.path.abspath(args.plumb)
        self.datasets = args.datasets
        self.python = args.python
        self.python_dir = os.path.abspath(args.python_dir) if args.python_dir else ""
        self.jpeg_helper = os.path.abspath(args.jpeg_helper) if args.jpeg_helper else ""
        self.work = work
        self._cache = {}

    def run_setup(self, cmd, **kw):
        r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=300, **kw)
        if r.returncode != 0:
            raise RuntimeError("setup failed: %s\n%s" % (" ".join(cmd), r.stdout.decode(errors="replace")))
        return r.stdout.decode(errors="replace")

    def synth_dataset(self, frames=10):
        """A cached synthetic TUM folder of `frames` frames (plumb synth), copied per use."""
        key = "ds%d" % frames
        if key not in self._cache:
            path = os.path.join(self.work, "_cache_" + key)
            self.run_setup([self.plumb, "synth", "--out", path, "--frames", str(frames)])
            self._cache[key] = path
        return self._cache[key]

    def copy_dataset(self, folder, frames=10):
        dst = os.path.join(folder, "ds")
        shutil.copytree(self.synth_dataset(frames), dst, symlinks=True)
        return dst

    def good_map(self):
        """A map with keyframes, from a short synthetic run (cached)."""
        if "map" not in self._cache:
            path = os.path.join(self.work, "_cache_good.map")
            self.run_setup([self.plumb, "run", "--dataset", "synth:textured:1:60", "--discard-trajectory",
                            "--save-map", path])
            self._cache["map"] = path
        return self._cache["map"]

    def recording(self):
        """A .plumbrec of the 10-frame synthetic folder (cached)."""
        if "rec" not in self._cache:
            path = os.path.join(self.work, "_cache_ds10.plumbrec")
            self.run_setup([self.plumb, "convert", self.synth_dataset(10), path])
            self._cache["rec"] = path
        return self._cache["rec"]


# ----------------------------------------------------------------------------------------------
# Crafted binary files: CRC-valid but hostile fields.

def recording_frames(data):
    """(offset, payload_size) of every frame chunk of a .plumbrec (file header 124 bytes)."""
    out, pos = [], 124
    while pos + 16 <= len(data):
        assert data[pos:pos + 4] == b"PLCK", "not a chunk at %d" % pos
        ctype, size = struct.unpack_from("<II", data, pos + 4)
        if ctype == 1:
            out.append((pos, size))
        pos += 16 + size + 4
    return out


def patch_frame(data, chunk_pos, payload_size, field_offset, fmt, value):
    """Sets a frame-info field and recomputes the chunk's CRC (header CRC covers 12 bytes only)."""
    struct.pack_into(fmt, data, chunk_pos + 16 + field_offset, value)
    end = chunk_pos + 16 + payload_size
    struct.pack_into("<I", data, end, crc32(bytes(data[chunk_pos:end])))


def craft_recording(src, dst, edit):
    data = bytearray(open(src, "rb").read())
    for i, (pos, size) in enumerate(recording_frames(data)):
        edit(data, i, pos, size)
    with open(dst, "wb") as f:
        f.write(data)


MAP_POSE, MAP_MAT6 = 96, 288
MAP_KEYFRAME_FIXED = 4 + 8 + 8 + 1 + 4 + MAP_POSE + MAP_POSE + MAP_MAT6 + 1 + MAP_POSE + 1 + MAP_POSE + MAP_MAT6 + 8 + 4


def map_sections(data):
    """[(tag, payload_start, payload_size)] of a plumb map (32-byte header)."""
    count = struct.unpack_from("<I", data, 12)[0]
    pos, out = 32, []
    for _ in range(count):
        tag, _reserved, size = struct.unpack_from("<IIQ", data, pos)
        out.append((tag, pos + 16, size))
        pos += 16 + size + 4
    return out


def map_keyframes(data):
    """(section start, section size, [(offset, id)] of every keyframe) of a map's KFRM section."""
    for tag, start, size in map_sections(data):
        if tag != struct.unpack("<I", b"KFRM")[0]:
            continue
        n = struct.unpack_from("<I", data, start)[0]
        pos, keyframes = start + 4, []
        for _ in range(n):
            keyframes.append((pos, struct.unpack_from("<I", data, pos)[0]))
            pos += MAP_KEYFRAME_FIXED
            points = struct.unpack_from("<I", data, pos)[0]
            pos += 4 + points * (24 + 1 + 32)
            lines = struct.unpack_from("<I", data, pos)[0]
            pos += 4
            for _ in range(lines):
                pos += 12 + 2 + data[pos + 13] * 12 + 32
        assert pos == start + size, "keyframe layout mismatch"
        return start, size, keyframes
    raise ValueError("no keyframe section")


def craft_map_last_id(src, dst, new_id):
    """The last keyframe's id set to new_id, the section CRC recomputed (loop edges untouched: they
    name keyframes by id, so the map must have none naming the last one for this to stay valid)."""
    data = bytearray(open(src, "rb").read())
    start, size, keyframes = map_keyframes(data)
    struct.pack_into("<I", data, keyframes[-1][0], new_id)
    struct.pack_into("<I", data, start + size, crc32(bytes(data[start - 16:start + size])))
    with open(dst, "wb") as f:
        f.write(data)


def craft_map_many_edges(src, dst, edges):
    """The loop-edge section replaced by `edges` valid edges (identity pose and information)
    between the first two keyframes: every field decodes, the loop closer's restore refuses it
    (it keeps 24), i.e. a refusal that comes after the run has begun."""
    data = bytes(open(src, "rb").read())
    ids = [i for _, i in map_keyframes(data)[2]]
    identity = [1.0 if r == c else 0.0 for r in range(3) for c in range(3)] + [0.0, 0.0, 0.0]
    info = [1.0 if r == c else 0.0 for r in range(6) for c in range(6)]
    edge = struct.pack("<II", ids[0], ids[1]) + struct.pack("<12d", *identity) + struct.pack("<36d", *info)
    sections = []
    for tag, start, size in map_sections(data):
        payload = data[start:start + size]
        if tag == struct.unpack("<I", b"LOOP")[0]:
            payload = struct.pack("<I", edges) + edge * edges
        sections.append((tag, payload))
    body = b""
    for tag, payload in sections:
        head = struct.pack("<IIQ", tag, 0, len(payload))
        body += head + payload + struct.pack("<I", crc32(head + payload))
    header = bytearray(data[:32])
    struct.pack_into("<Q", header, 16, 32 + len(body))
    struct.pack_into("<I", header, 28, crc32(bytes(header[:28])))
    with open(dst, "wb") as f:
        f.write(bytes(header) + body)


# ----------------------------------------------------------------------------------------------
# Running one command.

class Result:
    def __init__(self, code, signal_number, output, seconds, max_rss_kib, stderr_closed=False):
        self.code, self.signal, self.output = code, signal_number, output
        self.seconds, self.max_rss_kib = seconds, max_rss_kib


def run_command(cmd, cwd, timeout, send_signal=None, env=None, preexec=None, close_stderr_after_line=False):
    """Runs cmd; returns Result with exit code (or -signal), combined output, peak RSS (KiB)."""
    out_path = os.path.join(cwd, "..", os.path.basename(cwd) + ".output")
    start = time.monotonic()
    with open(out_path, "wb") as out:
        if close_stderr_after_line:
            p = subprocess.Popen(cmd, cwd=cwd, stdout=out, stderr=subprocess.PIPE, env=env, preexec_fn=preexec)
            p.stderr.readline()
            p.stderr.close()  # the reader goes away (`| head -1`): the next write raises SIGPIPE
        else:
            p = subprocess.Popen(cmd, cwd=cwd, stdout=out, stderr=subprocess.STDOUT, env=env, preexec_fn=preexec)
        signalled = False
        status, rusage = None, None
        while True:
            pid, status, rusage = os.wait4(p.pid, os.WNOHANG)
            if pid == p.pid:
                break
            elapsed = time.monotonic() - start
            if send_signal and not signalled and elapsed >= send_signal[1]:
                os.kill(p.pid, send_signal[0])
                signalled = True
            if elapsed > timeout:
                os.kill(p.pid, signal.SIGKILL)
                pid, status, rusage = os.wait4(p.pid, 0)
                break
            time.sleep(0.02)
        p.returncode = 0  # reaped here: keep Popen from waiting again
    seconds = time.monotonic() - start
    output = open(out_path, "rb").read().decode(errors="replace")
    os.remove(out_path)
    code = os.WEXITSTATUS(status) if os.WIFEXITED(status) else -os.WTERMSIG(status)
    timed_out = seconds > timeout
    r = Result(code if not timed_out else "timeout", 0, output, seconds, rusage.ru_maxrss)
    return r


def snapshot(folder, outputs):
    """SHA-256 of every file (and the target of every link) below folder, except outputs."""
    skip = set(os.path.normpath(os.path.join(folder, o)) for o in outputs)
    state = {}
    for root, dirs, files in os.walk(folder):
        for name in dirs + files:
            path = os.path.join(root, name)
            if os.path.normpath(path) in skip:
                continue
            if os.path.islink(path):
                state[path] = "link:" + os.readlink(path)
            elif os.path.isfile(path) and not name.startswith("fifo"):
                h = hashlib.sha256()
                with open(path, "rb") as f:
                    for block in iter(lambda: f.read(1 << 20), b""):
                        h.update(block)
                state[path] = h.hexdigest()
    return state


def partial_files(folder):
    found = []
    for root, _dirs, files in os.walk(folder):
        found += [os.path.join(root, f) for f in files if ".partial-" in f]
    return found


# ----------------------------------------------------------------------------------------------
# The table. Fields: cls (issue 23's class), name, setup(env, folder) -> None, cmd (list; "{plumb}"
# and "{d}" are replaced), exit (int), msg (fragment, case-insensitive; "" = any), outputs (files
# the command may create or change), timeout (s), mem_mb (peak RSS bound or None), signal
# ((signum, after_s) or None), check(folder, result) -> "" or a failure, python (a Python program
# run with the module's interpreter instead of cmd), limit_file_bytes (RLIMIT_FSIZE: a full disk).

def setup_dataset(env, d):
    env.copy_dataset(d)


def link_to(target, name):
    def setup(env, d):
        env.copy_dataset(d)
        os.symlink(target, os.path.join(d, name))
    return setup


def fifo_at(relative):
    def setup(env, d):
        env.copy_dataset(d)
        path = os.path.join(d, relative)
        if os.path.exists(path):
            os.remove(path)
        os.mkfifo(path)
    return setup


def camera_file(body, base=None):
    def setup(env, d):
        env.copy_dataset(d)
        write_text(os.path.join(d, "cam.txt"), body)
    return setup


CAM_OK = "fx 525\nfy 525\ncx 319.5\ncy 239.5\n"


def check_is_link(name, target):
    def check(d, r):
        path = os.path.join(d, name)
        if not os.path.islink(path):
            return "%s was replaced by a regular file (the link is gone)" % name
        if len(data_lines(os.path.join(d, target))) != 10:
            return "the link's target %s does not hold the 10 poses" % target
        return ""
    return check


def check_trajectory_lines(name, minimum, maximum=None):
    def check(d, r):
        path = os.path.join(d, name)
        if not os.path.exists(path):
            return "%s was not written" % name
        lines = read_lines(path)
        n = len([l for l in lines if not l.startswith("# plumb")])
        if n < minimum or (maximum is not None and n > maximum):
            return "%s holds %d frame lines, expected %d..%s" % (name, n, minimum, maximum)
        return ""
    return check


def check_absent(*names):
    def check(d, r):
        for n in names:
            if os.path.exists(os.path.join(d, n)):
                return "%s exists: nothing should have been written" % n
        return ""
    return check


def setup_failing_run_outputs(env, d):
    """A good map and a good trajectory; a camera whose image size is not the images'."""
    env.copy_dataset(d)
    shutil.copy(env.good_map(), os.path.join(d, "good.map"))
    write_text(os.path.join(d, "good.txt"), "# a trajectory from an earlier run\n1000 0 0 0 0 0 0 1\n")
    write_text(os.path.join(d, "cam320.txt"), "fx 262\nfy 262\ncx 160\ncy 120\nwidth 320\nheight 240\n")


def setup_uninitialised(env, d):
    """A folder whose frames never initialise (grey colour, no depth), and a good map."""
    ds = env.copy_dataset(d)
    for name in os.listdir(os.path.join(ds, "depth")):
        write_png16(os.path.join(ds, "depth", name), 640, 480, 0)
    for name in os.listdir(os.path.join(ds, "rgb")):
        write_png8_rgb(os.path.join(ds, "rgb", name), 640, 480)
    shutil.copy(env.good_map(), os.path.join(d, "good.map"))


def setup_convert_over_recording(env, d):
    ds = env.copy_dataset(d)
    shutil.copy(env.recording(), os.path.join(d, "existing.plumbrec"))
    # Frame 6's colour image cut in half: the conversion fails part-way.
    png = os.path.join(ds, "rgb", sorted(os.listdir(os.path.join(ds, "rgb")))[6])
    data = open(png, "rb").read()
    open(png, "wb").write(data[: len(data) // 2])


def setup_convert_full_disk(env, d):
    env.copy_dataset(d)
    shutil.copy(env.recording(), os.path.join(d, "existing.plumbrec"))


def setup_big_associations(env, d):
    """5 real frames, then a million lines naming frame 0's images with increasing stamps."""
    ds = env.copy_dataset(d)
    lines = data_lines(os.path.join(ds, "associations.txt"))[:5]
    first = lines[0].split()
    with open(os.path.join(ds, "associations.txt"), "w") as f:
        f.write("\n".join(lines) + "\n")
        for i in range(1_000_000):
            t = "%.6f" % (2000.0 + i * 0.001)
            f.write("%s %s %s %s\n" % (t, first[1], t, first[3]))


def setup_sparse_map(env, d):
    with open(os.path.join(d, "big.map"), "wb") as f:
        f.truncate(900 << 20)  # 900 MB of zeros (sparse): not a map, refused after 32 bytes


def rewrite_associations(ds, edit):
    """associations.txt with edit(index, fields) applied to each data line (comments dropped)."""
    path = os.path.join(ds, "associations.txt")
    out = []
    for i, line in enumerate(data_lines(path)):
        fields = line.split()
        edit(i, fields)
        out.append(" ".join(fields))
    write_text(path, "\n".join(out) + "\n")


def setup_realtime_gap(env, d):
    def shift(i, f):
        if i >= 5:
            f[0] = f[2] = "%.6f" % (float(f[0]) + 1e6)  # a recorded gap of 11.6 days before frame 5
    rewrite_associations(env.copy_dataset(d), shift)


def setup_bom(env, d):
    ds = env.copy_dataset(d)
    path = os.path.join(ds, "associations.txt")
    data = open(path, "rb").read()
    lines = [l for l in data.split(b"\n") if l and not l.startswith(b"#")]
    open(path, "wb").write(b"\xef\xbb\xbf" + b"\n".join(lines) + b"\n")


def setup_symlink_loop_image(env, d):
    ds = env.copy_dataset(d)
    name = sorted(os.listdir(os.path.join(ds, "rgb")))[3]
    path = os.path.join(ds, "rgb", name)
    os.remove(path)
    os.symlink(name, path)  # points to itself


def setup_jpeg(truncate):
    def setup(env, d):
        ds = env.copy_dataset(d)
        def use_jpeg(i, f):
            if i != 2:
                return
            jpg = os.path.join(ds, "rgb", "frame2.jpg")
            env.run_setup([env.jpeg_helper, jpg, "640", "480"])
            if truncate:
                data = open(jpg, "rb").read()
                open(jpg, "wb").write(data[: len(data) * 2 // 3])
            f[1] = "rgb/frame2.jpg"
        rewrite_associations(ds, use_jpeg)
    return setup


def setup_recording(edit):
    def setup(env, d):
        craft_recording(env.recording(), os.path.join(d, "rec.plumbrec"), edit)
    return setup


def set_depth_factor(value):
    def edit(data, i, pos, size):
        patch_frame(data, pos, size, 40, "<d", value)
    return edit


def stamp_frame(index, value):
    def edit(data, i, pos, size):
        if i == index:
            patch_frame(data, pos, size, 8, "<d", value)
            patch_frame(data, pos, size, 16, "<d", value)
    return edit


def setup_map_wrap(env, d):
    craft_map_last_id(env.good_map(), os.path.join(d, "wrap.map"), 0xFFFFFFF0)


def setup_map_many_edges(env, d):
    craft_map_many_edges(env.good_map(), os.path.join(d, "edges.map"), 30)
    write_text(os.path.join(d, "good.txt"), "# a trajectory from an earlier run\n1000 0 0 0 0 0 0 1\n")


def setup_map_other_camera(env, d):
    env.copy_dataset(d)
    shutil.copy(env.good_map(), os.path.join(d, "good.map"))
    write_text(os.path.join(d, "good.txt"), "# a trajectory from an earlier run\n1000 0 0 0 0 0 0 1\n")


def setup_eval(env, d):
    ds = env.copy_dataset(d)
    shutil.copy(os.path.join(ds, "groundtruth.txt"), os.path.join(d, "gt.txt"))
    shutil.copy(os.path.join(ds, "groundtruth.txt"), os.path.join(d, "est.txt"))
    os.symlink("gt.txt", os.path.join(d, "gt_link.png"))


def setup_trace(env, d):
    env.run_setup([env.plumb, "run", "--dataset", "synth:textured:1:10", "--discard-trajectory",
                   "--profile", os.path.join(d, "trace.json")])
    os.symlink("trace.json", os.path.join(d, "trace_link.png"))


PY_CONCURRENT = r"""
import sys, threading
import plumb
reader = plumb.FrameReader("synth:textured:1:20")
frames = list(reader)
odo = plumb.Odometry(camera=reader.camera)
refused, done, other = [], [], []
t = [1000.0]
lock = threading.Lock()
def worker(k):
    for i in range(len(frames)):
        rgb, depth, _ = frames[i]
        with lock:
            t[0] += 0.033
            stamp = t[0]
        try:
            odo.track(rgb, depth, stamp)
            done.append(1)
        except RuntimeError as e:
            if "in use by another thread" in str(e):
                refused.append(1)
            else:
                other.append(str(e))
threads = [threading.Thread(target=worker, args=(k,)) for k in range(3)]
for th in threads: th.start()
for th in threads: th.join()
print("done", len(done), "refused", len(refused), "other", other[:2])
sys.exit(0 if refused and not other else 1)
"""

PY_TIMESTAMPS = r"""
import math, plumb
reader = plumb.FrameReader("synth:textured:1:3")
frames = list(reader)
rgb, depth, t0 = frames[0]
failures = []
for label, stamps in [("nan", [math.nan]), ("inf", [math.inf]), ("negative", [-1.0]),
                      ("decreasing", [t0, t0 - 1.0]), ("repeated", [t0, t0])]:
    odo = plumb.Odometry(camera=reader.camera)
    try:
        for s in stamps:
            odo.track(rgb, depth, s)
        failures.append(label + " accepted")
    except ValueError as e:
        if "timestamp" not in str(e):
            failures.append(label + ": " + str(e))
for bad in [{"fx": "525", "fy": 525, "cx": 320, "cy": 240}, {"fx": 525, "fy": 525, "cx": 320, "cy": 240, "width": "640"}]:
    try:
        plumb.Odometry(camera=bad)
        failures.append("camera %r accepted" % bad)
    except TypeError as e:
        if "camera value" not in str(e):
            failures.append("camera message: " + str(e))
    except Exception as e:
        failures.append("camera raised %s: %s" % (type(e).__name__, e))
print(failures)
raise SystemExit(1 if failures else 0)
"""


def case(cls, name, cmd=None, exit=0, msg="", outputs=(), timeout=60, mem_mb=None, sig=None, check=None,
         setup=None, python=None, limit_file_bytes=None):
    return dict(cls=cls, name=name, cmd=cmd, exit=exit, msg=msg, outputs=list(outputs), timeout=timeout,
                mem_mb=mem_mb, signal=sig, check=check, setup=setup, python=python,
                limit_file_bytes=limit_file_bytes)


RUN = ["{plumb}", "run"]
SYN = ["--dataset", "synth:textured:1:10"]

CASES = [
    # 1. An output that is a symlink is written THROUGH the link, never replaced by a file.
    case(1, "--out symlink to a file: written through", RUN + SYN + ["--out", "{d}/link.txt"],
         setup=lambda e, d: (write_text(os.path.join(d, "real.txt"), "old\n"),
                             os.symlink("real.txt", os.path.join(d, "link.txt"))),
         outputs=["real.txt"], check=check_is_link("link.txt", "real.txt")),
    case(1, "--out dangling symlink: target created", RUN + SYN + ["--out", "{d}/link.txt"],
         setup=lambda e, d: os.symlink("new.txt", os.path.join(d, "link.txt")),
         outputs=["new.txt"], check=check_is_link("link.txt", "new.txt")),
    case(1, "--out symlink loop: refused as a loop", RUN + SYN + ["--out", "{d}/loop.txt"], exit=2,
         msg="symlink loop", setup=lambda e, d: os.symlink("loop.txt", os.path.join(d, "loop.txt"))),
    case(1, "--out link to /proc/self/fd/1 (a redirected stdout): refused, link kept",
         RUN + SYN + ["--out", "{d}/stdout_link.txt"], exit=2, msg="stream of this process",
         setup=lambda e, d: os.symlink("/proc/self/fd/1", os.path.join(d, "stdout_link.txt"))),
    # 2. Python: concurrent track() on one object is refused (RuntimeError), never a crash.
    case(2, "python: three threads on one Odometry", python=PY_CONCURRENT, timeout=300),
    # 3. eval --plot / profile --png never overwrite an input.
    case(3, "eval --plot = the ground truth", ["{plumb}", "eval", "--gt", "{d}/gt.txt", "--est", "{d}/est.txt",
                                                "--plot", "{d}/gt.txt"], exit=2, msg="input", setup=setup_eval),
    case(3, "eval --plot = the estimate", ["{plumb}", "eval", "--gt", "{d}/gt.txt", "--est", "{d}/est.txt",
                                            "--plot", "{d}/est.txt"], exit=2, msg="input", setup=setup_eval),
    case(3, "eval --plot = a link to the ground truth", ["{plumb}", "eval", "--gt", "{d}/gt.txt", "--est",
                                                          "{d}/est.txt", "--plot", "{d}/gt_link.png"],
         exit=2, msg="input", setup=setup_eval),
    case(3, "profile --png = the trace", ["{plumb}", "profile", "{d}/trace.json", "--png", "{d}/trace.json"],
         exit=2, msg="input", setup=setup_trace),
    case(3, "profile --png = a link to the trace", ["{plumb}", "profile", "{d}/trace.json", "--png",
                                                     "{d}/trace_link.png"], exit=2, msg="input", setup=setup_trace),
    # 4. A run that fails (or never initialises) replaces neither --out nor --save-map.
    case(4, "run failing on frame 0 keeps --out and --save-map",
         RUN + ["--dataset", "{d}/ds", "--camera", "{d}/cam320.txt", "--out", "{d}/good.txt", "--save-map",
                "{d}/good.map"], exit=1, msg="no output was written", setup=setup_failing_run_outputs),
    case(4, "run that never initialises keeps --save-map",
         RUN + ["--dataset", "{d}/ds", "--out", "{d}/t.txt", "--save-map", "{d}/good.map"], exit=0,
         msg="no map saved", setup=setup_uninitialised, outputs=["t.txt"]),
    # 5. convert never truncates an existing recording; no partial file on failure or full disk.
    case(5, "convert failing part-way keeps the existing recording",
         ["{plumb}", "convert", "{d}/ds", "{d}/existing.plumbrec"], exit=1, msg="png",
         setup=setup_convert_over_recording),
    case(5, "convert on a full disk keeps the existing recording, no partial",
         ["{plumb}", "convert", "{d}/ds", "{d}/existing.plumbrec"], exit=1, msg="",
         setup=setup_convert_full_disk, limit_file_bytes=1 << 20),
    # 6. Text and map inputs are bounded before they are read: /dev/zero costs nothing.
    case(6, "--camera /dev/zero", RUN + ["--dataset", "{d}/ds", "--camera", "/dev/zero", "--out", "{d}/t.txt"],
         exit=1, msg="character device", setup=setup_dataset, mem_mb=100, timeout=20),
    case(6, "--gt /dev/zero", RUN + SYN + ["--gt", "/dev/zero", "--out", "{d}/t.txt"], exit=1,
         msg="character device", mem_mb=100, timeout=20, check=check_absent("t.txt")),
    case(6, "profile /dev/zero", ["{plumb}", "profile", "/dev/zero"], exit=1, msg="character device",
         mem_mb=100, timeout=20),
    case(6, "associations.txt -> /dev/zero", RUN + ["--dataset", "{d}/ds", "--out", "{d}/t.txt"], exit=1,
         msg="character device", setup=lambda e, d: (e.copy_dataset(d), os.remove(os.path.join(d, "ds/associations.txt")),
                                                     os.symlink("/dev/zero", os.path.join(d, "ds/associations.txt"))),
         mem_mb=100, timeout=20),
    case(6, "camera.txt -> /dev/zero", RUN + ["--dataset", "{d}/ds", "--out", "{d}/t.txt"], exit=1,
         msg="character device", setup=lambda e, d: (e.copy_dataset(d), os.remove(os.path.join(d, "ds/camera.txt")),
                                                     os.symlink("/dev/zero", os.path.join(d, "ds/camera.txt"))),
         mem_mb=100, timeout=20),
    case(6, "1M-line associations.txt with --max-frames 5: fast and small",
         RUN + ["--dataset", "{d}/ds", "--max-frames", "5", "--out", "{d}/t.txt"], exit=0,
         setup=setup_big_associations, outputs=["t.txt"], mem_mb=100, timeout=15,
         check=check_trajectory_lines("t.txt", 5, 5)),
    case(6, "900 MB map of zeros: refused after its header", RUN + SYN + ["--load-map", "{d}/big.map", "--out",
                                                                           "{d}/t.txt"],
         exit=1, msg="not a plumb map", setup=setup_sparse_map, mem_mb=100, timeout=20),
    # 7. A FIFO input never blocks the open.
    case(7, "--load-map FIFO", RUN + SYN + ["--load-map", "{d}/fifo.map", "--out", "{d}/t.txt"], exit=1,
         msg="FIFO", setup=lambda e, d: os.mkfifo(os.path.join(d, "fifo.map")), timeout=20),
    case(7, "--camera FIFO", RUN + ["--dataset", "{d}/ds", "--camera", "{d}/ds/fifo_cam", "--out", "{d}/t.txt"],
         exit=1, msg="FIFO", setup=fifo_at("ds/fifo_cam"), timeout=20),
    case(7, "associations.txt FIFO", RUN + ["--dataset", "{d}/ds", "--out", "{d}/t.txt"], exit=1, msg="FIFO",
         setup=fifo_at("ds/associations.txt"), timeout=20),
    # 8. Real-time pacing over a huge recorded gap wakes on SIGINT and keeps every pose.
    case(8, "realtime, 1e6 s gap, SIGINT", RUN + ["--dataset", "{d}/ds", "--mode", "realtime", "--out",
                                                  "{d}/t.txt"],
         exit=3, msg="stopped by signal", setup=setup_realtime_gap, sig=(signal.SIGINT, 8), timeout=30,
         outputs=["t.txt"], check=check_trajectory_lines("t.txt", 5, 5)),
    # 9. --skip-frames: bounded, no wrap.
    case(9, "--skip-frames 10000000 on synth", RUN + ["--dataset", "synth:textured", "--skip-frames", "10000000",
                                                       "--out", "{d}/t.txt"],
         exit=2, msg="skips all", mem_mb=100, timeout=30),
    case(9, "--skip-frames 1e23", RUN + SYN + ["--skip-frames", "100000000000000000000000", "--out", "{d}/t.txt"],
         exit=2, msg="out of range", mem_mb=100, timeout=20),
    # 10. SIGHUP and SIGPIPE stop the run like SIGINT: every pose kept.
    case(10, "SIGHUP keeps every pose", RUN + ["--dataset", "synth:textured:1:100000", "--out", "{d}/t.txt",
                                               "--stats", "{d}/s.json"],
         exit=3, sig=(signal.SIGHUP, 12), timeout=60, outputs=["t.txt", "s.json"],
         check=lambda d, r: "" if '"stopped_by_signal": true' in open(os.path.join(d, "s.json")).read()
         else "statistics do not say stopped"),
    case(10, "SIGPIPE on stderr (--trace | head -1) keeps every pose",
         RUN + ["--dataset", "synth:textured:1:100000", "--trace", "--out", "{d}/t.txt"], exit=3, timeout=60,
         outputs=["t.txt"], check=check_trajectory_lines("t.txt", 1)),
    # 11. Integer options never wrap modulo 2^32.
    case(11, "--output-delay 4294967297", RUN + SYN + ["--output-delay", "4294967297", "--out", "{d}/t.txt"],
         exit=2, msg="out of range"),
    case(11, "--line-samples 4294967301", RUN + SYN + ["--line-samples", "4294967301", "--out", "{d}/t.txt"],
         exit=2, msg="out of range"),
    case(11, "--slots 4294967297", RUN + SYN + ["--slots", "4294967297", "--out", "{d}/t.txt"], exit=2,
         msg="out of range"),
    # 12. Empty values are usage errors; an unwritable output is refused before the run.
    case(12, '--out ""', RUN + SYN + ["--out", ""], exit=2, msg="empty"),
    case(12, '--covariance ""', RUN + SYN + ["--out", "{d}/t.txt", "--covariance", ""], exit=2, msg="empty"),
    case(12, '--mavlink ""', RUN + SYN + ["--out", "{d}/t.txt", "--mavlink", ""], exit=2, msg="empty"),
    case(12, '--stats ""', RUN + SYN + ["--out", "{d}/t.txt", "--stats", ""], exit=2, msg="empty", timeout=10),
    case(12, '--save-map ""', RUN + SYN + ["--out", "{d}/t.txt", "--save-map", ""], exit=2, msg="empty", timeout=10),
    case(12, "--save-map /proc/x.map refused before the run", RUN + SYN + ["--out", "{d}/t.txt", "--save-map",
                                                                           "/proc/x.map"],
         exit=2, msg="--save-map", timeout=10, check=check_absent("t.txt")),
    # 13. Python validates timestamps and camera dicts like the CLI.
    case(13, "python: bad timestamps and camera values", python=PY_TIMESTAMPS, timeout=120),
    # 14. A truncated JPEG is refused like a truncated PNG.
    case(14, "truncated JPEG colour image", RUN + ["--dataset", "{d}/ds", "--out", "{d}/t.txt"], exit=1,
         msg="jpeg", setup=setup_jpeg(True), outputs=["t.txt"]),
    case(14, "whole JPEG colour image still read", RUN + ["--dataset", "{d}/ds", "--out", "{d}/t.txt"], exit=0,
         setup=setup_jpeg(False), outputs=["t.txt"], check=check_trajectory_lines("t.txt", 10, 10)),
    # 15. Crafted CRC-valid maps: ids near 2^32 refused; a refused map replaces no --out.
    case(15, "map keyframe id near 2^32", RUN + SYN + ["--load-map", "{d}/wrap.map", "--out", "{d}/t.txt"],
         exit=1, msg="beyond 2147483647", setup=setup_map_wrap, check=check_absent("t.txt")),
    case(15, "map refused while restoring (30 loop edges) keeps --out, says so",
         RUN + SYN + ["--load-map", "{d}/edges.map", "--out", "{d}/good.txt"], exit=1,
         msg="no output was written", setup=setup_map_many_edges),
    case(15, "map of another camera keeps --out",
         RUN + ["--dataset", "{d}/ds", "--camera", "tum3", "--load-map", "{d}/good.map", "--out", "{d}/good.txt"],
         exit=1, msg="another camera", setup=setup_map_other_camera,
         check=lambda d, r: "says the poses were written" if "poses were written" in r.output else ""),
    # 16. Recordings with CRC-valid bad fields.
    case(16, "recording: depth factor 0 in every frame", RUN + ["--dataset", "{d}/rec.plumbrec", "--out",
                                                                 "{d}/t.txt"],
         exit=1, msg="no readable frame", setup=setup_recording(set_depth_factor(0.0)), check=check_absent("t.txt")),
    case(16, "recording: depth factor NaN in every frame", RUN + ["--dataset", "{d}/rec.plumbrec", "--out",
                                                                   "{d}/t.txt"],
         exit=1, msg="no readable frame", setup=setup_recording(set_depth_factor(float("nan"))),
         check=check_absent("t.txt")),
    case(16, "recording: one frame stamped 1e300", RUN + ["--dataset", "{d}/rec.plumbrec", "--out", "{d}/t.txt"],
         exit=0, msg="1 damaged region", setup=setup_recording(stamp_frame(3, 1e300)), outputs=["t.txt"],
         check=check_trajectory_lines("t.txt", 9, 9)),
    # 17. Camera plausibility: each value with its message.
    case(17, "camera cx = -1e9", RUN + ["--dataset", "{d}/ds", "--camera", "{d}/cam.txt", "--out", "{d}/t.txt"],
         exit=1, msg="principal point", setup=camera_file("fx 525\nfy 525\ncx -1e9\ncy 239.5\n")),
    case(17, "camera k1 = 1e6", RUN + ["--dataset", "{d}/ds", "--camera", "{d}/cam.txt", "--out", "{d}/t.txt"],
         exit=1, msg="radial distortion", setup=camera_file(CAM_OK + "k1 1e6\n")),
    case(17, "camera readout 1e9 s", RUN + ["--dataset", "{d}/ds", "--camera", "{d}/cam.txt", "--out", "{d}/t.txt"],
         exit=1, msg="rolling_shutter_readout", setup=camera_file(CAM_OK + "rolling_shutter_readout 1e9\n")),
    case(17, "camera fx = 1e300", RUN + ["--dataset", "{d}/ds", "--camera", "{d}/cam.txt", "--out", "{d}/t.txt"],
         exit=1, msg="focal length", setup=camera_file("fx 1e300\nfy 525\ncx 319.5\ncy 239.5\n")),
    case(17, "camera fx = 1e-300", RUN + ["--dataset", "{d}/ds", "--camera", "{d}/cam.txt", "--out", "{d}/t.txt"],
         exit=1, msg="focal length", setup=camera_file("fx 1e-300\nfy 525\ncx 319.5\ncy 239.5\n")),
    case(17, "camera depth_factor 1e-300", RUN + ["--dataset", "{d}/ds", "--camera", "{d}/cam.txt", "--out",
                                                   "{d}/t.txt"],
         exit=1, msg="depth factor", setup=camera_file(CAM_OK + "depth_factor 1e-300\n")),
    # 18. Messages that say what happened.
    case(18, "full disk: never 'their poses were written'", RUN + SYN + ["--out", "{d}/t.txt"], exit=1,
         msg="could not be written", limit_file_bytes=600, check=check_absent("t.txt")),
    case(18, "UTF-8 BOM in associations.txt is not a timestamp problem",
         RUN + ["--dataset", "{d}/ds", "--out", "{d}/t.txt"], exit=0, setup=setup_bom, outputs=["t.txt"],
         check=check_trajectory_lines("t.txt", 10, 10)),
    case(18, "image that is a symlink loop", RUN + ["--dataset", "{d}/ds", "--out", "{d}/t.txt"], exit=1,
         msg="symlink loop", setup=setup_symlink_loop_image),
    case(18, "udp spec with an extra field", RUN + SYN + ["--out", "{d}/t.txt", "--mavlink",
                                                          "udp:127.0.0.1:14550:extra"],
         exit=2, msg="unexpected field"),
]


# ----------------------------------------------------------------------------------------------

def run_case(env, c, folder):
    os.makedirs(folder)
    if c["setup"]:
        c["setup"](env, folder)
    before = snapshot(folder, c["outputs"])
    sub = lambda a: a.replace("{plumb}", env.plumb).replace("{d}", folder)
    process_env = dict(os.environ)
    preexec = None
    if c["limit_file_bytes"]:
        import resource
        limit = c["limit_file_bytes"]
        def preexec():
            signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # writes past the limit fail (EFBIG) like a full disk
            resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    if c["python"] is not None:
        if not env.python or not env.python_dir or not os.path.isdir(env.python_dir):
            return "SKIP", "the Python module was not built"
        program = os.path.join(folder, "..", os.path.basename(folder) + ".py")
        write_text(program, c["python"])
        process_env["PYTHONPATH"] = env.python_dir
        cmd = [env.python, program]
    else:
        cmd = [sub(a) for a in c["cmd"]]
    close_after_line = c["name"].startswith("SIGPIPE")
    r = run_command(cmd, folder, c["timeout"], send_signal=c["signal"], env=process_env, preexec=preexec,
                    close_stderr_after_line=close_after_line)
    problems = []
    if r.code == "timeout":
        problems.append("did not end within %.0f s" % c["timeout"])
    elif r.code != c["exit"]:
        problems.append("exit %s, expected %d" % (r.code, c["exit"]))
    if isinstance(r.code, int) and (r.code < 0 or r.code == 70) and c["exit"] not in (r.code,):
        problems.append("crashed (signal or internal error)")
    if c["msg"] and c["msg"].lower() not in r.output.lower():
        problems.append("message lacks '%s'" % c["msg"])
    if c["mem_mb"] is not None and r.max_rss_kib > c["mem_mb"] * 1024:
        problems.append("peak RSS %.0f MB > %.0f MB" % (r.max_rss_kib / 1024.0, c["mem_mb"]))
    after = snapshot(folder, c["outputs"])
    changed = sorted(os.path.relpath(p, folder) for p in set(before) | set(after)
                     if before.get(p) != after.get(p) and not os.path.basename(p).startswith("."))
    changed = [p for p in changed if not any(p == o for o in c["outputs"])]
    new_outputs = [p for p in changed if p not in [os.path.relpath(q, folder) for q in before]]
    modified = [p for p in changed if p not in new_outputs]
    if modified:
        problems.append("inputs changed: " + ", ".join(modified[:4]))
    if new_outputs and c["exit"] != 0:
        problems.append("files left behind: " + ", ".join(new_outputs[:4]))
    partial = partial_files(folder)
    if partial:
        problems.append("partial files left: " + ", ".join(os.path.relpath(p, folder) for p in partial[:3]))
    if c["check"] and not problems:
        extra = c["check"](folder, r)
        if extra:
            problems.append(extra)
    detail = "%.1f s, %.0f MB" % (r.seconds, r.max_rss_kib / 1024.0)
    if problems:
        tail = " | ".join(l for l in r.output.strip().splitlines()[-2:])
        return "FAIL", "; ".join(problems) + " [%s] output: %s" % (detail, tail[:300])
    return "PASS", detail


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--plumb", required=True)
    parser.add_argument("--datasets", default="")
    parser.add_argument("--python", default="")
    parser.add_argument("--python-dir", default="")
    parser.add_argument("--jpeg-helper", default="")
    parser.add_argument("--only", default="")
    parser.add_argument("--list", action="store_true")
    parser.add_argument("--keep", action="store_true", help="keep the scratch folders")
    parser.add_argument("--time-scale", type=float, default=1.0,
                        help="multiply every time limit (an emulated cross build runs ~10x slower)")
    parser.add_argument("--memory-slack-mb", type=float, default=0.0,
                        help="added to every memory bound (an emulator's own resident memory)")
    args = parser.parse_args()
    if args.list:
        for c in CASES:
            print("%2d  %s" % (c["cls"], c["name"]))
        return 0
    for c in CASES:
        c["timeout"] *= args.time_scale
        if c["mem_mb"] is not None:
            c["mem_mb"] += args.memory_slack_mb
        if c["signal"]:
            c["signal"] = (c["signal"][0], c["signal"][1] * args.time_scale)
    work = tempfile.mkdtemp(prefix="plumb_hostile_")
    env = Env(args, work)
    results = {"PASS": 0, "FAIL": 0, "SKIP": 0}
    classes_failed = set()
    try:
        for i, c in enumerate(CASES):
            if args.only and args.only not in c["name"] and args.only != str(c["cls"]):
                continue
            if c["setup"] is not None and "jpeg" in getattr(c["setup"], "__qualname__", "") and not (
                    args.jpeg_helper and os.path.exists(args.jpeg_helper)):
                verdict, detail = "SKIP", "no JPEG helper (plumb_hostile_jpeg)"
            else:
                try:
                    verdict, detail = run_case(env, c, os.path.join(work, "case%02d" % i))
                except Exception as e:  # a setup problem is a failure of the row, with its reason
                    verdict, detail = "FAIL", "setup: %s" % e
            results[verdict] += 1
            if verdict == "FAIL":
                classes_failed.add(c["cls"])
            print("%-4s %2d  %-62s %s" % (verdict, c["cls"], c["name"], detail), flush=True)
    finally:
        if not args.keep:
            shutil.rmtree(work, ignore_errors=True)
    print("hostile: %d passed, %d failed, %d skipped; classes failing: %s" %
          (results["PASS"], results["FAIL"], results["SKIP"],
           ",".join(str(c) for c in sorted(classes_failed)) or "none"))
    return 1 if results["FAIL"] else 0


if __name__ == "__main__":
    sys.exit(main())
