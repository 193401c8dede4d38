#pragma once
// Process-wide heap allocation counter. Linking plumb_platform replaces the global operator
// new/delete with versions that bump relaxed atomic counters and otherwise call malloc/free, so
// tests (and `plumb run --count-allocations`) can prove a code path allocates nothing:
//
//   const uint64_t before = plumb::allocationCount();
//   solver.solve();
//   EXPECT_EQ(plumb::allocationCount() - before, 0u);
//
// The counters are process-wide (every thread); take differences around the code under test.
#include <cstdint>

namespace plumb {

uint64_t allocationCount();    // operator new calls since start (threads excluded below not counted)
uint64_t deallocationCount();  // operator delete calls (non-null) since start
uint64_t allocatedBytes();     // bytes requested through operator new since start (every thread)

// A thread that is no part of any frame path (the viewer's server thread, viewer/) calls this once
// at its start: from then on its allocations go to excludedAllocationCount() instead, so
// allocationCount() still proves the frame path allocates nothing while a viewer runs beside it.
// What such a thread allocates is reported on its own, never hidden.
void excludeThisThreadFromAllocationCount();
uint64_t excludedAllocationCount();  // operator new calls on excluded threads since start

// RAII helper: allocations made between construction and count().
class AllocationScope {
 public:
  AllocationScope() : start_(allocationCount()) {}
  uint64_t count() const { return allocationCount() - start_; }

 private:
  uint64_t start_;
};

}  // namespace plumb
