#!/usr/bin/env bash
# Sourced by the build scripts: plumb_generator_args BUILD_DIR fills the array `generator_args`
# with the CMake generator for a new build folder.
#   - Ninja when it is installed (scripts/install_deps.sh installs ninja-build): it schedules every
#     target's files in one queue. The Makefile generator builds the targets named on one command
#     line one after the other (`.NOTPARALLEL` at the top level), so a test program's last file and
#     its link ran on one core while the other waited.
#   - nothing (CMake's default, Unix Makefiles) otherwise, and for a folder that is already
#     configured: CMake refuses to change the generator of an existing build folder.
plumb_generator_args() {
  generator_args=()
  if [ ! -f "$1/CMakeCache.txt" ] && command -v ninja >/dev/null 2>&1; then
    generator_args=(-G Ninja)
  fi
}
