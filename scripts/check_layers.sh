#!/usr/bin/env bash
# Layering check: fails (exit 1) and lists file:line for every #include that crosses a layer
# boundary the architecture forbids. Registered as the ctest test `layering`.
#
#   solver/    std headers, <Eigen/...>, solver/            (pure maths, no OpenCV, no platform)
#   platform/  std, C/POSIX/Linux system headers, platform/ (libc + pthread only)
#   runtime/   std, system headers, platform/, runtime/     (no OpenCV, Eigen, pipeline, drivers)
#   pipeline/  must not include drivers/ or tools/          (algorithms never open devices/files)
#   drivers/   must not include tools/
#
# solver/, platform/ and runtime/ are checked against an allow-list, so a new third-party
# dependency fails by default; pipeline/ and drivers/ against a deny-list.
#
# Usage: scripts/check_layers.sh [SOURCE_DIR]   (default: the repository holding this script)
set -u

root="${1:-$(cd "$(dirname "$0")/.." && pwd)}"
cd "$root" || { echo "check_layers: cannot enter source dir '$root'" >&2; exit 2; }

# C++ standard library headers have no extension: <vector>, <cmath>, <type_traits>.
std_cxx='<[a-z_]+>'
# C standard and POSIX headers that live directly in the system include directory. Listed
# explicitly so that a third-party <foo.h> (libusb.h, OpenNI.h, libv4l2.h) is not mistaken for one.
c_posix_names='assert|complex|ctype|errno|fenv|float|inttypes|iso646|limits|locale|math|setjmp'
c_posix_names+='|signal|stdalign|stdarg|stdatomic|stdbool|stddef|stdint|stdio|stdlib|string'
c_posix_names+='|tgmath|threads|time|uchar|wchar|wctype|aio|dirent|dlfcn|execinfo|fcntl|fnmatch'
c_posix_names+='|glob|grp|iconv|langinfo|libgen|malloc|mqueue|netdb|poll|pthread|pwd|regex'
c_posix_names+='|sched|search|semaphore|spawn|strings|syslog|termios|unistd|utime|wordexp'
system_c="<(${c_posix_names})\\.h>"
# Kernel and libc sub-directories: <sys/mman.h>, <linux/futex.h>, <asm/...>.
system_dirs='<(sys|linux|asm|asm-generic|bits|arpa|netinet|net)/[A-Za-z0-9_/]+\.h>'

violations=0

# report FILE LINE INCLUDE REASON
report() {
  echo "$1:$2: $3  -- $4"
  violations=$((violations + 1))
}

# list_includes DIR -> "file<TAB>line<TAB>target" for every #include under DIR.
list_includes() {
  [ -d "$1" ] || return 0
  grep -rnE --include='*.h' --include='*.hpp' --include='*.cpp' --include='*.cc' \
      '^[[:space:]]*#[[:space:]]*include[[:space:]]*[<"]' "$1" |
    sed -E 's/^([^:]+):([0-9]+):[[:space:]]*#[[:space:]]*include[[:space:]]*([<"][^>"]*[>"]).*/\1\t\2\t\3/'
}

# A quoted include without a folder ("foo.h") is resolved next to the including file, so it stays
# inside that file's layer; anything else must name its layer folder explicitly.
is_same_folder_quote() {
  [[ "$1" =~ ^\"[^/]+\"$ ]]
}

# check_allow_list LAYER DESCRIPTION REGEX...: every include must match one of the regexes.
check_allow_list() {
  local layer="$1" description="$2"
  shift 2
  local file line target pattern ok
  while IFS=$'\t' read -r file line target; do
    [ -n "$file" ] || continue
    ok=0
    if is_same_folder_quote "$target"; then
      ok=1
    else
      for pattern in "$@"; do
        if [[ "$target" =~ ^${pattern}$ ]]; then ok=1; break; fi
      done
    fi
    [ "$ok" = 1 ] || report "$file" "$line" "$target" "$layer/ may include only $description"
  done < <(list_includes "$layer")
}

# check_deny_list LAYER REGEX DESCRIPTION: no include may match REGEX.
check_deny_list() {
  local layer="$1" pattern="$2" description="$3"
  local file line target
  while IFS=$'\t' read -r file line target; do
    [ -n "$file" ] || continue
    if [[ "$target" =~ ^${pattern}$ ]]; then
      report "$file" "$line" "$target" "$layer/ must not include $description"
    fi
  done < <(list_includes "$layer")
}

check_allow_list solver "std headers, <Eigen/...> and solver/" \
  "$std_cxx" '<Eigen/[A-Za-z]+>' '"solver/[^"]+"'
check_allow_list platform "std, C/POSIX/Linux system headers and platform/" \
  "$std_cxx" "$system_c" "$system_dirs" '"platform/[^"]+"'
check_allow_list runtime "std and system headers, platform/ and runtime/" \
  "$std_cxx" "$system_c" "$system_dirs" '"platform/[^"]+"' '"runtime/[^"]+"'
check_deny_list pipeline '[<"](drivers|tools)/[^">]+[">]' "drivers/ or tools/"
check_deny_list drivers '[<"]tools/[^">]+[">]' "tools/"

if [ "$violations" -gt 0 ]; then
  echo "check_layers: $violations layering violation(s) in $root" >&2
  exit 1
fi
echo "check_layers: OK (solver, platform, runtime, pipeline, drivers)"
