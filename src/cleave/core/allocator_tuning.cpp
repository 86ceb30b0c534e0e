#include "cleave/core/allocator_tuning.hpp"

#include <climits>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace cleave {
namespace {

/// Free memory at the top of the heap kept before any is returned (mallopt takes an int).
constexpr int kKeptTopBytes = INT_MAX;
/// Extra heap requested from the kernel with each growth: fewer, larger brk calls.
constexpr int kTopPadBytes = 64 << 20;

}  // namespace

void keep_freed_memory_for_reuse() {
#if defined(__GLIBC__)
  mallopt(M_MMAP_MAX, 0);  // no block gets its own mapping: freed blocks are reused, not unmapped
  mallopt(M_TRIM_THRESHOLD, kKeptTopBytes);
  mallopt(M_TOP_PAD, kTopPadBytes);
#endif
}

}  // namespace cleave
