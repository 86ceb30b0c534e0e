#pragma once
// VTK XML unstructured grid (.vtu) and ParaView collection (.pvd) writers. ParaView opens both.
// The cells are written in the reference configuration; split vertices are separate points, so
// a cut shows as a crack when the displacement is applied (ParaView: "Warp By Vector").
#include <filesystem>
#include <string>
#include <vector>

#include "cleave/grid/linked_volume.hpp"

namespace cleave {

/// A named data array: `components` values per point or per cell, stored point-/cell-major.
struct DataArray {
  std::string name;  ///< include the unit where it has one, or document it: "displacement" (mm)
  int components = 1;
  std::vector<double> values;
};

struct VolumeFields {
  std::vector<DataArray> point_data;  ///< one tuple per vertex of the linked volume
  std::vector<DataArray> cell_data;   ///< one tuple per cell
};

/// Writes the hexahedral cells of `volume` with `fields`. Throws InputError when an array's
/// size does not match the vertex or cell count, or the file cannot be written.
/// Non-finite values are refused (ComputeError naming the array) so that no NaN reaches a result.
void write_vtu(const std::filesystem::path& file, const LinkedVolume& volume, const VolumeFields& fields);

struct PvdEntry {
  double time_s = 0;
  std::filesystem::path file;  ///< relative to the .pvd's folder
};
void write_pvd(const std::filesystem::path& file, const std::vector<PvdEntry>& entries);

}  // namespace cleave
