#!/usr/bin/env python3
"""Doc path check: every file path the documentation names must exist in the tree.

Usage: scripts/check_doc_paths.py [SOURCE_DIR]   (default: the repository holding this script)

Reads README.md, docs/*.md and tests/README.md, finds every token that looks like a path in the tree
(`folder/name.ext` with a known source or script extension, and any name under a top-level folder
of the tree, `tests/drivers/mapfile/` or `tests/api/python`) and reports the ones that name no file
or folder. Exit 0 when all exist, 1 with one `doc:line: path` per missing file.
Registered as the ctest test `doc_paths` (label `docs`). Python 3 standard library only.

What is not checked, on purpose: paths outside the tree (`../shared/...`), build outputs
(`build/`, `build-*/`), an installed tree's layout (`include/`, `lib/`), placeholders in
capitals (`DIR/rgb.txt`), installed headers (`<plumb/odometry.h>` is `api/plumb/odometry.h` in the
tree, and is checked under that name too), URLs, and names with a wildcard (`synth_*_test.cpp`),
which must match at least one file instead. Lines between `<!-- doc_paths: off -->` and
`<!-- doc_paths: on -->` are not checked (a table of where files were moved from).
"""

import glob
import os
import re
import sys

EXTENSIONS = ("h", "hpp", "cpp", "cc", "py", "sh", "md", "cmake", "js", "json", "txt", "ts",
              "html", "css", "yml", "yaml")
# folder/…/name.ext; the folder part may hold a wildcard (`tests/drivers/synth/synth_*_test.cpp`).
PATH = re.compile(r"(?<![\w./:-])((?:\.\./)*[A-Za-z0-9_.*-]+(?:/[A-Za-z0-9_.*-]+)+\.(?:%s))(?![\w/])"
                  % "|".join(EXTENSIONS))
# Any name under a top-level folder of the tree (`tests/drivers/mapfile/`, `tests/api/python`), file or
# folder, with or without an extension.
def top_level_pattern(root):
    tops = sorted(d for d in os.listdir(root) if os.path.isdir(os.path.join(root, d))
                  and not d.startswith(".") and not d.startswith("build"))
    return re.compile(r"(?<![\w./:-])((?:%s)/[A-Za-z0-9_.*/-]*[A-Za-z0-9_*/])" % "|".join(map(re.escape, tops)))


# Roots a name may be relative to besides the repository root: installed API headers.
EXTRA_ROOTS = ["api"]
# ../shared: data beside the tree; build*: outputs; include/, lib/: an installed tree's layout.
SKIP_PREFIXES = ("../", "build/", "build-", "http", "node_modules/", "/", "include/", "lib/")
# A first component in capitals is a placeholder (`DIR/rgb.txt`, `OUT/groundtruth.txt`).
PLACEHOLDER = re.compile(r"^[A-Z][A-Z0-9_]*/")


def documents(root):
    docs = [os.path.join(root, "README.md"), os.path.join(root, "tests", "README.md")]
    docs += sorted(glob.glob(os.path.join(root, "docs", "*.md")))
    return [d for d in docs if os.path.isfile(d)]


def exists(root, path):
    for base in [root] + [os.path.join(root, r) for r in EXTRA_ROOTS]:
        full = os.path.join(base, path)
        if "*" in path:
            if glob.glob(full):
                return True
        elif os.path.exists(full.rstrip("/")):
            return True
    return False


def check(root):
    missing = []
    under_top = top_level_pattern(root)
    for doc in documents(root):
        rel_doc = os.path.relpath(doc, root)
        checking = True
        with open(doc, encoding="utf-8") as f:
            for number, line in enumerate(f, 1):
                # Names that no longer exist on purpose (where files were moved from).
                if "<!-- doc_paths: off -->" in line:
                    checking = False
                elif "<!-- doc_paths: on -->" in line:
                    checking = True
                if not checking:
                    continue
                paths = [m for m in PATH.finditer(line)] + [m for m in under_top.finditer(line)]
                for m in paths:
                    path = m.group(1)
                    if (path.startswith(SKIP_PREFIXES) or PLACEHOLDER.match(path) or
                            "://" in line[max(0, m.start() - 12):m.start()]):
                        continue
                    if not exists(root, path):
                        missing.append("%s:%d: %s" % (rel_doc, number, path))
    missing = list(dict.fromkeys(missing))
    return missing


def main(argv):
    if len(argv) > 2 or (len(argv) == 2 and argv[1].startswith("-")):
        print(__doc__.strip().split("\n\n")[1], file=sys.stderr)
        return 2
    root = argv[1] if len(argv) == 2 else os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
    missing = check(root)
    for m in missing:
        print("%s (no such file)" % m)
    if missing:
        print("check_doc_paths: %d path(s) in the docs name no file of the tree" % len(missing))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
