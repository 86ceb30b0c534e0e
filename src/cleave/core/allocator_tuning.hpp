#pragma once
// How the C library's allocator treats large blocks, tuned for cleave's access pattern.

namespace cleave {

/// Keeps freed memory in the process for the next allocation of its size instead of handing it
/// back to the kernel. cleave allocates and frees the same large arrays again and again (a
/// solver's levels after every cut, a factor after every stroke, the block copy of a matrix);
/// glibc serves each block above 32 MB with a fresh mapping, so every step paid for its
/// page-faults again (~40 % of a 44k-cell dynamic step, measured with perf). With this, large
/// blocks come from the heap and stay there (resident memory stays near its peak: it is what
/// the next step needs again). Call once at the start of `main`, before any thread exists.
/// Does nothing where the C library is not glibc or under AddressSanitizer (its own allocator).
void keep_freed_memory_for_reuse();

}  // namespace cleave
