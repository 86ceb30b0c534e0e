#pragma once
// VTK XML PolyData (.vtp) writer for polylines (ParaView opens it): streamlines of the Langer
// field (paper fig. 6), stroke paths. ASCII, written atomically.
//
//   Polylines lines;
//   lines.lines.push_back({p0, p1, p2});                        // mm
//   lines.point_data.push_back({"speed", 1, {...}});            // one tuple per point, in line order
//   write_vtp_polylines(out / "streamlines.vtp", lines);
#include <filesystem>
#include <vector>

#include "cleave/io/vtu_writer.hpp"

namespace cleave {

struct Polylines {
  std::vector<std::vector<Vec3>> lines;  ///< each with at least 2 points (shorter ones are refused)
  std::vector<DataArray> point_data;     ///< one tuple per point, points numbered line after line
  std::vector<DataArray> cell_data;      ///< one tuple per line
};

/// Throws InputError when a line has fewer than 2 points or an array's size does not match;
/// ComputeError naming the array (or "points") when a value is not finite.
void write_vtp_polylines(const std::filesystem::path& file, const Polylines& polylines);

}  // namespace cleave
