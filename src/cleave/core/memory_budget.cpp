#include "cleave/core/memory_budget.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include "cleave/core/error.hpp"

namespace cleave {

std::uint64_t physical_memory_bytes() {
  const long pages = sysconf(_SC_PHYS_PAGES);
  const long page_size = sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || page_size <= 0) return 0;
  return static_cast<std::uint64_t>(pages) * static_cast<std::uint64_t>(page_size);
}

void require_memory(std::uint64_t bytes_needed, const std::string& what) {
  const std::uint64_t total = physical_memory_bytes();
  const std::uint64_t allowed = total == 0 ? (std::uint64_t{8} << 30) : total / 2;
  if (bytes_needed > allowed) {
    throw InputError(fmt::format("{} would need {:.1f} GiB of memory; this machine allows {:.1f} GiB "
                                 "(half of its {:.1f} GiB): choose a larger cell size or a smaller region",
                                 what, static_cast<double>(bytes_needed) / (1 << 30),
                                 static_cast<double>(allowed) / (1 << 30), static_cast<double>(total) / (1 << 30)));
  }
}

}  // namespace cleave
