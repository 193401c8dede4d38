#include "pipeline/frontend/descriptor_match.h"

#include <cstdint>

#include "pipeline/frontend/descriptor_match_avx2.h"

// x86-64 without -mpopcnt (the portable baseline): the scans are built twice, the portable copy on
// hammingDistance's SSE2 bit-slicing and a POPCNT copy picked at run time (every x86-64 CPU since
// ~2008 has it). Elsewhere (aarch64, -mpopcnt builds) __builtin_popcountll is inline already and
// the portable copy is the only one.
#if defined(__x86_64__) && !defined(__POPCNT__) && (defined(__GNUC__) || defined(__clang__))
#define PLUMB_SCAN_DISPATCH 1
#else
#define PLUMB_SCAN_DISPATCH 0
#endif

namespace plumb {
namespace {

namespace portable {
#define PLUMB_SCAN_TARGET
#if PLUMB_SCAN_DISPATCH
// SSE2 counts 128 bits at a time and sums them at the end: no cheap partial distance, so the whole
// distance is the head and the tail is empty (its test folds away).
inline int headDistance(const Descriptor256& q, const Descriptor256& o) { return hammingDistance(q, o); }
inline int tailDistance(const Descriptor256&, const Descriptor256&) { return 0; }
#else
// Word counts are single instructions (or NEON's cnt): the first two words, then the other two.
inline int headDistance(const Descriptor256& q, const Descriptor256& o) {
  return __builtin_popcountll(q.words[0] ^ o.words[0]) + __builtin_popcountll(q.words[1] ^ o.words[1]);
}
inline int tailDistance(const Descriptor256& q, const Descriptor256& o) {
  return __builtin_popcountll(q.words[2] ^ o.words[2]) + __builtin_popcountll(q.words[3] ^ o.words[3]);
}
#endif
#include "pipeline/frontend/descriptor_match_kernels.inc"
#undef PLUMB_SCAN_TARGET
}  // namespace portable

#if PLUMB_SCAN_DISPATCH
namespace popcnt {
#define PLUMB_SCAN_TARGET __attribute__((target("popcnt")))
PLUMB_SCAN_TARGET inline int headDistance(const Descriptor256& q, const Descriptor256& o) {
  return __builtin_popcountll(q.words[0] ^ o.words[0]) + __builtin_popcountll(q.words[1] ^ o.words[1]);
}
PLUMB_SCAN_TARGET inline int tailDistance(const Descriptor256& q, const Descriptor256& o) {
  return __builtin_popcountll(q.words[2] ^ o.words[2]) + __builtin_popcountll(q.words[3] ^ o.words[3]);
}
#include "pipeline/frontend/descriptor_match_kernels.inc"
#undef PLUMB_SCAN_TARGET
}  // namespace popcnt

bool cpuHasPopcnt() {
  static const bool has = __builtin_cpu_supports("popcnt");
  return has;
}
#endif

#if PLUMB_SCAN_AVX2
bool cpuHasAvx2() {
  static const bool has = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("popcnt");
  return has;
}
#endif

}  // namespace

bool descriptorScanAvailable(DescriptorScanPath path) {
  switch (path) {
    case DescriptorScanPath::kPortable:
      return true;
    case DescriptorScanPath::kPopcnt:
#if PLUMB_SCAN_DISPATCH
      return cpuHasPopcnt();
#else
      return false;
#endif
    case DescriptorScanPath::kAvx2:
#if PLUMB_SCAN_AVX2
      return cpuHasAvx2();
#else
      return false;
#endif
  }
  return false;
}

DescriptorScanPath descriptorScanPath() {
  static const DescriptorScanPath path = descriptorScanAvailable(DescriptorScanPath::kAvx2)     ? DescriptorScanPath::kAvx2
                                         : descriptorScanAvailable(DescriptorScanPath::kPopcnt) ? DescriptorScanPath::kPopcnt
                                                                                                : DescriptorScanPath::kPortable;
  return path;
}

int ratioBound(int max_distance, float ratio, int none) {
  if (max_distance < 0) return 0;  // nothing is within max_distance: no distance matters
  for (int c = max_distance + 1; c < none; ++c)
    if (float(max_distance) < ratio * float(c)) return c;
  return none;
}

NearestTwo nearestTwoBelowOn(DescriptorScanPath path, const Descriptor256& d, const Descriptor256* others,
                             std::size_t n, int bound) {
  switch (path) {
    case DescriptorScanPath::kPortable:
      break;
    case DescriptorScanPath::kPopcnt:
#if PLUMB_SCAN_DISPATCH
      return popcnt::nearestTwoBelowKernel(d, others, n, bound);
#else
      break;
#endif
    case DescriptorScanPath::kAvx2:
#if PLUMB_SCAN_AVX2
      return descriptor_scan_avx2::nearestTwoBelow(d, others, n, bound);
#else
      break;
#endif
  }
  return portable::nearestTwoBelowKernel(d, others, n, bound);
}

void nearestBothWaysOn(DescriptorScanPath path, const Descriptor256* a, std::size_t na, const Descriptor256* b,
                       std::size_t nb, int row_bound, int col_bound, NearestTwo* rows, int* col_best, int* col_index) {
  switch (path) {
    case DescriptorScanPath::kPortable:
      break;
    case DescriptorScanPath::kPopcnt:
#if PLUMB_SCAN_DISPATCH
      return popcnt::nearestBothWaysKernel(a, na, b, nb, row_bound, col_bound, rows, col_best, col_index);
#else
      break;
#endif
    case DescriptorScanPath::kAvx2:
#if PLUMB_SCAN_AVX2
      return descriptor_scan_avx2::nearestBothWays(a, na, b, nb, row_bound, col_bound, rows, col_best, col_index);
#else
      break;
#endif
  }
  portable::nearestBothWaysKernel(a, na, b, nb, row_bound, col_bound, rows, col_best, col_index);
}

NearestTwo nearestTwoBelow(const Descriptor256& d, const Descriptor256* others, std::size_t n, int bound) {
  return nearestTwoBelowOn(descriptorScanPath(), d, others, n, bound);
}

void nearestBothWays(const Descriptor256* a, std::size_t na, const Descriptor256* b, std::size_t nb, int row_bound,
                     int col_bound, NearestTwo* rows, int* col_best, int* col_index) {
  nearestBothWaysOn(descriptorScanPath(), a, na, b, nb, row_bound, col_bound, rows, col_best, col_index);
}

}  // namespace plumb
