#include "cleave/fem/cell_ranges.hpp"

#include <fmt/format.h>

#include "cleave/core/error.hpp"

namespace cleave {

void require_ranges_within(std::span<const CellRange> ranges, std::size_t cells, std::string_view what) {
  for (const auto& [begin, end] : ranges)
    if (begin > end || end > cells) throw InputError(fmt::format("{}: range [{}, {}) outside the {} cells", what, begin, end, cells));
}

}  // namespace cleave
