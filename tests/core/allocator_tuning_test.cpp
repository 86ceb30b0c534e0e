#include "cleave/core/allocator_tuning.hpp"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <cstddef>
#include <cstdio>
#include <cstdlib>

namespace cleave {
namespace {

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitizerAllocator = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kSanitizerAllocator = true;
#else
constexpr bool kSanitizerAllocator = false;
#endif
#else
constexpr bool kSanitizerAllocator = false;
#endif

constexpr std::size_t kPageBytes = 4096;
constexpr std::size_t kBlockBytes = std::size_t{256} << 20;  // well above glibc's 32 MB mapping threshold

long minor_page_faults() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_minflt;
}

void touch_every_page(volatile char* block, std::size_t bytes) {
  for (std::size_t i = 0; i < bytes; i += kPageBytes) block[i] = 1;
}

/// Page faults taken while touching a freshly allocated block after one of the same size was
/// allocated, touched and freed: what a solver's second setup pays for its arrays.
long page_faults_of_a_reallocated_block(std::size_t bytes) {
  auto* first = static_cast<volatile char*>(std::malloc(bytes));
  EXPECT_NE(first, nullptr);
  touch_every_page(first, bytes);
  std::free(const_cast<char*>(first));
  const long before = minor_page_faults();
  auto* second = static_cast<volatile char*>(std::malloc(bytes));
  EXPECT_NE(second, nullptr);
  touch_every_page(second, bytes);
  const long faults = minor_page_faults() - before;
  std::free(const_cast<char*>(second));
  return faults;
}

TEST(AllocatorTuning, AFreedLargeBlockIsReusedWithoutPageFaults) {
  if (kSanitizerAllocator) GTEST_SKIP() << "AddressSanitizer brings its own allocator";
  const long untuned = page_faults_of_a_reallocated_block(kBlockBytes);
  if (untuned == 0) GTEST_SKIP() << "this C library already reuses freed large blocks";
  keep_freed_memory_for_reuse();
  const long tuned = page_faults_of_a_reallocated_block(kBlockBytes);
  std::printf("page faults of a reallocated 256 MB block: %ld untuned, %ld tuned\n", untuned, tuned);
  EXPECT_LE(10 * tuned, untuned) << "untuned " << untuned << " faults, tuned " << tuned;
  EXPECT_LT(tuned, static_cast<long>(kBlockBytes / kPageBytes / 100));
}

}  // namespace
}  // namespace cleave
