#include "cleave/core/allocator_tuning.hpp"

#include <climits>
#include <cstdlib>
#include <string>
#include <string_view>

#if defined(__GLIBC__)
#include <gnu/libc-version.h>
#include <malloc.h>
#include <unistd.h>
#endif

#include "cleave/core/address_sanitizer.hpp"

namespace cleave {
namespace {

/// Free memory at the top of the heap kept before any is returned (mallopt takes an int).
constexpr int kKeptTopBytes = INT_MAX;
/// Extra heap requested from the kernel with each growth: fewer, larger brk calls.
constexpr int kTopPadBytes = 64 << 20;

constexpr std::string_view kHugePageTunable = "glibc.malloc.hugetlb=1";

/// The environment's GLIBC_TUNABLES, empty when unset.
std::string glibc_tunables() {
  const char* value = std::getenv("GLIBC_TUNABLES");
  return value != nullptr ? value : "";
}

/// glibc 2.35 or later (the first with glibc.malloc.hugetlb), on Linux, without AddressSanitizer.
bool huge_page_tunable_supported() {
#if defined(__GLIBC__) && defined(__linux__) && !defined(CLEAVE_ADDRESS_SANITIZER)
  const std::string version = gnu_get_libc_version();
  const std::size_t dot = version.find('.');
  if (dot == std::string::npos) return false;
  const int major = std::atoi(version.substr(0, dot).c_str());
  const int minor = std::atoi(version.substr(dot + 1).c_str());
  return major > 2 || (major == 2 && minor >= 35);
#else
  return false;
#endif
}

/// Read when the program is loaded: what glibc's malloc read at the same time.
const bool kStartedWithHugePages = huge_page_tunable_supported() && glibc_tunables().find(kHugePageTunable) != std::string::npos;

}  // namespace

void keep_freed_memory_for_reuse() {
#if defined(__GLIBC__)
  mallopt(M_MMAP_MAX, 0);  // no block gets its own mapping: freed blocks are reused, not unmapped
  mallopt(M_TRIM_THRESHOLD, kKeptTopBytes);
  mallopt(M_TOP_PAD, kTopPadBytes);
#endif
}

void restart_with_huge_pages(char** argv) {
#if defined(__GLIBC__) && defined(__linux__)
  if (argv == nullptr || argv[0] == nullptr || !huge_page_tunable_supported()) return;
  const char* opt_out = std::getenv("CLEAVE_HUGE_PAGES");
  if (opt_out != nullptr && std::string_view(opt_out) == "0") return;
  const std::string before = glibc_tunables();
  if (before.find("glibc.malloc.hugetlb") != std::string::npos) return;  // set: by an earlier start, or the user's choice
  const std::string with_huge_pages = before.empty() ? std::string(kHugePageTunable) : before + ":" + std::string(kHugePageTunable);
  if (setenv("GLIBC_TUNABLES", with_huge_pages.c_str(), 1) != 0) return;
  execv("/proc/self/exe", argv);
  // No exec (no /proc): go on as started, with the environment as it was.
  if (before.empty()) unsetenv("GLIBC_TUNABLES");
  else setenv("GLIBC_TUNABLES", before.c_str(), 1);
#else
  (void)argv;
#endif
}

bool malloc_uses_huge_pages() { return kStartedWithHugePages; }

}  // namespace cleave
