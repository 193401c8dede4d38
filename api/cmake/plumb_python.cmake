# Finds pybind11 for the Python module (api/python/). The module is built for, and tested with, the
# first python3 on PATH that can import numpy (Debian's /usr/bin/python3 with python3-numpy), so a
# pyenv or venv interpreter without numpy earlier on PATH does not win. -DPYTHON_EXECUTABLE=...
# overrides. Sets pybind11_FOUND and PLUMB_PYTHON_EXECUTABLE.
if(NOT DEFINED PYTHON_EXECUTABLE)
  string(REPLACE ":" ";" _plumb_path "$ENV{PATH}")
  foreach(_plumb_dir IN LISTS _plumb_path)
    if(EXISTS "${_plumb_dir}/python3")
      execute_process(COMMAND "${_plumb_dir}/python3" -c "import numpy"
        RESULT_VARIABLE _plumb_numpy OUTPUT_QUIET ERROR_QUIET)
      if(_plumb_numpy EQUAL 0)
        set(PYTHON_EXECUTABLE "${_plumb_dir}/python3" CACHE FILEPATH "Python interpreter of the module")
        break()
      endif()
    endif()
  endforeach()
endif()
if(DEFINED PYTHON_EXECUTABLE)
  find_package(pybind11 CONFIG QUIET)
endif()
set(PLUMB_PYTHON_EXECUTABLE "${PYTHON_EXECUTABLE}")
