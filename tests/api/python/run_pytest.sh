#!/usr/bin/env bash
# ctest python_module: the pytest suite of the Python module (tests/api/python), with the interpreter
# the module was built for. Exit 77 (ctest: skipped) when the module was not built (no pybind11)
# or pytest/numpy are missing.
# Usage: run_pytest.sh PYTHON MODULE_DIR PLUMB_BINARY DATASETS_DIR [pytest args]
set -u
python="$1"; module_dir="$2"; plumb="$3"; datasets="$4"; shift 4
here="$(cd "$(dirname "$0")" && pwd)"
if [ -z "$python" ] || [ ! -d "$module_dir" ] || ! ls "$module_dir"/plumb*.so >/dev/null 2>&1; then
  echo "SKIP python_module: the module was not built (needs pybind11: apt-get install python3-pybind11 pybind11-dev)"
  exit 77
fi
if ! "$python" -c "import numpy, pytest" >/dev/null 2>&1; then
  echo "SKIP python_module: $python lacks numpy or pytest (apt-get install python3-numpy python3-pytest)"
  exit 77
fi
export PLUMB_PYTHON_DIR="$module_dir" PLUMB_BINARY="$plumb" PLUMB_DATASETS_DIR="$datasets"
exec "$python" -m pytest -q -p no:cacheprovider "$here" "$@"
