#!/usr/bin/env python3
"""Layer check: every #include and every CMake link edge must follow the layer rules.

Usage: scripts/check_layers.py [SOURCE_DIR]        (default: the repository holding this script)
       scripts/check_layers.py --rules             (print the rule table and exit)

Exit 0 when the tree is clean, 1 with one `path:line: message` per violation, 2 on a usage error.
Python 3 standard library only. Registered as the ctest test `layering`; its own test is
tests/tools/layer_check_test.py (ctest `layering_selftest`).

Why a resolver and not a pattern match: the compiler looks for "x.h" next to the including file
first and then on the include path (the source root only), and for <x> on the include path and
then in the system directories. The check does the same, so "../drivers/x.h" is seen as a use of
drivers/, and a quoted name that is not a file of the tree (it would silently pick up a system
header) is an error. Every header that is not a file of the tree must belong to a known family
(C++ standard, POSIX, Eigen, OpenCV, ...) that the including layer may use: a new third-party
dependency fails until it is added to the table below.
"""

import fnmatch
import glob
import os
import re
import sys

# --------------------------------------------------------------------------------------------
# Layers. A source file belongs to the layer of the longest folder prefix below; tests/<area>
# and bench/<x> folders are layers of their own kind. A source file in no layer is an error.

PRODUCT = ["platform", "runtime", "solver", "sensor", "pipeline/frontend", "pipeline/odometry",
           "pipeline/loop", "pipeline/run", "drivers"]
# api/: the public front door (<plumb/odometry.h>, the Python module) over everything below it;
# no product folder uses it. examples/: separate projects built against an INSTALLED plumb
# (find_package(plumb)), so they include only <plumb/...> and link only plumb::plumb.
# viewer/: watching a run (docs/VIEWER.md), over pipeline/run and drivers; only tools/, tests and
# benchmarks use it (a product folder of its own that no other product folder may include).
VIEWER = ["viewer"]
FIXED_LAYERS = PRODUCT + VIEWER + ["api", "examples", "tools", "tests/support", "bench", "fuzz"]

_PIPE = ["sensor", "solver", "runtime", "platform"]
# Project folders a layer may include/link besides itself.
ALLOWED_LAYERS = {
    "platform": [],
    "runtime": ["platform"],
    "solver": [],  # pure maths: Eigen and the standard library, not even platform/
    "sensor": ["platform"],
    "pipeline/frontend": _PIPE,
    "pipeline/odometry": ["pipeline/frontend"] + _PIPE,
    "pipeline/loop": ["pipeline/odometry", "pipeline/frontend"] + _PIPE,
    "pipeline/run": ["pipeline/loop", "pipeline/odometry", "pipeline/frontend"] + _PIPE,
    # solver/ for SE(3) maths only (output frame conventions, e.g. MAVLink's covariance).
    "drivers": ["sensor", "solver", "runtime", "platform"],
    "viewer": PRODUCT,
    "api": PRODUCT,
    "examples": [],
    "tools": PRODUCT + VIEWER,
    "tests/support": PRODUCT,
    "tests/*": PRODUCT + VIEWER + ["api", "tests/support"],
    # Benchmarks and fuzzers may share test scaffolding, but only what tests/support holds.
    "bench": PRODUCT + VIEWER + ["tests/support"],
    "fuzz": PRODUCT + VIEWER + ["tests/support"],
}

# Families of headers (and link items) that are not files of the tree.
STD_CXX = set("""algorithm any array atomic barrier bit bitset cassert ccomplex cctype cerrno cfenv
cfloat charconv chrono cinttypes ciso646 climits clocale cmath codecvt compare complex concepts
condition_variable coroutine csetjmp csignal cstdalign cstdarg cstdbool cstddef cstdint cstdio
cstdlib cstring ctgmath ctime cuchar cwchar cwctype deque exception execution filesystem format
forward_list fstream functional future initializer_list iomanip ios iosfwd iostream istream
iterator latch limits list locale map memory memory_resource mutex new numbers numeric optional
ostream queue random ranges ratio regex scoped_allocator semaphore set shared_mutex
source_location span sstream stack stdexcept stop_token streambuf string string_view strstream
syncstream system_error thread tuple type_traits typeindex typeinfo unordered_map unordered_set
utility valarray variant vector version""".split())
STD_C = set("""assert complex ctype errno fenv float inttypes iso646 limits locale math setjmp
signal stdalign stdarg stdatomic stdbool stddef stdint stdio stdlib string tgmath threads time
uchar wchar wctype""".split())
POSIX_H = set("""aio arpa/inet cpio dirent dlfcn execinfo fcntl fmtmsg fnmatch ftw glob grp iconv
langinfo libgen malloc monetary mqueue ndbm netdb nl_types poll pthread pwd regex sched search
semaphore spawn strings syslog tar termios ulimit unistd utime utmpx wordexp""".split())
POSIX_DIRS = ("sys/", "linux/", "asm/", "asm-generic/", "bits/", "arpa/", "netinet/", "net/")

# Standard headers solver/ must not include: solver/ is called from any thread and must neither
# start, lock or wait on threads (threads) nor touch files or the process's standard streams
# (files). Formatting into a string (<sstream>, <ostream>) is allowed; so are clocks (<chrono>).
SOLVER_FORBIDDEN_STD = {
    # threads
    "thread", "mutex", "shared_mutex", "condition_variable", "future", "atomic", "stop_token",
    "semaphore", "latch", "barrier", "execution", "threads.h", "stdatomic.h",
    # files and process streams
    "fstream", "iostream", "cstdio", "stdio.h", "filesystem", "syncstream",
}


def header_family(name):
    """Family of an include <name> that is not a file of the tree, or None when unknown."""
    if name in STD_CXX:
        return "std"
    if name.endswith(".h") and name[:-2] in STD_C:
        return "std"
    # The compiler's own SIMD intrinsics (x86 SSE/AVX, ARM NEON): part of the toolchain, like std.
    if name in ("emmintrin.h", "xmmintrin.h", "pmmintrin.h", "tmmintrin.h", "smmintrin.h", "nmmintrin.h",
                "immintrin.h", "arm_neon.h"):
        return "std"
    if (name.endswith(".h") and name[:-2] in POSIX_H) or name.startswith(POSIX_DIRS):
        return "posix"
    if name.startswith(("Eigen/", "unsupported/Eigen/")):
        return "eigen"
    if name == "opencv2/core.hpp" or name.startswith("opencv2/core/"):
        return "opencv_core"
    if name.startswith("opencv2/"):
        return "opencv"
    if name == "png.h":
        return "png"
    if name == "libdeflate.h":
        return "libdeflate"
    if name == "zlib.h":
        return "zlib"
    if name == "jpeglib.h":
        return "jpeg"
    if name in ("OpenNI.h", "openni2/OpenNI.h"):
        return "openni2"
    if name in ("libusb.h", "libusb-1.0/libusb.h"):
        return "libusb"
    if name.startswith(("gtest/", "gmock/")):
        return "gtest"
    if name.startswith("ceres/"):
        return "ceres"
    if name.startswith("pybind11/"):
        return "pybind11"
    if name.startswith("websocketpp/"):
        return "websocketpp"
    if name == "asio.hpp" or name.startswith("asio/"):
        return "asio"
    if name.startswith("plumb/"):
        return "plumb_installed"  # the installed public headers (examples/)
    return None


_ALL_THIRD_PARTY = ["std", "posix", "eigen", "opencv_core", "opencv", "png", "jpeg", "libdeflate",
                    "openni2", "libusb"]
ALLOWED_FAMILIES = {
    "platform": ["std", "posix"],
    "runtime": ["std", "posix"],
    "solver": ["std", "eigen"],  # minus SOLVER_FORBIDDEN_STD
    "sensor": ["std", "eigen", "opencv_core"],
    "pipeline/frontend": ["std", "eigen", "opencv_core", "opencv"],
    "pipeline/odometry": ["std", "eigen", "opencv_core", "opencv"],
    "pipeline/loop": ["std", "eigen", "opencv_core", "opencv"],
    "pipeline/run": ["std", "eigen", "opencv_core", "opencv"],
    "drivers": _ALL_THIRD_PARTY,
    "viewer": _ALL_THIRD_PARTY + ["websocketpp", "asio"],
    "api": _ALL_THIRD_PARTY + ["pybind11"],
    "examples": ["std", "eigen", "plumb_installed"],
    "tools": _ALL_THIRD_PARTY,
    "tests/support": _ALL_THIRD_PARTY + ["gtest"],
    # Ceres: a test-only oracle; websocketpp/asio: tests/viewer's client.
    "tests/*": _ALL_THIRD_PARTY + ["gtest", "ceres", "websocketpp", "asio"],
    "bench": _ALL_THIRD_PARTY + ["ceres", "websocketpp", "asio"],  # bench/viewer's clients
    "fuzz": _ALL_THIRD_PARTY + ["zlib"],  # zlib: re-deflating mutated PNGs
}

# CMake link items that are not targets of the tree, by family.
LINK_FAMILIES = [
    (r"Eigen3::.*", "eigen"),
    (r"opencv_core", "opencv_core"),
    (r"opencv_.*|\$\{OpenCV_LIBS\}|\$\{OpenCV_LIBRARIES\}", "opencv"),
    (r"Threads::Threads|pthread|rt|dl|\$\{CMAKE_THREAD_LIBS_INIT\}", "posix"),
    (r"m", "std"),
    (r"PNG::PNG|PkgConfig::PNG|png", "png"),
    (r"ZLIB::ZLIB|PkgConfig::ZLIB|z", "zlib"),
    (r"JPEG::JPEG|jpeg", "jpeg"),
    (r"PkgConfig::LIBDEFLATE|deflate", "libdeflate"),
    (r"PkgConfig::OPENNI2|OpenNI2", "openni2"),
    (r"PkgConfig::LIBUSB|usb-1\.0", "libusb"),
    (r"GTest::.*|gtest|gtest_main|gmock", "gtest"),
    (r"Ceres::ceres|ceres", "ceres"),
    (r"pybind11::.*", "pybind11"),
    (r"plumb::.*", "plumb_installed"),
]

SOURCE_EXTENSIONS = (".h", ".hh", ".hpp", ".hxx", ".inl", ".ipp", ".tpp", ".c", ".cc", ".cpp",
                     ".cxx")


def layer_of(rel):
    """Layer of a repository-relative path (file or folder), or None."""
    parts = rel.split("/")
    if parts[0] == "tests" and len(parts) >= 3:
        return "tests/support" if parts[1] == "support" else "tests/" + parts[1]
    best = None
    for layer in FIXED_LAYERS:
        if rel == layer or rel.startswith(layer + "/"):
            if best is None or len(layer) > len(best):
                best = layer
    return best


def rule_key(layer):
    if layer.startswith("tests/") and layer != "tests/support":
        return "tests/*"
    return layer


def coarse(layer):
    """The unit that is one CMake library: all of pipeline/ is plumb_pipeline."""
    return "pipeline" if layer.startswith("pipeline/") else layer


def layer_may_use(user, used):
    return used == user or used in ALLOWED_LAYERS[rule_key(user)]


def coarse_may_use(user, used):
    """user/used are coarse layers; true when some fine layer of user may use some of used."""
    if user == used:
        return True
    users = [l for l in PRODUCT if coarse(l) == user] or [user]
    useds = [l for l in PRODUCT if coarse(l) == used] or [used]
    return any(layer_may_use(u, v) for u in users for v in useds)


def family_allowed(layer, family, header):
    if family not in ALLOWED_FAMILIES[rule_key(layer)]:
        return False
    if layer == "solver" and header in SOLVER_FORBIDDEN_STD:
        return False
    return True


# --------------------------------------------------------------------------------------------
# Reading sources.

_INCLUDE = re.compile(r'^[ \t]*#[ \t]*(include|include_next|import)\b[ \t]*(.*)$')
_HAS_INCLUDE = re.compile(r'__has_include(?:_next)?\s*\(\s*([<"][^>"]*[>"])\s*\)')


def strip_comments(text):
    """Replaces comments by spaces (keeping newlines) so commented-out includes are not counted.
    String and character literals are kept as they are."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if c == "/" and i + 1 < n and text[i + 1] == "/":
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif c == "/" and i + 1 < n and text[i + 1] == "*":
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append("".join(ch if ch == "\n" else " " for ch in text[i:j]))
            i = j
        elif c in "\"'":
            # A raw string R"(...)" cannot hold a directive at line start that matters here.
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            out.append(text[i:j + 1])
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def read_includes(path):
    """[(line, spelled, kind)] with kind '"' or '<', or '?' for a computed include."""
    with open(path, encoding="utf-8", errors="replace") as f:
        text = f.read()
    lines = strip_comments(text.replace("\r\n", "\n")).split("\n")
    found = []
    number = 0
    while number < len(lines):
        start = number + 1
        line = lines[number]
        # A directive may continue on the next line after a backslash.
        while line.endswith("\\") and number + 1 < len(lines):
            number += 1
            line = line[:-1] + lines[number]
        number += 1
        m = _INCLUDE.match(line)
        if m:
            arg = m.group(2).strip()
            if arg.startswith('"') and arg.find('"', 1) > 0:
                found.append((start, arg[1:arg.find('"', 1)], '"'))
            elif arg.startswith("<") and arg.find(">") > 0:
                found.append((start, arg[1:arg.find(">")], "<"))
            else:
                found.append((start, arg, "?"))
        for h in _HAS_INCLUDE.findall(line):
            found.append((start, h[1:-1], h[0]))
    return found


def is_build_tree(dirpath):
    return os.path.exists(os.path.join(dirpath, "CMakeCache.txt"))


def walk_tree(root):
    """Repository-relative paths of all files, skipping hidden folders and build trees."""
    for dirpath, dirnames, filenames in os.walk(root):
        rel_dir = os.path.relpath(dirpath, root)
        keep = []
        for d in sorted(dirnames):
            full = os.path.join(dirpath, d)
            if d.startswith("."):
                continue
            if rel_dir == "." and fnmatch.fnmatch(d, "build*"):
                continue
            if is_build_tree(full):
                continue
            keep.append(d)
        dirnames[:] = keep
        for name in sorted(filenames):
            rel = os.path.normpath(os.path.join(rel_dir, name)).replace(os.sep, "/")
            yield rel


# --------------------------------------------------------------------------------------------
# The checker.

class Checker:
    def __init__(self, root):
        self.root = os.path.realpath(root)
        self.violations = []           # (path, line, message)
        self.folder_edges = {}         # (from_dir, to_dir) -> "path:line"

    def report(self, path, line, message):
        self.violations.append((path, line, message))

    def resolve(self, including_rel, spelled, kind):
        """Repository-relative real path of the file the compiler would open, 'outside' for a
        file out of the tree, or None when there is no such file. Symbolic links are followed
        (component by component, as the kernel does), so a link cannot move a file into
        another layer."""
        candidates = []
        if kind == '"':
            candidates.append(os.path.join(os.path.dirname(including_rel), spelled))
        candidates.append(spelled)  # the source root is the only project include directory
        for cand in candidates:
            if os.path.isabs(cand):
                return "outside" if os.path.isfile(cand) else None
            real = os.path.realpath(os.path.join(self.root, cand))
            if not os.path.isfile(real):
                continue
            if not real.startswith(self.root + os.sep):
                return "outside"
            return os.path.relpath(real, self.root).replace(os.sep, "/")
        return None

    def note_folder_edge(self, src_rel, dst_rel, where):
        a, b = os.path.dirname(src_rel), os.path.dirname(dst_rel)
        # Only edges the rules allow: a forbidden edge is reported as such, and as the rules
        # between layers form no cycle, any cycle left is among folders of one layer.
        if a != b:
            self.folder_edges.setdefault((a, b), where)

    # ---- includes
    def check_sources(self):
        pending = [rel for rel in walk_tree(self.root) if rel.endswith(SOURCE_EXTENSIONS)]
        scanned = set()
        while pending:
            rel = pending.pop(0)
            if rel in scanned:
                continue
            scanned.add(rel)
            layer = layer_of(rel)
            if layer is None:
                self.report(rel, 0, "source file in no layer folder (see ALLOWED_LAYERS in "
                            "scripts/check_layers.py)")
                continue
            for line, spelled, kind in read_includes(os.path.join(self.root, rel)):
                target = self.check_include(rel, layer, line, spelled, kind)
                # An included file is code whatever its name (x.inc, x.def): read it too.
                if target is not None and target not in scanned:
                    pending.append(target)

    def check_include(self, rel, layer, line, spelled, kind):
        shown = {'"': '"%s"', "<": "<%s>", "?": "%s"}[kind] % spelled
        if kind == "?":
            self.report(rel, line, "#include %s: computed include, cannot be checked" % shown)
            return
        target = self.resolve(rel, spelled, kind)
        if target == "outside":
            self.report(rel, line, "#include %s leaves the source tree" % shown)
            return
        if target is None:
            if kind == '"':
                self.report(rel, line, "#include %s is not a file of the tree: a quoted include "
                            "must name a project file (next to this one or from the source "
                            "root), else the compiler silently takes a system header of that "
                            "name; use <...> for system headers" % shown)
                return
            family = header_family(spelled)
            if family is None:
                self.report(rel, line, "#include %s: unknown external header (add its family "
                            "to scripts/check_layers.py if %s/ may use it)" % (shown, layer))
            elif not family_allowed(layer, family, spelled):
                what = family
                if layer == "solver" and spelled in SOLVER_FORBIDDEN_STD:
                    what = "threads/files std header"
                self.report(rel, line, "#include %s: %s/ must not use %s" % (shown, layer, what))
            return
        used = layer_of(target)
        if used is None:
            self.report(rel, line, "#include %s -> %s, a file in no layer folder" % (shown, target))
            return
        if not layer_may_use(layer, used):
            self.report(rel, line, "#include %s -> %s: %s/ must not include %s/" %
                        (shown, target, layer, used))
            return
        self.note_folder_edge(rel, target, "%s:%d" % (rel, line))
        return target

    # ---- folder cycles
    def check_cycles(self):
        graph = {}
        for (a, b) in self.folder_edges:
            graph.setdefault(a, set()).add(b)
            graph.setdefault(b, set())
        for scc in strongly_connected(graph):
            if len(scc) < 2:
                continue
            members = sorted(scc)
            edges = ["%s -> %s (%s)" % (a, b, self.folder_edges[(a, b)])
                     for a in members for b in sorted(graph[a]) if b in scc]
            loop = shortest_cycle(graph, members[0], scc)
            self.report(members[0], 0, "folder cycle %s; the folders %s depend on each other "
                        "through: %s" % (" -> ".join(loop), ", ".join(m + "/" for m in members),
                                         "; ".join(edges)))

    # ---- CMake
    def check_cmake(self):
        model = CMakeModel(self.root)
        files = [rel for rel in walk_tree(self.root)
                 if os.path.basename(rel) == "CMakeLists.txt" or rel.endswith(".cmake")]
        # Modules first: they define the functions that CMakeLists.txt files call.
        for rel in sorted(files, key=lambda r: (not r.endswith(".cmake"), r.count("/"), r)):
            model.run_file(rel)
        for problem in model.problems:
            self.report(*problem)
        for name, target in sorted(model.targets.items()):
            self.check_target(model, name, target)

    def target_home(self, target):
        here = layer_of(target["dir"] + "/x") if target["dir"] != "." else None
        if target["dir"] == "pipeline":
            return "pipeline"
        if here is not None:
            return coarse(here)
        counts = {}
        for src, _ in target["sources"]:
            l = layer_of(src)
            if l is not None:
                counts[coarse(l)] = counts.get(coarse(l), 0) + 1
        if counts:
            return max(sorted(counts), key=lambda k: counts[k])
        return None

    def check_target(self, model, name, target):
        home = self.target_home(target)
        where = target["where"]
        if home is None:
            self.report(where[0], where[1], "target %s is in no layer folder" % name)
            return
        target["home"] = home
        for src, at in target["sources"]:
            l = layer_of(src)
            if l is None:
                self.report(at[0], at[1], "target %s compiles %s, a file in no layer folder" %
                            (name, src))
            elif not coarse_may_use(home, coarse(l)):
                self.report(at[0], at[1], "target %s (%s/) compiles %s: %s/ must not use %s/" %
                            (name, home, src, home, coarse(l)))
        for item, at in target["links"]:
            item = model.aliases.get(item, item)
            if item in model.targets:
                used = self.target_home(model.targets[item])
                if used is not None and not coarse_may_use(home, used):
                    self.report(at[0], at[1], "target %s (%s/) links %s (%s/): %s/ must not "
                                "link %s/" % (name, home, item, used, home, used))
                continue
            family = None
            for pattern, fam in LINK_FAMILIES:
                if re.fullmatch(pattern, item):
                    family = fam
                    break
            if family is None:
                self.report(at[0], at[1], "target %s links %s: unknown library (add it to "
                            "LINK_FAMILIES in scripts/check_layers.py if %s/ may use it)" %
                            (name, item, home))
                continue
            fine = [l for l in PRODUCT if coarse(l) == home] or [home]
            if not any(family_allowed(l, family, "") for l in fine):
                self.report(at[0], at[1], "target %s (%s/) links %s: %s/ must not use %s" %
                            (name, home, item, home, family))
        for inc, at in target["include_dirs"]:
            self.check_include_dir(name, inc, at)

    def check_include_dir(self, name, inc, at):
        if "${" in inc or "$<" in inc:
            return  # an external package's directories (${OpenCV_INCLUDE_DIRS})
        path = inc if os.path.isabs(inc) else os.path.join(self.root, inc)
        real = os.path.realpath(path)
        if (real.startswith(self.root + os.sep) or real == self.root) and real != self.root:
            self.report(at[0], at[1], "%s adds include directory %s: only the source root may "
                        "be an include directory (a folder-less include would bypass the "
                        "layer check)" % (name, os.path.relpath(real, self.root)))

    def run(self):
        self.check_sources()
        self.check_cycles()
        self.check_cmake()
        return self.violations


def shortest_cycle(graph, start, within):
    """Shortest path start -> ... -> start inside the node set `within` (breadth first)."""
    previous, frontier = {start: None}, [start]
    while frontier:
        following = []
        for node in frontier:
            for child in sorted(graph[node]):
                if child not in within:
                    continue
                if child == start:
                    path = [node]
                    while previous[path[-1]] is not None:
                        path.append(previous[path[-1]])
                    return path[::-1] + [start]
                if child not in previous:
                    previous[child] = node
                    following.append(child)
        frontier = following
    return [start]


def strongly_connected(graph):
    """Tarjan's algorithm, iterative; yields sets of nodes."""
    index, low, on_stack, stack, counter = {}, {}, set(), [], [0]
    for start in sorted(graph):
        if start in index:
            continue
        work = [(start, iter(sorted(graph[start])))]
        index[start] = low[start] = counter[0]
        counter[0] += 1
        stack.append(start)
        on_stack.add(start)
        while work:
            node, children = work[-1]
            advanced = False
            for child in children:
                if child not in index:
                    index[child] = low[child] = counter[0]
                    counter[0] += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph[child]))))
                    advanced = True
                    break
                if child in on_stack:
                    low[node] = min(low[node], index[child])
            if advanced:
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                scc = set()
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    scc.add(member)
                    if member == node:
                        break
                yield scc


# --------------------------------------------------------------------------------------------
# A small CMake reader: enough of the language to know every target's sources, link items and
# include directories without configuring a build. Conditions are not evaluated: every branch of
# an if() counts and return() is ignored, so an optional dependency is checked as if present.

def tokenize_cmake(text):
    """[(command, [(arg, quoted)], line)]"""
    commands = []
    i, n, line = 0, len(text), 1
    ident = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
    while i < n:
        c = text[i]
        if c == "\n":
            line += 1
            i += 1
        elif c.isspace():
            i += 1
        elif c == "#":
            m = re.match(r"#\[(=*)\[", text[i:])
            if m:
                end = text.find("]" + m.group(1) + "]", i)
                end = n if end < 0 else end + len(m.group(1)) + 2
            else:
                end = text.find("\n", i)
                end = n if end < 0 else end
            line += text.count("\n", i, end)
            i = end
        else:
            m = ident.match(text, i)
            if not m:
                i += 1
                continue
            name, start_line = m.group(0).lower(), line
            i = m.end()
            while i < n and text[i] in " \t":
                i += 1
            if i >= n or text[i] != "(":
                continue
            i += 1
            args, depth, current, quoted = [], 0, [], False
            while i < n:
                c = text[i]
                if c == '"':
                    j = i + 1
                    buf = []
                    while j < n and text[j] != '"':
                        if text[j] == "\\" and j + 1 < n:
                            buf.append(text[j:j + 2] if text[j + 1] not in '"\\' else text[j + 1])
                            j += 2
                            continue
                        buf.append(text[j])
                        j += 1
                    line += text.count("\n", i, j)
                    args.append(("".join(buf), True))
                    i = j + 1
                elif c == "#":
                    end = text.find("\n", i)
                    i = n if end < 0 else end
                elif c == "(":
                    depth += 1
                    current.append(c)
                    i += 1
                elif c == ")":
                    if depth == 0:
                        if current:
                            args.append(("".join(current), False))
                        i += 1
                        break
                    depth -= 1
                    current.append(c)
                    i += 1
                elif c.isspace():
                    if c == "\n":
                        line += 1
                    if current:
                        args.append(("".join(current), False))
                        current = []
                    i += 1
                else:
                    current.append(c)
                    i += 1
            commands.append((name, args, start_line))
    return commands


class CMakeModel:
    def __init__(self, root):
        self.root = root
        self.targets = {}      # name -> {"dir", "where", "sources", "links", "include_dirs"}
        self.aliases = {}
        self.functions = {}    # name -> (params, body commands, defining file)
        self.problems = []

    def run_file(self, rel):
        with open(os.path.join(self.root, rel), encoding="utf-8", errors="replace") as f:
            commands = tokenize_cmake(f.read())
        directory = os.path.dirname(rel) or "."
        variables = {
            "CMAKE_SOURCE_DIR": self.root, "PROJECT_SOURCE_DIR": self.root,
            "CMAKE_CURRENT_SOURCE_DIR": os.path.join(self.root, directory),
            "CMAKE_CURRENT_LIST_DIR": os.path.join(self.root, directory),
        }
        self.execute(commands, variables, rel, directory)

    def expand(self, value, variables):
        def sub(m):
            return variables.get(m.group(1), m.group(0))
        for _ in range(8):  # nested ${a_${b}}
            new = re.sub(r"\$\{([A-Za-z0-9_.+-]+)\}", sub, value)
            if new == value:
                break
            value = new
        return value

    def expand_args(self, args, variables):
        out = []
        for value, quoted in args:
            value = self.expand(value, variables)
            if quoted:
                out.append(value)
            else:
                out.extend(v for v in value.split(";") if v != "")
        return out

    def execute(self, commands, variables, rel, directory, call_line=None):
        """Runs commands; inside a function body, call_line is the line of the call, so a
        violation points at the call that supplied the arguments."""
        i = 0
        while i < len(commands):
            name, args, line = commands[i]
            if name in ("function", "macro"):
                end = "end" + name
                depth, j = 0, i + 1
                while j < len(commands):
                    if commands[j][0] == name:
                        depth += 1
                    elif commands[j][0] == end:
                        if depth == 0:
                            break
                        depth -= 1
                    j += 1
                words = [a for a, _ in args]
                if words:
                    self.functions[words[0].lower()] = (words[1:], commands[i + 1:j])
                i = j + 1
                continue
            if name == "foreach":
                depth, j = 0, i + 1
                while j < len(commands):
                    if commands[j][0] == "foreach":
                        depth += 1
                    elif commands[j][0] == "endforeach":
                        if depth == 0:
                            break
                        depth -= 1
                    j += 1
                words = self.expand_args(args, variables)
                body = commands[i + 1:j]
                if words:
                    var, items = words[0], words[1:]
                    if items[:1] == ["IN"]:
                        items = [w for w in items[1:] if w not in ("LISTS", "ITEMS")]
                    if items[:1] == ["RANGE"]:
                        items = []
                    for item in items:
                        scope = dict(variables)
                        scope[var] = item
                        self.execute(body, scope, rel, directory, call_line)
                i = j + 1
                continue
            where = (rel, call_line if call_line is not None else line)
            self.command(name, self.expand_args(args, variables), variables, where, directory)
            i += 1

    def source_path(self, value, directory):
        path = value if os.path.isabs(value) else os.path.join(self.root, directory, value)
        return os.path.normpath(os.path.relpath(os.path.realpath(path), self.root)).replace(
            os.sep, "/")

    def add_sources(self, entry, values, where, directory):
        for value in values:
            objects = re.fullmatch(r"\$<TARGET_OBJECTS:([^>]+)>", value)
            if objects:  # another target's object files: as good as linking it
                entry["links"].append((objects.group(1), where))
            elif "$<" in value:
                continue  # other generator expressions select flags or configurations
            elif value.startswith("${CMAKE_CURRENT_BINARY_DIR}/") and "${" not in value[28:]:
                # A file this folder's build generates (viewer/'s embedded page): it belongs to the
                # folder whose CMakeLists.txt makes it.
                entry["sources"].append((os.path.normpath(os.path.join(directory, value[28:])).replace(
                    os.sep, "/"), where))
            elif "${" in value:
                self.problems.append((where[0], where[1], "source %s: a variable this check "
                                      "cannot see (set it in the same file)" % value))
            else:
                entry["sources"].append((self.source_path(value, directory), where))

    def command(self, name, words, variables, where, directory):
        keywords = {"PUBLIC", "PRIVATE", "INTERFACE", "LINK_PUBLIC", "LINK_PRIVATE",
                    "LINK_INTERFACE_LIBRARIES", "debug", "optimized", "general", "SYSTEM",
                    "BEFORE", "AFTER"}
        if name in self.functions:
            params, body = self.functions[name]
            scope = dict(variables)
            for k, p in enumerate(params):
                scope[p] = words[k] if k < len(words) else ""
            for k, w in enumerate(words):
                scope["ARGV%d" % k] = w
            scope["ARGN"] = ";".join(words[len(params):])
            scope["ARGV"] = ";".join(words)
            self.execute(body, scope, where[0], directory, where[1])
            return
        if name == "set" and words:
            values = words[1:]
            for stop in ("CACHE", "PARENT_SCOPE"):
                if stop in values:
                    values = values[:values.index(stop)]
            variables[words[0]] = ";".join(values)
        elif name == "list" and len(words) >= 2 and words[0] == "APPEND":
            old = variables.get(words[1], "")
            variables[words[1]] = ";".join([v for v in old.split(";") if v] + words[2:])
        elif name == "file" and len(words) >= 2 and words[0] in ("GLOB", "GLOB_RECURSE"):
            patterns, relative, k = [], None, 2
            while k < len(words):
                w = words[k]
                if w == "LIST_DIRECTORIES":
                    k += 2
                    continue
                if w == "RELATIVE":
                    relative = words[k + 1] if k + 1 < len(words) else None
                    k += 2
                    continue
                if w != "CONFIGURE_DEPENDS":
                    patterns.append(w)
                k += 1
            found = []
            for p in patterns:
                full = p if os.path.isabs(p) else os.path.join(self.root, directory, p)
                found.extend(sorted(glob.glob(full, recursive=words[0] == "GLOB_RECURSE")))
            if relative:
                found = [os.path.relpath(f, relative) for f in found]
            variables[words[1]] = ";".join(found)
        elif name in ("add_library", "add_executable", "pybind11_add_module") and words:
            target, rest = words[0], words[1:]
            if "IMPORTED" in rest:
                return
            if "ALIAS" in rest:
                self.aliases[target] = rest[rest.index("ALIAS") + 1]
                return
            skip = {"STATIC", "SHARED", "MODULE", "OBJECT", "INTERFACE", "UNKNOWN", "WIN32",
                    "MACOSX_BUNDLE", "EXCLUDE_FROM_ALL", "GLOBAL"}
            entry = self.targets.setdefault(target, {
                "dir": directory, "where": where, "sources": [], "links": [],
                "include_dirs": []})
            self.add_sources(entry, [s for s in rest if s not in skip], where, directory)
        elif name == "target_sources" and words:
            entry = self.targets.get(words[0])
            if entry is not None:
                self.add_sources(entry, [s for s in words[1:] if s not in
                                         ("PUBLIC", "PRIVATE", "INTERFACE")], where, directory)
        elif name == "target_link_libraries" and words:
            entry = self.targets.get(words[0])
            if entry is None:
                self.problems.append((where[0], where[1], "target_link_libraries(%s ...) before "
                                      "its add_library/add_executable" % words[0]))
                return
            for w in words[1:]:
                if w in keywords:
                    continue
                if w.startswith("$<"):
                    inner = re.sub(r"^\$<.*:", "", w).rstrip(">")
                    if not inner:
                        continue
                    w = inner
                entry["links"].append((w, where))
        elif name == "target_include_directories" and words:
            entry = self.targets.get(words[0])
            if entry is not None:
                entry["include_dirs"] += [(w, where) for w in words[1:] if w not in keywords]
        elif name == "include_directories":
            for w in words:
                if w not in keywords and "${" not in w and "$<" not in w:
                    full = w if os.path.isabs(w) else os.path.join(self.root, directory, w)
                    real = os.path.realpath(full)
                    if real != os.path.realpath(self.root) and real.startswith(
                            os.path.realpath(self.root) + os.sep):
                        self.problems.append((where[0], where[1], "include_directories(%s): "
                                              "only the source root may be an include directory"
                                              % os.path.relpath(real, self.root)))
        elif name == "link_libraries":
            self.problems.append((where[0], where[1], "link_libraries() links every target of "
                                  "the folder; use target_link_libraries so the layer check "
                                  "sees each edge"))


def print_rules():
    print("Layer           may include/link (besides itself)")
    for layer, used in ALLOWED_LAYERS.items():
        print("  %-18s %s" % (layer, ", ".join(used) or "-"))
    print("External header families per layer")
    for layer, fams in ALLOWED_FAMILIES.items():
        print("  %-18s %s" % (layer, ", ".join(fams)))
    print("solver/ must not include: " + " ".join("<%s>" % h for h in
                                                  sorted(SOLVER_FORBIDDEN_STD)))


def main(argv):
    if len(argv) > 1 and argv[1] == "--rules":
        print_rules()
        return 0
    if len(argv) > 2 or (len(argv) == 2 and argv[1].startswith("-")):
        print(__doc__.strip().split("\n\n")[1], file=sys.stderr)
        return 2
    root = argv[1] if len(argv) == 2 else os.path.join(os.path.dirname(
        os.path.abspath(__file__)), "..")
    if not os.path.isdir(root):
        print("check_layers: no such source dir '%s'" % root, file=sys.stderr)
        return 2
    violations = Checker(root).run()
    for path, line, message in sorted(set(violations)):
        print("%s:%d: %s" % (path, line, message))
    if violations:
        print("check_layers: %d layering violation(s) in %s" % (len(set(violations)),
                                                                 os.path.realpath(root)),
              file=sys.stderr)
        return 1
    print("check_layers: OK (includes of every source file, folder cycles, CMake link graph)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
