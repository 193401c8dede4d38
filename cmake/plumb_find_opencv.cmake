# OpenCV for the product: core and imgproc only (docs/EMBEDDED.md). Sets OpenCV_FOUND,
# OpenCV_INCLUDE_DIRS, OpenCV_LIBS and the targets opencv_core and opencv_imgproc.
#
# Why not just find_package(OpenCV): Debian ships OpenCVConfig.cmake only in libopencv-dev, which
# depends on every OpenCV module's -dev package (VTK, GDAL, Qt, ...: most of a 15-minute first
# install). The product needs libopencv-core-dev and libopencv-imgproc-dev, which carry the headers
# and the libraries but no CMake package; with only those installed, this finds the two libraries
# directly. Tests and benchmarks that use more modules find_package(OpenCV) themselves (they
# need libopencv-dev, installed by `scripts/install_deps.sh --tests`).
find_package(OpenCV QUIET COMPONENTS core imgproc)
if(NOT OpenCV_FOUND)
  find_path(PLUMB_OPENCV_INCLUDE_DIR opencv2/core.hpp PATH_SUFFIXES opencv4)
  # cvconfig.h sits in an architecture folder on Debian (multiarch).
  find_path(PLUMB_OPENCV_ARCH_INCLUDE_DIR opencv2/cvconfig.h
    PATH_SUFFIXES opencv4 ${CMAKE_LIBRARY_ARCHITECTURE}/opencv4)
  find_library(PLUMB_OPENCV_CORE_LIBRARY opencv_core)
  find_library(PLUMB_OPENCV_IMGPROC_LIBRARY opencv_imgproc)
  include(FindPackageHandleStandardArgs)
  find_package_handle_standard_args(PlumbOpenCV
    REQUIRED_VARS PLUMB_OPENCV_INCLUDE_DIR PLUMB_OPENCV_CORE_LIBRARY PLUMB_OPENCV_IMGPROC_LIBRARY)
  if(NOT PlumbOpenCV_FOUND)
    message(FATAL_ERROR "OpenCV core and imgproc not found (Debian: apt-get install "
      "libopencv-core-dev libopencv-imgproc-dev, or run scripts/install_deps.sh)")
  endif()
  set(OpenCV_INCLUDE_DIRS ${PLUMB_OPENCV_INCLUDE_DIR})
  if(PLUMB_OPENCV_ARCH_INCLUDE_DIR)
    list(APPEND OpenCV_INCLUDE_DIRS ${PLUMB_OPENCV_ARCH_INCLUDE_DIR})
    list(REMOVE_DUPLICATES OpenCV_INCLUDE_DIRS)
  endif()
  foreach(module core imgproc)
    string(TOUPPER ${module} upper)
    if(NOT TARGET opencv_${module})
      add_library(opencv_${module} UNKNOWN IMPORTED)
      set_target_properties(opencv_${module} PROPERTIES
        IMPORTED_LOCATION "${PLUMB_OPENCV_${upper}_LIBRARY}"
        INTERFACE_INCLUDE_DIRECTORIES "${OpenCV_INCLUDE_DIRS}")
    endif()
  endforeach()
  set_property(TARGET opencv_imgproc APPEND PROPERTY INTERFACE_LINK_LIBRARIES opencv_core)
  set(OpenCV_LIBS opencv_core opencv_imgproc)
  set(OpenCV_FOUND TRUE)
endif()
