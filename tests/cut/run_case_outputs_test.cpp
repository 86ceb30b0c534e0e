// What `cleave run` writes for cuts, checked on the files a user opens:
//   - the cut faces carry their colouring (released traction ||sigma n||, depth) in surface.ply
//     (triangle and vertex arrays, vertex colours) and in result.vtu (cell arrays);
//   - removed plugs are held in place (no free pieces);
//   - a dynamic run writes frames.pvd, a ParaView series of frame_NNNN.vtu files;
//   - the demo's case (built-in abdomen, Langer design): every incision where the designed
//     eigenvalue ratio is at least 1.5 opens into an ellipse whose long axis lies within 10
//     degrees of the Langer direction, the cut across the lines gapes wider than the one along.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "cleave/io/case_file.hpp"
#include "cleave/io/ply_reader.hpp"
#include "cleave/pipeline/demo_case.hpp"
#include "cleave/shapes/builtin_shapes.hpp"
#include "cleave/pipeline/run_case.hpp"

namespace cleave {
namespace {

using nlohmann::json;

std::filesystem::path fresh_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("cleave_cut_run_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

json run(const json& c, const std::filesystem::path& dir) {
  const RunResult r = run_case(parse_case_text(c.dump(), "case.json", dir), dir, nullptr);
  std::ifstream in(r.summary_file);
  return json::parse(in);
}

std::string read_text(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// The values of an ASCII VTU DataArray named `name`.
std::vector<double> vtu_array(const std::string& vtu, const std::string& name) {
  const std::size_t at = vtu.find("Name=\"" + name + "\"");
  if (at == std::string::npos) return {};
  const std::size_t begin = vtu.find('>', at) + 1;
  std::istringstream in(vtu.substr(begin, vtu.find("</DataArray>", begin) - begin));
  std::vector<double> out;
  for (double x; in >> x;) out.push_back(x);
  return out;
}

const NamedScalars& named(const std::vector<NamedScalars>& arrays, const std::string& name) {
  for (const NamedScalars& a : arrays)
    if (a.name == name) return a;
  throw std::runtime_error("no array " + name);
}

/// Plate 100 x 100 x 10 mm at 5 mm cells, 20 kPa along x, 10 kPa along y, rim held.
json plate_case() {
  json c = {{"model", {{"source", "plate"}, {"resolution", {20, 20, 2}}}},
            {"materials", {{"1", {{"E_kPa", 80}, {"nu", 0.4}}}}},
            {"residual_stress", {{"uniform_kPa", {20, 10, 0, 0, 0, 0}}}}};
  c["simulation"] = {{"fixed", json::array({json{{"box_mm", {{-1, -1, -1}, {0.1, 101, 11}}}},
                                            json{{"box_mm", {{99.9, -1, -1}, {101, 101, 11}}}},
                                            json{{"box_mm", {{-1, -1, -1}, {101, 0.1, 11}}}},
                                            json{{"box_mm", {{-1, 99.9, -1}, {101, 101, 11}}}}})}};
  return c;
}

TEST(RunCaseOutputs, CutFacesCarryReleasedTractionAndDepthInSurfaceAndVolume) {
  // A 5 mm deep cut along y at x = 50: its faces have normal +-x, so ||sigma n|| = 20 kPa on all.
  json c = plate_case();
  c["cuts"] = json::array({json{{"type", "scalpel"}, {"path_mm", {{50, 20, 10}, {50, 80, 10}}}, {"depth_mm", 5}}});
  const auto dir = fresh_dir("colours");
  const json summary = run(c, dir);
  ASSERT_GT(summary["surface"]["cut_triangles"].get<int>(), 0);

  const SurfaceMesh mesh = read_ply(dir / "surface.ply");
  const NamedScalars& is_cut = named(mesh.triangle_scalars, "is_cut");
  const NamedScalars& traction = named(mesh.triangle_scalars, "released_traction_kPa");
  const NamedScalars& depth = named(mesh.triangle_scalars, "cut_face_depth");
  float depth_lo = 1, depth_hi = 0;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (is_cut.values[t] > 0.5f) {
      EXPECT_NEAR(traction.values[t], 20.0f, 1e-3f) << "triangle " << t;
      depth_lo = std::min(depth_lo, depth.values[t]);
      depth_hi = std::max(depth_hi, depth.values[t]);
    } else {
      EXPECT_EQ(traction.values[t], 0.0f);
      EXPECT_EQ(depth.values[t], 0.0f);
    }
  }
  // Face centres of a 5 mm deep cut in a 10 mm plate lie 2.5 mm below the skin: depth 0.25
  // (distance to the nearer face / thickness).
  EXPECT_NEAR(depth_lo, 0.25f, 0.05f);
  EXPECT_NEAR(depth_hi, 0.25f, 0.05f);
  EXPECT_NEAR(*std::max_element(named(mesh.vertex_scalars, "released_traction_kPa").values.begin(),
                                named(mesh.vertex_scalars, "released_traction_kPa").values.end()),
              20.0f, 1e-3f);
  ASSERT_EQ(mesh.vertex_colors.size(), mesh.positions_mm.size());

  const std::string vtu = read_text(dir / "result.vtu");
  const std::vector<double> cell_traction_Pa = vtu_array(vtu, "released_traction");
  const std::vector<double> cell_depth = vtu_array(vtu, "cut_face_depth");
  ASSERT_FALSE(cell_traction_Pa.empty());
  ASSERT_EQ(cell_depth.size(), cell_traction_Pa.size());
  EXPECT_NEAR(*std::max_element(cell_traction_Pa.begin(), cell_traction_Pa.end()), 20000.0, 1e-6);
  EXPECT_NE(read_text(dir / "surface.gltf").find("RELEASED_TRACTION_KPA"), std::string::npos);
}

TEST(RunCaseOutputs, RemovedPlugsAreHeldInPlaceAndAreNoFreePieces) {
  // One round incision through half the plate: its plug is cut free and removed. The mechanics
  // holds every vertex of the plug (it touches nothing) instead of treating it as a free piece.
  json c = plate_case();
  c["incisions"] = {{"radius_mm", 12}, {"depth_mm", 5}, {"plug", "remove"}, {"at_mm", {{50, 50, 10}}}};
  const auto dir = fresh_dir("plug");
  const json summary = run(c, dir);
  const int removed = summary["cut"]["removed_cells"].get<int>();
  ASSERT_GT(removed, 0);
  EXPECT_EQ(summary["mechanics"]["held_removed_cells"].get<int>(), removed);
  EXPECT_EQ(summary["mechanics"]["free_components"].get<int>(), 0);

  const std::string vtu = read_text(dir / "result.vtu");
  const std::vector<double> removed_cell = vtu_array(vtu, "removed");
  const std::vector<double> fixed = vtu_array(vtu, "fixed");
  const std::vector<double> displacement = vtu_array(vtu, "displacement");
  const std::vector<double> connectivity = vtu_array(vtu, "connectivity");
  ASSERT_EQ(connectivity.size(), 8 * removed_cell.size());
  ASSERT_EQ(displacement.size(), 3 * fixed.size());
  int plug_cells = 0;
  for (std::size_t cell = 0; cell < removed_cell.size(); ++cell) {
    if (removed_cell[cell] < 0.5) continue;
    ++plug_cells;
    for (std::size_t k = 0; k < 8; ++k) {
      const auto v = static_cast<std::size_t>(connectivity[8 * cell + k]);
      EXPECT_EQ(fixed[v], 1.0) << "vertex " << v;
      for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(displacement[3 * v + i], 0.0) << "vertex " << v;
    }
  }
  EXPECT_EQ(plug_cells, removed);
  // The opened hole itself moves: the plate's stress is released at its wall.
  EXPECT_GT(summary["mechanics"]["max_displacement_mm"].get<double>(), 0.05);
  EXPECT_EQ(summary["incisions_overview"]["measured"].get<int>(), 1);
}

TEST(RunCaseOutputs, DynamicRunWritesAParaViewSeriesOfFrames) {
  json c = plate_case();
  c["cuts"] = json::array({json{{"type", "scalpel"}, {"path_mm", {{50, 20, 10}, {50, 80, 10}}}, {"depth_mm", 5}}});
  c["simulation"]["mode"] = "dynamic";
  c["simulation"]["time_step_s"] = 0.01;
  c["simulation"]["steps"] = 20;
  c["simulation"]["steps_per_frame"] = 5;
  c["simulation"]["damping"] = {{"mass_per_s", 20}};
  const auto dir = fresh_dir("dynamic");
  const json summary = run(c, dir);
  EXPECT_EQ(summary["mechanics"]["frames_written"].get<int>(), 5);  // t = 0, 0.05, ..., 0.2 s

  const std::string pvd = read_text(dir / "frames.pvd");
  ASSERT_NE(pvd.find("type=\"Collection\""), std::string::npos);
  const std::regex dataset("<DataSet[^>]*timestep=\"([^\"]+)\"[^>]*file=\"([^\"]+)\"");
  std::vector<double> times;
  double last_max_u = 0;
  for (auto it = std::sregex_iterator(pvd.begin(), pvd.end(), dataset); it != std::sregex_iterator(); ++it) {
    times.push_back(std::stod((*it)[1]));
    const std::filesystem::path frame = dir / (*it)[2].str();
    ASSERT_TRUE(std::filesystem::exists(frame)) << frame;
    const std::vector<double> u = vtu_array(read_text(frame), "displacement");
    ASSERT_FALSE(u.empty());
    last_max_u = 0;
    for (std::size_t i = 0; i + 2 < u.size(); i += 3) last_max_u = std::max(last_max_u, std::hypot(u[i], u[i + 1], u[i + 2]));
  }
  ASSERT_EQ(times.size(), 5u);
  for (std::size_t k = 0; k < times.size(); ++k) EXPECT_NEAR(times[k], 0.05 * static_cast<double>(k), 1e-9);
  EXPECT_GT(last_max_u, 0.1);  // the wound has begun to open by t = 0.2 s
}

TEST(RunCaseOutputs, DemoIncisionsFollowLangersLinesAndTheCutAcrossGapesWider) {
  ShapeResolution resolution;
  resolution.cell_size_mm = kDemoCellSizeMm;
  const TissueModel abdomen = make_tissue_model("abdomen", make_builtin_shape("abdomen", resolution));
  const auto dir = fresh_dir("demo");
  const json summary = run(abdomen_demo_case(abdomen, DemoStress::designed), dir);
  int anisotropic = 0;
  for (const json& i : summary["incisions"]) {
    EXPECT_GT(i["opening_mm"].get<double>(), 0.0) << i.dump();
    if (i.value("eigenvalue_ratio", 0.0) < 1.5) continue;
    ++anisotropic;
    EXPECT_LT(i["langer_angle_deg"].get<double>(), 10.0) << i.dump();
    EXPECT_GT(i["outer"]["axis_ratio"].get<double>(), 1.05) << i.dump();
  }
  EXPECT_GE(anisotropic, 10);
  const json& cuts = summary["cuts"];
  ASSERT_EQ(cuts.size(), 3u);
  const double across = cuts[0]["max_width_mm"].get<double>(), along = cuts[1]["max_width_mm"].get<double>();
  EXPECT_GE(across, 5.0);  // paper section 7: 5 to 20 mm
  EXPECT_LE(across, 20.0);
  EXPECT_GE(across, 1.5 * along);
  EXPECT_LT(cuts[2]["skin_area_change_percent"].get<double>(), -5.0);  // the flap shrinks
}

}  // namespace
}  // namespace cleave
