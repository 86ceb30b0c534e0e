#include "cleave/pipeline/demo_case.hpp"

namespace cleave {
namespace {

using nlohmann::json;

constexpr double kLangerKPa = 20.0;      // paper section 7
constexpr double kCrossKPa = 10.0;
constexpr double kYoungKPa = 80.0;
constexpr double kPoisson = 0.4;
constexpr double kCellSizeMm = kDemoCellSizeMm;
constexpr double kIncisionRadiusMm = 8.0;
constexpr double kIncisionDepthMm = 5.0;  // through the skin and the fat, about half the wall
constexpr double kIncisionSpacingMm = 35.0;
constexpr double kCutLengthMm = 50.0;    // "a 5 cm incision"
constexpr double kCutDepthMm = 8.0;
constexpr double kFlapDepthMm = 5.0;
constexpr double kRimMm = 5.0;           // held band along the wall's edges

/// Point on the skin above (x, z): the top of the body found by a vertical ray from above.
json skin_point(const TissueModel& model, double x, double z) {
  const LinkedVolume& v = model.volume;
  const double step = 0.1 * v.grid().cell_size_mm;
  double y = v.grid().origin_mm.y() + v.grid().extent_mm().y();
  while (y > v.grid().origin_mm.y() && v.cell_containing(Vec3(x, y, z)) == kNone) y -= step;
  return json::array({x, y + 0.5 * step, z});
}

}  // namespace

json abdomen_demo_case(const TissueModel& model, DemoStress stress) {
  const bool with_design = stress == DemoStress::designed;
  const Vec3 extent = model.volume.grid().extent_mm();
  const double w = extent.x(), l = extent.z();
  json strokes = json::array();
  for (const double z : {0.2 * l, 0.5 * l, 0.8 * l}) {
    json pts = json::array();
    for (double x = 0.1 * w; x <= 0.9 * w + 1e-9; x += 0.1 * w) pts.push_back(skin_point(model, x, z));
    strokes.push_back({{"points", pts}});
  }
  json controls = json::array();
  for (const double x : {0.3 * w, 0.7 * w})
    for (const double z : {0.3 * l, 0.7 * l})
      controls.push_back({{"position", skin_point(model, x, z)}, {"langer_kPa", kLangerKPa}, {"cross_kPa", kCrossKPa}});
  const double xa = 0.32 * w, xb = 0.72 * w, zc = 0.3 * l;
  json c = json::object();
  c["cleave_case"] = 1;
  c["description"] = "cleave demo: Langer design on the abdomen, round incisions, cuts across and along, a flap";
  c["model"] = {{"source", "abdomen"}, {"cell_size_mm", kCellSizeMm}};
  json material = {{"E_kPa", kYoungKPa}, {"nu", kPoisson}};
  c["materials"] = {{"1", material}, {"2", material}, {"3", material}};
  json place = json::object();
  place["spacing_mm"] = kIncisionSpacingMm;
  place["region"] = {{"box_mm", json::array({json::array({0.1 * w, 0.0, 0.55 * l}), json::array({0.9 * w, extent.y(), 0.9 * l})})}};
  place["seed"] = 7;
  c["incisions"] = {{"radius_mm", kIncisionRadiusMm}, {"depth_mm", kIncisionDepthMm}, {"plug", "remove"}, {"place", place}};
  json across = {{"type", "scalpel"}, {"depth_mm", kCutDepthMm}};  // Langer's lines run along x: this path runs along z
  across["path_mm"] = json::array({skin_point(model, xa, zc - 0.5 * kCutLengthMm), skin_point(model, xa, zc + 0.5 * kCutLengthMm)});
  json along = {{"type", "scalpel"}, {"depth_mm", kCutDepthMm}};
  along["path_mm"] = json::array({skin_point(model, xb - 0.5 * kCutLengthMm, zc), skin_point(model, xb + 0.5 * kCutLengthMm, zc)});
  json flap = {{"type", "flap"}, {"shape", "u"}, {"depth_mm", kFlapDepthMm}};
  flap["path_mm"] = json::array({skin_point(model, 0.45 * w, 0.12 * l), skin_point(model, 0.45 * w, 0.27 * l),
                                 skin_point(model, 0.55 * w, 0.27 * l), skin_point(model, 0.55 * w, 0.12 * l)});
  c["cuts"] = json::array({across, along, flap});
  const json settings = abdomen_demo_settings(model);
  c["simulation"] = settings["simulation"];
  if (with_design) {
    c["design"] = settings["design"];
    c["design"]["strokes"] = strokes;
    c["design"]["control_points"] = controls;
  } else {
    c["residual_stress"] = {{"uniform_kPa", json::array({kLangerKPa, 0.0, kCrossKPa, 0.0, 0.0, 0.0})}};
  }
  return c;
}

json abdomen_demo_settings(const TissueModel& model) {
  const Vec3 extent = model.volume.grid().extent_mm();
  const double w = extent.x(), l = extent.z();
  const auto box = [](double x0, double y0, double z0, double x1, double y1, double z1) {
    return json{{"box_mm", json::array({json::array({x0, y0, z0}), json::array({x1, y1, z1})})}};
  };
  const double top = extent.y() + 1;
  json s = json::object();
  s["design"] = {{"weights", {{"equilibrium", 0.0}}}, {"equilibrate", true}, {"equilibrium_support", "simulation"}};
  s["simulation"] = {{"mode", "static"},
                     {"fixed", json::array({box(-1, -1, -1, kRimMm, top, l + 1), box(w - kRimMm, -1, -1, w + 1, top, l + 1),
                                            box(-1, -1, -1, w + 1, top, kRimMm), box(-1, -1, l - kRimMm, w + 1, top, l + 1),
                                            {{"surface", "inner"}}})}};
  return s;
}

}  // namespace cleave
