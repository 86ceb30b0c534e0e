#pragma once
// Cells as [begin, end) ranges of cell ids: what the dynamic step's cell passes compute when they
// leave out the cells held at every corner (CorotatedSystemOperator::computed_cell_ranges lists
// them; the forces, rotations and tensions take the same list).
//
//   for_each_cell_range(ranges, [&](std::size_t begin, std::size_t end) { ... });   // in parallel
//   require_ranges_within(ranges, cells, "corotated forces over cell ranges");       // InputError
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cstddef>
#include <span>
#include <string_view>
#include <utility>

namespace cleave {

using CellRange = std::pair<std::size_t, std::size_t>;  ///< cells [first, second)

/// f(begin, end) for each range, in parallel over the ranges.
template <typename F>
void for_each_cell_range(std::span<const CellRange> ranges, const F& f) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, ranges.size()), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t k = r.begin(); k < r.end(); ++k) f(ranges[k].first, ranges[k].second);
  });
}

/// InputError "<what>: range [begin, end) outside the <cells> cells" for the first range that is
/// reversed or reaches past the last cell.
void require_ranges_within(std::span<const CellRange> ranges, std::size_t cells, std::string_view what);

}  // namespace cleave
