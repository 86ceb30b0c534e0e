#include "cleave/io/vtu_writer.hpp"

#include <cmath>
#include <fmt/format.h>
#include <fmt/os.h>

#include "cleave/core/error.hpp"
#include "cleave/io/atomic_file.hpp"

namespace cleave {
namespace {

/// VTK_HEXAHEDRON node order in terms of cleave's corner bits (x = 1, y = 2, z = 4).
constexpr int kVtkHexOrder[8] = {0, 1, 3, 2, 4, 5, 7, 6};

void check_array(const DataArray& a, std::size_t tuples, const char* where) {
  if (a.components <= 0 || a.values.size() != tuples * static_cast<std::size_t>(a.components))
    throw InputError(fmt::format("{} array '{}' holds {} values; expected {} tuples of {}", where, a.name,
                                 a.values.size(), tuples, a.components));
  for (double v : a.values)
    if (!std::isfinite(v)) throw ComputeError(fmt::format("{} array '{}' holds a non-finite value; refusing to write it", where, a.name));
}

void write_arrays(std::string& out, const std::vector<DataArray>& arrays) {
  for (const DataArray& a : arrays) {
    out += fmt::format("        <DataArray type=\"Float64\" Name=\"{}\" NumberOfComponents=\"{}\" format=\"ascii\">\n",
                       a.name, a.components);
    for (std::size_t i = 0; i < a.values.size(); ++i) {
      out += fmt::format("{:.9g}", a.values[i]);
      out += (i + 1) % static_cast<std::size_t>(a.components) == 0 ? '\n' : ' ';
    }
    out += "        </DataArray>\n";
  }
}

}  // namespace

void write_vtu(const std::filesystem::path& file, const LinkedVolume& volume, const VolumeFields& fields) {
  const auto points = static_cast<std::size_t>(volume.vertex_count());
  const auto cells = static_cast<std::size_t>(volume.cell_count());
  for (const auto& a : fields.point_data) check_array(a, points, "point data");
  for (const auto& a : fields.cell_data) check_array(a, cells, "cell data");

  std::string out;
  out.reserve(cells * 200 + points * 60);
  out += "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\">\n";
  out += "  <UnstructuredGrid>\n";
  out += fmt::format("    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n", points, cells);
  out += "      <PointData>\n";
  write_arrays(out, fields.point_data);
  out += "      </PointData>\n      <CellData>\n";
  write_arrays(out, fields.cell_data);
  out += "      </CellData>\n      <Points>\n";
  out += "        <DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (VertexId v = 0; v < volume.vertex_count(); ++v) {
    const Vec3 p = volume.vertex_position_mm(v);
    out += fmt::format("{:.9g} {:.9g} {:.9g}\n", p.x(), p.y(), p.z());
  }
  out += "        </DataArray>\n      </Points>\n      <Cells>\n";
  out += "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (CellId c = 0; c < volume.cell_count(); ++c) {
    for (int k = 0; k < 8; ++k) out += fmt::format("{} ", volume.corner_vertex(c, kVtkHexOrder[k]));
    out += '\n';
  }
  out += "        </DataArray>\n        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  for (std::size_t c = 1; c <= cells; ++c) out += fmt::format("{}\n", 8 * c);
  out += "        </DataArray>\n        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (std::size_t c = 0; c < cells; ++c) out += "12\n";
  out += "        </DataArray>\n      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n";
  write_file_atomically(file, out);
}

void write_pvd(const std::filesystem::path& file, const std::vector<PvdEntry>& entries) {
  std::string out = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n  <Collection>\n";
  for (const PvdEntry& e : entries)
    out += fmt::format("    <DataSet timestep=\"{:.9g}\" part=\"0\" file=\"{}\"/>\n", e.time_s, e.file.generic_string());
  out += "  </Collection>\n</VTKFile>\n";
  write_file_atomically(file, out);
}

}  // namespace cleave
