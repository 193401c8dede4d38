#!/usr/bin/env python3
"""Doc check: the files and the code names the documentation mentions must exist in the tree.

Usage: scripts/check_doc_paths.py [SOURCE_DIR]   (default: the repository holding this script)

Reads README.md, docs/*.md and tests/README.md and reports, one `doc:line: name` each:
- paths: every token that looks like a path in the tree (`folder/name.ext` with a known source or
  script extension, and any name under a top-level folder of the tree, `tests/drivers/mapfile/`
  or `tests/api/python`) that names no file or folder;
- code names: every qualified name in backticks (`Tracker::track`, `loop::makeLoopKeyframe`,
  `StageRunner<OdometrySlot>::runLockStep`) whose parts are not all names in the sources, or whose
  last two parts (class and member, namespace and function) appear in no source file together.
  A weak test (a name can be found beside an unrelated one), but a renamed or removed function
  or class fails it.
Exit 0 when everything is found, 1 otherwise. Registered as the ctest test `doc_paths` (label
`docs`). Python 3 standard library only.

What is not checked, on purpose: paths outside the tree (`../shared/...`), build outputs
(`build/`, `build-*/`), an installed tree's layout (`include/`, `lib/`), placeholders in
capitals (`DIR/rgb.txt`), URLs, names of other libraries (`std::`, `cv::`, `Eigen::`, `ceres::`).
Installed headers (`plumb/odometry.h`) are also looked for under `api/`; a name with a wildcard
(`synth_*_test.cpp`) must match at least one file. Lines between `<!-- doc_paths: off -->` and
`<!-- doc_paths: on -->` are not checked (a table of where files were moved from).
"""

import functools
import glob
import os
import re
import sys

EXTENSIONS = ("h", "hpp", "cpp", "cc", "py", "sh", "md", "cmake", "js", "json", "txt", "ts",
              "html", "css", "yml", "yaml")
# folder/…/name.ext; the folder part may hold a wildcard (`tests/drivers/synth/synth_*_test.cpp`).
PATH = re.compile(r"(?<![\w./:-])((?:\.\./)*[A-Za-z0-9_.*-]+(?:/[A-Za-z0-9_.*-]+)+\.(?:%s))(?![\w/])"
                  % "|".join(EXTENSIONS))
# Roots a name may be relative to besides the repository root: installed API headers.
EXTRA_ROOTS = ["api"]
# ../shared: data beside the tree; build*: outputs; include/, lib/: an installed tree's layout.
SKIP_PREFIXES = ("../", "build/", "build-", "http", "node_modules/", "/", "include/", "lib/")
# A first component in capitals is a placeholder (`DIR/rgb.txt`, `OUT/groundtruth.txt`).
PLACEHOLDER = re.compile(r"^[A-Z][A-Z0-9_]*/")

# A qualified C++ name: parts joined by ::, template arguments allowed (`StageRunner<T>::run`).
QUALIFIED = re.compile(r"((?:[A-Za-z_]\w*(?:<[^<>`]*>)?::)+~?[A-Za-z_]\w*)")
OTHER_LIBRARIES = {"std", "cv", "Eigen", "ceres", "testing", "pybind11", "py"}
SOURCE_FOLDERS = ["platform", "runtime", "solver", "sensor", "pipeline", "drivers", "tools", "api",
                  "viewer", "bench", "fuzz", "tests", "examples"]
SOURCE_EXTENSIONS = (".h", ".hpp", ".cpp", ".cc")


def documents(root):
    docs = [os.path.join(root, "README.md"), os.path.join(root, "tests", "README.md")]
    docs += sorted(glob.glob(os.path.join(root, "docs", "*.md")))
    return [d for d in docs if os.path.isfile(d)]


def checked_lines(doc):
    """(line number, text) of the lines the check reads."""
    checking = True
    with open(doc, encoding="utf-8") as f:
        for number, line in enumerate(f, 1):
            if "<!-- doc_paths: off -->" in line:
                checking = False
            elif "<!-- doc_paths: on -->" in line:
                checking = True
            elif checking:
                yield number, line


# ---- paths

@functools.lru_cache(maxsize=None)
def top_level_pattern(root):
    """Any name under a top-level folder of the tree, file or folder, extension or not."""
    tops = sorted(d for d in os.listdir(root) if os.path.isdir(os.path.join(root, d))
                  and not d.startswith(".") and not d.startswith("build"))
    return re.compile(r"(?<![\w./:-])((?:%s)/[A-Za-z0-9_.*/-]*[A-Za-z0-9_*/])"
                      % "|".join(map(re.escape, tops)))


def path_exists(root, path):
    for base in [root] + [os.path.join(root, r) for r in EXTRA_ROOTS]:
        full = os.path.join(base, path)
        if "*" in path:
            if glob.glob(full):
                return True
        elif os.path.exists(full.rstrip("/")):
            return True
    return False


def missing_paths(root, line):
    under_top = top_level_pattern(root)
    for m in list(PATH.finditer(line)) + list(under_top.finditer(line)):
        path = m.group(1)
        if path.startswith(SKIP_PREFIXES) or PLACEHOLDER.match(path):
            continue
        if "://" in line[max(0, m.start() - 12):m.start()]:
            continue
        if not path_exists(root, path):
            yield path


# ---- code names

def source_words(root):
    """word -> the set of source files it appears in."""
    words = {}
    for folder in SOURCE_FOLDERS:
        for path in glob.glob(os.path.join(root, folder, "**", "*"), recursive=True):
            if not path.endswith(SOURCE_EXTENSIONS) or "node_modules" in path or not os.path.isfile(path):
                continue
            with open(path, encoding="utf-8", errors="replace") as f:
                for word in set(re.findall(r"[A-Za-z_]\w*", f.read())):
                    words.setdefault(word, set()).add(path)
    return words


def missing_names(words, line):
    for code in re.findall(r"`([^`]+)`", line):
        for name in QUALIFIED.findall(code):
            parts = [re.sub(r"<.*>", "", p).lstrip("~") for p in name.split("::")]
            if parts[0] == "plumb":
                parts = parts[1:]
            if not parts or parts[0] in OTHER_LIBRARIES:
                continue
            if any(p not in words for p in parts):
                yield name
            elif len(parts) >= 2 and not words[parts[-2]] & words[parts[-1]]:
                yield name


def check(root):
    problems = []
    words = source_words(root)
    for doc in documents(root):
        rel_doc = os.path.relpath(doc, root)
        for number, line in checked_lines(doc):
            for path in missing_paths(root, line):
                problems.append("%s:%d: %s (no such file)" % (rel_doc, number, path))
            for name in missing_names(words, line):
                problems.append("%s:%d: %s (no such name in the sources)" % (rel_doc, number, name))
    return list(dict.fromkeys(problems))


def main(argv):
    if len(argv) > 2 or (len(argv) == 2 and argv[1].startswith("-")):
        print(__doc__.strip().split("\n\n")[1], file=sys.stderr)
        return 2
    root = argv[1] if len(argv) == 2 else os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
    problems = check(root)
    for p in problems:
        print(p)
    if problems:
        print("check_doc_paths: %d name(s) in the docs are not in the tree" % len(problems))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
