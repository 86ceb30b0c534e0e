#include "cleave/core/allocator_tuning.hpp"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <unistd.h>

#include <array>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include "cleave/core/address_sanitizer.hpp"

namespace cleave {
namespace {

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
  if (kAddressSanitizer) GTEST_SKIP() << "AddressSanitizer brings its own allocator";
  const long untuned = page_faults_of_a_reallocated_block(kBlockBytes);
  if (untuned == 0) GTEST_SKIP() << "this C library already reuses freed large blocks";
  keep_freed_memory_for_reuse();
  const long tuned = page_faults_of_a_reallocated_block(kBlockBytes);
  std::printf("page faults of a reallocated 256 MB block: %ld untuned, %ld tuned\n", untuned, tuned);
  EXPECT_LE(10 * tuned, untuned) << "untuned " << untuned << " faults, tuned " << tuned;
  EXPECT_LT(tuned, static_cast<long>(kBlockBytes / kPageBytes / 100));
}

// Run in a child process by the next test: the page faults of touching a fresh 256 MB block
// from the tuned heap.
TEST(AllocatorTuning, DISABLED_PrintFaultsOfAFreshBlock) {
  keep_freed_memory_for_reuse();
  const long before = minor_page_faults();
  auto* block = static_cast<volatile char*>(std::malloc(kBlockBytes));
  ASSERT_NE(block, nullptr);
  touch_every_page(block, kBlockBytes);
  std::printf("fresh-block-faults %ld\n", minor_page_faults() - before);
  std::free(const_cast<char*>(block));
}

/// The faults the helper above reports when this test binary runs it with `environment`; -1 when
/// it printed none.
long faults_of_a_fresh_block_in_a_child(const std::string& environment) {
  std::array<char, 4096> self{};
  const ssize_t length = readlink("/proc/self/exe", self.data(), self.size() - 1);
  if (length <= 0) return -1;
  const std::string command = "env " + environment + " '" + std::string(self.data(), static_cast<std::size_t>(length)) +
                              "' --gtest_also_run_disabled_tests --gtest_filter=AllocatorTuning.DISABLED_PrintFaultsOfAFreshBlock";
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(command.c_str(), "r"), pclose);
  if (!pipe) return -1;
  std::array<char, 512> line{};
  long faults = -1;
  while (std::fgets(line.data(), static_cast<int>(line.size()), pipe.get()) != nullptr) {
    std::istringstream in(line.data());
    std::string word;
    if (in >> word && word == "fresh-block-faults") in >> faults;
  }
  return faults;
}

// With the tunable restart_with_huge_pages sets (glibc.malloc.hugetlb=1) the heap comes in 2 MB
// pages: touching a fresh 256 MB block takes a few hundred faults instead of one per 4 KB page.
TEST(AllocatorTuning, HugePagesCutThePageFaultsOfAFreshBlock) {
  if (kAddressSanitizer) GTEST_SKIP() << "AddressSanitizer brings its own allocator";
  std::ifstream thp("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string modes;
  std::getline(thp, modes);
  if (modes.empty() || modes.find("[never]") != std::string::npos) GTEST_SKIP() << "the kernel gives no transparent huge pages";
  const long small_pages = faults_of_a_fresh_block_in_a_child("GLIBC_TUNABLES=glibc.malloc.hugetlb=0");
  const long huge_pages = faults_of_a_fresh_block_in_a_child("GLIBC_TUNABLES=glibc.malloc.hugetlb=1");
  std::printf("page faults of a fresh 256 MB block: %ld with 4 KB pages, %ld with huge pages\n", small_pages, huge_pages);
  ASSERT_GE(small_pages, 0);
  ASSERT_GE(huge_pages, 0);
  EXPECT_GE(small_pages, static_cast<long>(kBlockBytes / kPageBytes / 2));
  EXPECT_LE(20 * huge_pages, small_pages);
}

}  // namespace
}  // namespace cleave
