# pytest setup for the Python module tests: the module is found in PLUMB_PYTHON_DIR (the build's
# python/ folder, set by ctest); the `plumb` CLI in PLUMB_BINARY, the data in PLUMB_DATASETS_DIR.
import os
import sys

import pytest

_dir = os.environ.get("PLUMB_PYTHON_DIR")
if _dir:
    sys.path.insert(0, _dir)


@pytest.fixture(scope="session")
def plumb_binary():
    path = os.environ.get("PLUMB_BINARY", "")
    if not path or not os.path.exists(path):
        pytest.skip("PLUMB_BINARY (the plumb command) not given")
    return path


@pytest.fixture(scope="session")
def datasets_dir():
    return os.environ.get("PLUMB_DATASETS_DIR", os.path.join(os.path.dirname(__file__), "..", "..", "..",
                                                            "shared", "datasets"))
