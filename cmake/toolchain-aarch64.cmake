# Cross-compiling plumb for aarch64 Linux (Raspberry Pi 5, Jetson Orin, RK3588) with Debian's
# aarch64-linux-gnu-gcc, against an arm64 sysroot that scripts/cross_aarch64.sh fills from Debian's
# arm64 packages. Tests and tools run on the x86-64 host through qemu user-mode emulation: ctest
# prefixes every test whose command is a built target with CMAKE_CROSSCOMPILING_EMULATOR (binfmt_misc
# is not mounted on the project's machines, so nothing can rely on the kernel starting ARM binaries).
#   cmake -S . -B build-aarch64 -DCMAKE_TOOLCHAIN_FILE=cmake/toolchain-aarch64.cmake \
#         [-DPLUMB_ARM64_SYSROOT=/opt/plumb/sysroot-arm64]
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)

# The sysroot: a -D value, else the environment, else the script's default. try_compile projects
# re-read this file, so the value is forwarded to them too.
if(NOT PLUMB_ARM64_SYSROOT)
  if(DEFINED ENV{PLUMB_ARM64_SYSROOT})
    set(PLUMB_ARM64_SYSROOT "$ENV{PLUMB_ARM64_SYSROOT}")
  else()
    set(PLUMB_ARM64_SYSROOT "/opt/plumb/sysroot-arm64")
  endif()
endif()
set(PLUMB_ARM64_SYSROOT "${PLUMB_ARM64_SYSROOT}" CACHE PATH "arm64 sysroot (scripts/cross_aarch64.sh)")
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES PLUMB_ARM64_SYSROOT)

set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)
set(CMAKE_LIBRARY_ARCHITECTURE aarch64-linux-gnu)
set(CMAKE_SYSROOT "${PLUMB_ARM64_SYSROOT}")

# Headers, libraries and CMake package files only from the sysroot; programs (pkg-config, bash)
# from the host.
set(CMAKE_FIND_ROOT_PATH "${PLUMB_ARM64_SYSROOT}")
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)

# pkg-config (drivers' optional back ends) must see the arm64 .pc files only, never the host's.
set(ENV{PKG_CONFIG_DIR} "")
set(ENV{PKG_CONFIG_LIBDIR}
  "${PLUMB_ARM64_SYSROOT}/usr/lib/aarch64-linux-gnu/pkgconfig:${PLUMB_ARM64_SYSROOT}/usr/share/pkgconfig")
set(ENV{PKG_CONFIG_SYSROOT_DIR} "${PLUMB_ARM64_SYSROOT}")

# -L: qemu looks up the ELF interpreter and every absolute path the program opens (shared libraries
# first) in the sysroot before the host's root.
set(CMAKE_CROSSCOMPILING_EMULATOR "qemu-aarch64-static;-L;${PLUMB_ARM64_SYSROOT}")
