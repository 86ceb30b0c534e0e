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

/// Starts this program again (same process, same arguments) with glibc's malloc asking the
/// kernel for transparent huge pages (GLIBC_TUNABLES glibc.malloc.hugetlb=1, glibc 2.35 and
/// later), unless it already runs so. Where the kernel gives huge pages only on request (THP
/// "madvise", the default here) every 4 KB page of the heap is otherwise faulted in one by one:
/// 1.2-1.3 million faults in a `cleave bench` run of the 350k-cell tube, about 28 % of its time
/// in the kernel, against 4-5 thousand with huge pages (docs/PERFORMANCE.md, session 21).
/// glibc reads its tunables only when a program starts, hence the exec (of /proc/self/exe: the
/// process id stays). Call first thing in `main`. Returns without restarting when the tunable is
/// set already (by an earlier start or by the user), when CLEAVE_HUGE_PAGES=0, where the C
/// library is not glibc 2.35 or later on Linux, under AddressSanitizer, or when the exec fails.
/// Tools that do not follow an exec (valgrind without --trace-children=yes) need
/// CLEAVE_HUGE_PAGES=0, or they lose the program at the restart.
void restart_with_huge_pages(char** argv);

/// Whether this process's malloc asks for transparent huge pages (see restart_with_huge_pages).
bool malloc_uses_huge_pages();

}  // namespace cleave
