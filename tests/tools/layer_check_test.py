#!/usr/bin/env python3
"""Self-test of scripts/check_layers.py (ctest `layering_selftest`).

Builds a small fake source tree that obeys every layer rule (it must pass), then, one case at a
time, adds a single forbidden include, link or layout and expects the checker to exit 1 with the
right message naming the right file. The checker runs as a separate process, as ctest runs it.

Usage: python3 tests/tools/layer_check_test.py [-v]
"""

import os
import shutil
import subprocess
import sys
import tempfile
import textwrap
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
CHECKER = os.path.normpath(os.path.join(HERE, "..", "..", "scripts", "check_layers.py"))

# A tree that follows the rules: each layer uses only what it may, with the include spellings
# the checker must accept (root-relative, same folder, relative inside a layer, <project/...>),
# and CMake files using a function with ARGN, globs, if()/return() like the real ones.
CLEAN_TREE = {
    "CMakeLists.txt": """
        cmake_minimum_required(VERSION 3.22)
        project(fake CXX)
        add_subdirectory(platform)
    """,
    "platform/status.h": "#include <cstdint>\n#include <pthread.h>\n#include <sys/mman.h>\n",
    "platform/status.cpp": '#include "status.h"\n#include <cstdio>\n',
    "platform/CMakeLists.txt": """
        file(GLOB PLATFORM_SOURCES CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*.cpp)
        add_library(plumb_platform STATIC ${PLATFORM_SOURCES})
        target_include_directories(plumb_platform PUBLIC ${CMAKE_SOURCE_DIR})
        target_link_libraries(plumb_platform PUBLIC Threads::Threads)
    """,
    "runtime/ring.h": '#include "platform/status.h"\n#include <atomic>\n#include <thread>\n',
    "runtime/ring.cpp": '#include "runtime/ring.h"\n#include <fstream>\n',
    "runtime/CMakeLists.txt": """
        add_library(plumb_runtime STATIC ring.cpp)
        target_link_libraries(plumb_runtime PUBLIC plumb_platform)
    """,
    "solver/se3.h": "#include <Eigen/Core>\n#include <cmath>\n#include <vector>\n",
    "solver/se3.cpp": textwrap.dedent("""\
        #include "solver/se3.h"
        // #include <thread>   (a comment is not a dependency)
        /* #include <fstream> */
        #include <sstream>
        #include <algorithm>
        const char* kNote = "#include <mutex>";
    """),
    "solver/CMakeLists.txt": """
        add_library(plumb_solver STATIC se3.cpp)
        target_link_libraries(plumb_solver PUBLIC Eigen3::Eigen)
        target_compile_options(plumb_solver PRIVATE $<$<CONFIG:Release>:-O3>)
    """,
    "sensor/camera.h": '#include <Eigen/Core>\n#include <opencv2/core.hpp>\n#include "platform/status.h"\n',
    "sensor/CMakeLists.txt": """
        add_library(plumb_sensor INTERFACE)
        target_link_libraries(plumb_sensor INTERFACE Eigen3::Eigen opencv_core)
    """,
    "pipeline/frontend/extractor.h": '#include "sensor/camera.h"\n#include "solver/se3.h"\n#include <opencv2/imgproc.hpp>\n',
    "pipeline/frontend/extractor.cpp": '#include "extractor.h"\n#include "runtime/ring.h"\n',
    "pipeline/odometry/tracker.h": '#include "../frontend/extractor.h"\n#include <atomic>\n',
    "pipeline/odometry/tracker.cpp": '#include <pipeline/odometry/tracker.h>\n',
    "pipeline/loop/closer.h": '#include "pipeline/odometry/tracker.h"\n',
    "pipeline/run/runner.h": '#include "pipeline/loop/closer.h"\n#include "pipeline/frontend/extractor.h"\n',
    "pipeline/run/runner.cpp": '#include "runner.h"\n',
    "pipeline/CMakeLists.txt": """
        file(GLOB PIPELINE_SOURCES CONFIGURE_DEPENDS
          ${CMAKE_CURRENT_SOURCE_DIR}/frontend/*.cpp ${CMAKE_CURRENT_SOURCE_DIR}/odometry/*.cpp
          ${CMAKE_CURRENT_SOURCE_DIR}/run/*.cpp ${CMAKE_CURRENT_SOURCE_DIR}/loop/*.cpp)
        add_library(plumb_pipeline STATIC ${PIPELINE_SOURCES})
        target_link_libraries(plumb_pipeline PUBLIC plumb_sensor plumb_solver plumb_runtime ${OpenCV_LIBS})
        target_include_directories(plumb_pipeline SYSTEM PUBLIC ${OpenCV_INCLUDE_DIRS})
    """,
    "drivers/common/frame_source.h": '#include "sensor/camera.h"\n#include "runtime/ring.h"\n',
    "drivers/dataset/tum.h": '#include "../common/frame_source.h"\n#include <png.h>\n#include <fcntl.h>\n',
    "drivers/dataset/tum.cpp": '#include "drivers/dataset/tum.h"\n#include <opencv2/imgcodecs.hpp>\n',
    "drivers/CMakeLists.txt": """
        file(GLOB DRIVER_SOURCES CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*/*.cpp)
        add_library(plumb_drivers STATIC ${DRIVER_SOURCES})
        target_link_libraries(plumb_drivers PUBLIC plumb_sensor plumb_runtime ${OpenCV_LIBS})
        target_link_libraries(plumb_drivers PRIVATE PNG::PNG)
        if(LIBUSB_FOUND)
          target_link_libraries(plumb_drivers PUBLIC PkgConfig::LIBUSB)
        endif()
    """,
    "tools/args.h": '#include <string>\n',
    "tools/main.cpp": '#include "args.h"\n#include "drivers/dataset/tum.h"\n#include "pipeline/run/runner.h"\n',
    "tools/CMakeLists.txt": """
        add_executable(plumb main.cpp)
        target_link_libraries(plumb PRIVATE plumb_drivers plumb_pipeline)
    """,
    "tests/support/cli.h": '#include "platform/status.h"\n',
    "tests/pipeline/tracker_test.cpp": '#include <gtest/gtest.h>\n#include "tests/support/cli.h"\n#include "pipeline/odometry/tracker.h"\n#include "drivers/dataset/tum.h"\n',
    "tests/solver/window.h": '#include "solver/se3.h"\n',
    "tests/solver/se3_test.cpp": '#include "window.h"\n#include <gtest/gtest.h>\n',
    "tests/CMakeLists.txt": """
        add_test(NAME layering COMMAND python3 ${CMAKE_SOURCE_DIR}/scripts/check_layers.py)
        function(plumb_area_tests area)
          file(GLOB sources CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/${area}/*.cpp)
          if(NOT sources)
            return()
          endif()
          add_executable(plumb_test_${area} ${sources})
          target_link_libraries(plumb_test_${area} PRIVATE ${ARGN} GTest::gtest GTest::gtest_main)
        endfunction()
        plumb_area_tests(pipeline plumb_drivers plumb_pipeline)
        plumb_area_tests(solver plumb_solver)
    """,
    "bench/solver/bench.cpp": '#include "solver/se3.h"\n#include <ceres/ceres.h>\n#include "tests/support/cli.h"\n',
    "bench/solver/CMakeLists.txt": """
        find_package(Ceres QUIET)
        if(NOT Ceres_FOUND)
          return()
        endif()
        add_executable(plumb_bench_solver bench.cpp)
        target_link_libraries(plumb_bench_solver PRIVATE plumb_solver Ceres::ceres)
    """,
    "fuzz/reader_fuzzer.cpp": '#include "drivers/dataset/tum.h"\n#include <unistd.h>\n',
    "fuzz/CMakeLists.txt": """
        set(PLUMB_ROOT ${CMAKE_CURRENT_SOURCE_DIR}/..)
        add_executable(fuzz_reader reader_fuzzer.cpp ${PLUMB_ROOT}/drivers/dataset/tum.cpp)
        target_include_directories(fuzz_reader PRIVATE ${PLUMB_ROOT} ${OpenCV_INCLUDE_DIRS})
        target_link_libraries(fuzz_reader PRIVATE Eigen3::Eigen ${OpenCV_LIBS})
    """,
    "api/plumb/odometry.h": "#include <Eigen/Core>\n",
    "api/odometry.cpp": '#include "api/plumb/odometry.h"\n#include "drivers/dataset/tum.h"\n',
    "api/python/module.cpp": '#include "api/plumb/odometry.h"\n#include <pybind11/pybind11.h>\n',
    "api/CMakeLists.txt": """
        add_library(plumb_api STATIC odometry.cpp)
        target_link_libraries(plumb_api PUBLIC plumb_drivers plumb_pipeline)
        pybind11_add_module(plumb_python MODULE python/module.cpp)
        target_link_libraries(plumb_python PRIVATE plumb_api)
    """,
    "examples/embed/main.cpp": "#include <plumb/odometry.h>\n#include <cstdio>\n",
    "examples/embed/CMakeLists.txt": """
        find_package(plumb REQUIRED)
        add_executable(embed main.cpp)
        target_link_libraries(embed PRIVATE plumb::plumb)
    """,
    "docs/ARCHITECTURE.md": "# not code\n",
}


def write_tree(root, files):
    for rel, text in files.items():
        path = os.path.join(root, rel)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "w") as f:
            f.write(textwrap.dedent(text).lstrip("\n"))


def run_checker(root):
    proc = subprocess.run([sys.executable, CHECKER, root], stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, universal_newlines=True)
    return proc.returncode, proc.stdout.strip().splitlines(), proc.stderr


class LayerCheckTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="layer_check_test_")
        self.root = os.path.join(self.tmp, "tree")
        write_tree(self.root, CLEAN_TREE)

    def tearDown(self):
        shutil.rmtree(self.tmp)

    def append(self, rel, text):
        path = os.path.join(self.root, rel)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "a") as f:
            f.write(textwrap.dedent(text).lstrip("\n"))

    def expect_only(self, path_prefix, *fragments):
        """Exactly one violation, reported at path_prefix, whose message has every fragment."""
        code, lines, stderr = run_checker(self.root)
        self.assertEqual(code, 1, "checker passed a forbidden tree; output: %s" % lines)
        self.assertIn("layering violation", stderr)
        self.assertEqual(len(lines), 1, "expected one violation, got:\n" + "\n".join(lines))
        self.assertTrue(lines[0].startswith(path_prefix), lines[0])
        for fragment in fragments:
            self.assertIn(fragment, lines[0])
        return lines[0]

    # ---- the clean tree
    def test_clean_tree_passes(self):
        code, lines, stderr = run_checker(self.root)
        self.assertEqual((code, lines), (0, ["check_layers: OK (includes of every source file, "
                                             "folder cycles, CMake link graph)"]), stderr)

    # ---- includes across layers
    def test_relative_include_up_a_layer(self):
        self.append("drivers/dataset/tum.cpp", '#include "../../pipeline/frontend/extractor.h"\n')
        self.expect_only("drivers/dataset/tum.cpp:3:", "pipeline/frontend/extractor.h",
                         "drivers/ must not include pipeline/frontend/")

    def test_drivers_include_pipeline(self):
        self.append("drivers/common/frame_source.h", '#include "pipeline/odometry/tracker.h"\n')
        self.expect_only("drivers/common/frame_source.h:3:",
                         "drivers/ must not include pipeline/odometry/")

    def test_project_header_with_angle_brackets(self):
        self.append("runtime/ring.cpp", "#include <drivers/common/frame_source.h>\n")
        self.expect_only("runtime/ring.cpp:3:", "runtime/ must not include drivers/")

    def test_tools_header_from_pipeline(self):
        self.append("pipeline/odometry/tracker.cpp", '#include "tools/args.h"\n')
        self.expect_only("pipeline/odometry/tracker.cpp:2:",
                         "pipeline/odometry/ must not include tools/")

    def test_product_includes_api(self):
        self.append("drivers/dataset/tum.cpp", '#include "api/plumb/odometry.h"\n')
        self.expect_only("drivers/dataset/tum.cpp:3:", "drivers/ must not include api/")

    def test_example_includes_the_tree(self):
        self.append("examples/embed/main.cpp", '#include "solver/se3.h"\n')
        self.expect_only("examples/embed/main.cpp:3:", "examples/ must not include solver/")

    def test_example_links_a_tree_library(self):
        self.append("examples/embed/CMakeLists.txt", "target_link_libraries(embed PRIVATE plumb_solver)\n")
        self.expect_only("examples/embed/CMakeLists.txt:", "must not link solver/")

    def test_tests_header_from_product(self):
        self.append("drivers/dataset/tum.h", '#include "tests/support/cli.h"\n')
        self.expect_only("drivers/dataset/tum.h:4:", "drivers/ must not include tests/support/")

    def test_test_area_uses_another_test_area(self):
        self.append("tests/pipeline/tracker_test.cpp", '#include "tests/solver/window.h"\n')
        self.expect_only("tests/pipeline/tracker_test.cpp:5:",
                         "tests/pipeline/ must not include tests/solver/")

    def test_front_end_uses_back_end(self):
        self.append("pipeline/frontend/extractor.cpp", '#include "pipeline/loop/closer.h"\n')
        code, lines, _ = run_checker(self.root)
        self.assertEqual(code, 1)
        self.assertIn("pipeline/frontend/extractor.cpp:3: #include \"pipeline/loop/closer.h\" -> "
                      "pipeline/loop/closer.h: pipeline/frontend/ must not include "
                      "pipeline/loop/", lines)

    # ---- quoted includes that are not files of the tree
    def test_folderless_quoted_system_header(self):
        self.append("solver/se3.cpp", '#include "thread"\n')
        self.expect_only("solver/se3.cpp:7:", '"thread" is not a file of the tree')

    def test_folderless_quoted_header_of_another_folder(self):
        # "status.h" exists in platform/, not next to the runtime file: the compiler would take
        # whatever status.h the include path offers.
        self.append("runtime/ring.cpp", '#include "status.h"\n')
        self.expect_only("runtime/ring.cpp:3:", '"status.h" is not a file of the tree')

    def test_quoted_opencv_header(self):
        self.append("runtime/ring.h", '#include "opencv2/core.hpp"\n')
        self.expect_only("runtime/ring.h:4:", "not a file of the tree")

    def test_include_leaving_the_tree(self):
        with open(os.path.join(self.tmp, "outside.h"), "w") as f:
            f.write("\n")
        self.append("platform/status.cpp", '#include "../../outside.h"\n')
        self.expect_only("platform/status.cpp:3:", "leaves the source tree")

    # ---- system headers per layer
    def test_thread_in_solver(self):
        self.append("solver/se3.h", "#include <thread>\n")
        self.expect_only("solver/se3.h:4:", "<thread>", "solver/ must not use threads/files")

    def test_files_and_locks_in_solver(self):
        for n, header in enumerate(["fstream", "mutex", "cstdio", "condition_variable",
                                    "iostream", "filesystem", "atomic", "future"]):
            with self.subTest(header=header):
                write_tree(self.root, {"solver/extra.cpp": "#include <%s>\n" % header})
                self.expect_only("solver/extra.cpp:1:", "<%s>" % header,
                                 "solver/ must not use threads/files")

    def test_posix_in_solver(self):
        self.append("solver/se3.cpp", "#include <unistd.h>\n")
        self.expect_only("solver/se3.cpp:7:", "solver/ must not use posix")

    def test_opencv_in_runtime(self):
        self.append("runtime/ring.h", "#include <opencv2/core.hpp>\n")
        self.expect_only("runtime/ring.h:4:", "runtime/ must not use opencv_core")

    def test_opencv_in_solver(self):
        self.append("solver/se3.h", "#include <opencv2/core/mat.hpp>\n")
        self.expect_only("solver/se3.h:4:", "solver/ must not use opencv_core")

    def test_eigen_in_platform(self):
        self.append("platform/status.h", "#include <Eigen/Core>\n")
        self.expect_only("platform/status.h:4:", "platform/ must not use eigen")

    def test_opencv_beyond_core_in_sensor(self):
        self.append("sensor/camera.h", "#include <opencv2/imgproc.hpp>\n")
        self.expect_only("sensor/camera.h:4:", "sensor/ must not use opencv")

    def test_unknown_external_header(self):
        self.append("pipeline/run/runner.cpp", "#include <boost/optional.hpp>\n")
        self.expect_only("pipeline/run/runner.cpp:2:", "unknown external header")

    def test_spellings_that_hide_an_include(self):
        cases = {
            "continued": "#include \\\n  <thread>\n",
            "spaced": "  #   include   <thread>\n",
            "has_include": "#if __has_include(<thread>)\n#endif\n",
        }
        for name, text in cases.items():
            with self.subTest(spelling=name):
                write_tree(self.root, {"solver/extra.cpp": text})
                self.expect_only("solver/extra.cpp:1:", "<thread>")

    def test_included_file_with_another_extension(self):
        write_tree(self.root, {"solver/kernels.inc": "#include <mutex>\n"})
        self.append("solver/se3.cpp", '#include "kernels.inc"\n')
        self.expect_only("solver/kernels.inc:1:", "<mutex>", "solver/ must not use threads/files")

    def test_computed_include(self):
        self.append("runtime/ring.cpp", "#define HEADER <thread>\n#include HEADER\n")
        self.expect_only("runtime/ring.cpp:4:", "computed include")

    def test_source_in_no_layer(self):
        self.append("misc/helper.cpp", "int x;\n")
        self.expect_only("misc/helper.cpp:0:", "no layer folder")

    def test_source_directly_in_pipeline(self):
        self.append("pipeline/flat.cpp", '#include "pipeline/run/runner.h"\n')
        self.expect_only("pipeline/flat.cpp:0:", "no layer folder")

    # ---- folder cycles
    def test_folder_cycle_inside_drivers(self):
        write_tree(self.root, {
            "drivers/common/open_source.cpp": '#include "drivers/dataset/tum.h"\n'})
        line = self.expect_only("drivers/common:0:", "folder cycle",
                                "drivers/common -> drivers/dataset -> drivers/common",
                                "drivers/common/open_source.cpp:1",
                                "drivers/dataset/tum.h:1")
        self.assertNotIn("drivers/dataset/tum.cpp", line.split("through:")[0])

    # ---- CMake link graph
    def test_drivers_link_pipeline(self):
        self.append("drivers/CMakeLists.txt", "target_link_libraries(plumb_drivers PUBLIC plumb_pipeline)\n")
        self.expect_only("drivers/CMakeLists.txt:8:", "plumb_drivers (drivers/) links "
                         "plumb_pipeline (pipeline/)", "drivers/ must not link pipeline/")

    def test_link_inside_an_if_branch(self):
        self.append("runtime/CMakeLists.txt", """
            if(SOMETHING)
              target_link_libraries(plumb_runtime PRIVATE plumb_solver)
            endif()
        """)
        self.expect_only("runtime/CMakeLists.txt:4:", "runtime/ must not link solver/")

    def test_link_through_a_cmake_function(self):
        write_tree(self.root, {"solver/CMakeLists.txt": """
            function(solver_library name)
              add_library(${name} STATIC se3.cpp)
              target_link_libraries(${name} PUBLIC Eigen3::Eigen ${ARGN})
            endfunction()
            solver_library(plumb_solver plumb_runtime)
        """})
        self.expect_only("solver/CMakeLists.txt:5:", "plumb_solver (solver/) links "
                         "plumb_runtime (runtime/)")

    def test_opencv_linked_into_runtime(self):
        self.append("runtime/CMakeLists.txt", "target_link_libraries(plumb_runtime PUBLIC ${OpenCV_LIBS})\n")
        self.expect_only("runtime/CMakeLists.txt:3:", "runtime/ must not use opencv")

    def test_tools_source_compiled_into_a_test(self):
        self.append("tests/CMakeLists.txt", "target_sources(plumb_test_pipeline PRIVATE ${CMAKE_SOURCE_DIR}/tools/main.cpp)\n")
        self.expect_only("tests/CMakeLists.txt:12:", "plumb_test_pipeline (tests/pipeline/) "
                         "compiles tools/main.cpp")

    def test_object_library_of_pipeline_in_drivers(self):
        self.append("drivers/CMakeLists.txt", "target_sources(plumb_drivers PRIVATE $<TARGET_OBJECTS:plumb_pipeline>)\n")
        self.expect_only("drivers/CMakeLists.txt:8:", "drivers/ must not link pipeline/")

    def test_source_list_the_check_cannot_see(self):
        self.append("drivers/CMakeLists.txt", "target_sources(plumb_drivers PRIVATE ${FROM_ELSEWHERE})\n")
        self.expect_only("drivers/CMakeLists.txt:8:", "${FROM_ELSEWHERE}", "cannot see")

    def test_product_includes_the_viewer(self):
        # viewer/ sits on pipeline/run and drivers; the run must never depend on a viewer.
        self.append("viewer/live_view.h", '#include "pipeline/run/runner.h"\n')
        self.append("pipeline/run/runner.cpp", '#include "viewer/live_view.h"\n')
        self.expect_only("pipeline/run/runner.cpp:", "pipeline/run/ must not include viewer/")

    def test_viewer_headers_outside_the_viewer(self):
        self.append("drivers/dataset/tum.cpp", "#include <websocketpp/server.hpp>\n")
        self.expect_only("drivers/dataset/tum.cpp:3:", "websocketpp")

    def test_generated_source_belongs_to_its_folder(self):
        # The viewer's embedded page is generated into the build tree: it counts as a file of the
        # folder whose CMakeLists.txt makes it (drivers/ here), which may compile it.
        self.append("drivers/CMakeLists.txt",
                    "target_sources(plumb_drivers PRIVATE ${CMAKE_CURRENT_BINARY_DIR}/page.cpp)\n")
        code, lines, stderr = run_checker(self.root)
        self.assertEqual(code, 0, "\n".join(lines) + stderr)

    def test_symbolic_link_into_another_layer(self):
        os.symlink(os.path.join(self.root, "drivers"),
                   os.path.join(self.root, "pipeline", "frontend", "devices"))
        self.append("pipeline/frontend/extractor.cpp",
                    '#include "pipeline/frontend/devices/common/frame_source.h"\n')
        self.expect_only("pipeline/frontend/extractor.cpp:3:", "drivers/common/frame_source.h",
                         "pipeline/frontend/ must not include drivers/")

    def test_include_directory_other_than_root(self):
        self.append("pipeline/CMakeLists.txt", "target_include_directories(plumb_pipeline PUBLIC ${CMAKE_SOURCE_DIR}/tools)\n")
        self.expect_only("pipeline/CMakeLists.txt:7:", "adds include directory tools")

    def test_unknown_link_item(self):
        self.append("solver/CMakeLists.txt", "target_link_libraries(plumb_solver PUBLIC boost_system)\n")
        self.expect_only("solver/CMakeLists.txt:4:", "boost_system: unknown library")

    # ---- the real tree's rule table itself
    def test_rule_table_is_closed_under_use(self):
        # If A may use B and B may use C, A must be allowed C too: otherwise a rule could be
        # dodged through an intermediate header that the check accepts.
        sys.path.insert(0, os.path.dirname(CHECKER))
        import check_layers
        for user, used_list in check_layers.ALLOWED_LAYERS.items():
            for used in used_list:
                for further in check_layers.ALLOWED_LAYERS.get(check_layers.rule_key(used), []):
                    self.assertIn(further, used_list + [user],
                                  "%s may use %s which may use %s" % (user, used, further))


if __name__ == "__main__":
    unittest.main()
