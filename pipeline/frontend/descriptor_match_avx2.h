#pragma once
// The AVX2 build of the scans of descriptor_match.h (descriptor_match_avx2.cpp), for
// descriptor_match.cpp's run-time choice only: call them where the CPU has AVX2 and POPCNT.
#include <cstddef>

#include "pipeline/frontend/descriptor_match.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define PLUMB_SCAN_AVX2 1
#else
#define PLUMB_SCAN_AVX2 0
#endif

#if PLUMB_SCAN_AVX2
namespace plumb::descriptor_scan_avx2 {
NearestTwo nearestTwoBelow(const Descriptor256& d, const Descriptor256* others, std::size_t n, int bound);
void nearestBothWays(const Descriptor256* a, std::size_t na, const Descriptor256* b, std::size_t nb, int row_bound,
                     int col_bound, NearestTwo* rows, int* col_best, int* col_index);
}  // namespace plumb::descriptor_scan_avx2
#endif
