#include "cleave/io/vtp_writer.hpp"

#include <cmath>
#include <fmt/format.h>
#include <string>

#include "cleave/core/error.hpp"
#include "cleave/io/atomic_file.hpp"

namespace cleave {
namespace {

void check_array(const DataArray& a, std::size_t tuples, const char* where) {
  if (a.components < 1 || a.values.size() != tuples * static_cast<std::size_t>(a.components))
    throw InputError(fmt::format("{} array '{}' holds {} values; expected {} ({} tuples of {})", where, a.name,
                                 a.values.size(), tuples * static_cast<std::size_t>(std::max(a.components, 1)), tuples,
                                 a.components));
  for (double v : a.values)
    if (!std::isfinite(v)) throw ComputeError(fmt::format("{} array '{}' holds a non-finite value", where, a.name));
}

void append_array(std::string& out, const DataArray& a) {
  out += fmt::format("        <DataArray type=\"Float64\" Name=\"{}\" NumberOfComponents=\"{}\" format=\"ascii\">\n          ",
                     a.name, a.components);
  for (double v : a.values) out += fmt::format("{:.10g} ", v);
  out += "\n        </DataArray>\n";
}

}  // namespace

void write_vtp_polylines(const std::filesystem::path& file, const Polylines& polylines) {
  std::size_t points = 0;
  for (std::size_t i = 0; i < polylines.lines.size(); ++i) {
    if (polylines.lines[i].size() < 2)
      throw InputError(fmt::format("{}: polyline {} has {} points; expected at least 2", file.string(), i,
                                   polylines.lines[i].size()));
    for (const Vec3& p : polylines.lines[i])
      if (!p.allFinite()) throw ComputeError(fmt::format("{}: polyline {} has a non-finite point", file.string(), i));
    points += polylines.lines[i].size();
  }
  for (const DataArray& a : polylines.point_data) check_array(a, points, "point");
  for (const DataArray& a : polylines.cell_data) check_array(a, polylines.lines.size(), "line");

  std::string out;
  out += "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <PolyData>\n";
  out += fmt::format("    <Piece NumberOfPoints=\"{}\" NumberOfVerts=\"0\" NumberOfLines=\"{}\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n",
                     points, polylines.lines.size());
  out += "      <Points>\n        <DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n          ";
  for (const auto& line : polylines.lines)
    for (const Vec3& p : line) out += fmt::format("{:.10g} {:.10g} {:.10g} ", p.x(), p.y(), p.z());
  out += "\n        </DataArray>\n      </Points>\n      <Lines>\n";
  out += "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n          ";
  for (std::size_t i = 0; i < points; ++i) out += fmt::format("{} ", i);
  out += "\n        </DataArray>\n        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n          ";
  std::size_t offset = 0;
  for (const auto& line : polylines.lines) {
    offset += line.size();
    out += fmt::format("{} ", offset);
  }
  out += "\n        </DataArray>\n      </Lines>\n";
  out += "      <PointData>\n";
  for (const DataArray& a : polylines.point_data) append_array(out, a);
  out += "      </PointData>\n      <CellData>\n";
  for (const DataArray& a : polylines.cell_data) append_array(out, a);
  out += "      </CellData>\n    </Piece>\n  </PolyData>\n</VTKFile>\n";
  write_file_atomically(file, out);
}

}  // namespace cleave
