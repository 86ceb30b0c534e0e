#include "cleave/io/case_cuts.hpp"

#include <fmt/format.h>
#include <limits>

#include "cleave/core/error.hpp"

namespace cleave {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kSmallest = std::numeric_limits<double>::min();
constexpr int kMaxCount = 100000;

double positive_mm(const nlohmann::json& obj, const std::string& key, const JsonPath& at, const std::string& what) {
  const nlohmann::json* v = json_find(obj, key);
  if (!v) json_missing(at / key, what);
  return json_number_in(*v, at / key, kSmallest, kInf, what);
}

PlugHandling parse_plug(const nlohmann::json& v, const JsonPath& at) {
  constexpr const char* kExpected = "\"remove\" or \"keep\"";
  if (!v.is_string()) json_error(at, v, kExpected);
  const std::string s = v.get<std::string>();
  if (s == "remove") return PlugHandling::remove;
  if (s == "keep") return PlugHandling::keep;
  json_error(at, v, kExpected);
}

IncisionRegion parse_region(const nlohmann::json& v, const JsonPath& at) {
  constexpr const char* kExpected =
      "\"surface\", {\"box_mm\": [[x0, y0, z0], [x1, y1, z1]]} or {\"sphere_mm\": {\"centre\": [x, y, z], \"radius\": r}}";
  if (v.is_string() && v.get<std::string>() == "surface") return {};
  if (!v.is_object() || v.size() != 1) json_error(at, v, kExpected);
  if (const auto* box = json_find(v, "box_mm")) {
    if (!box->is_array() || box->size() != 2) json_error(at / "box_mm", *box, "[[x0, y0, z0], [x1, y1, z1]] (mm)");
    const Vec3 lo = json_vec3((*box)[0], at / "box_mm" / 0), hi = json_vec3((*box)[1], at / "box_mm" / 1);
    if ((lo.array() > hi.array()).any())
      json_error(at / "box_mm", *box, "a lower corner [x0, y0, z0] not above the upper corner [x1, y1, z1]");
    return IncisionRegion::box(lo, hi);
  }
  if (const auto* sphere = json_find(v, "sphere_mm")) {
    const JsonPath sp = at / "sphere_mm";
    if (!sphere->is_object()) json_error(sp, *sphere, "{\"centre\": [x, y, z], \"radius\": r} (mm)");
    json_allow_keys(*sphere, sp, {"centre", "radius"});
    const auto* c = json_find(*sphere, "centre");
    if (!c) json_missing(sp / "centre", "[x, y, z] (mm)");
    return IncisionRegion::sphere(json_vec3(*c, sp / "centre"), positive_mm(*sphere, "radius", sp, "a positive radius in mm"));
  }
  json_error(at, v, kExpected);
}

std::vector<Vec3> parse_path(const nlohmann::json& cut, const JsonPath& at, std::size_t least) {
  const auto* p = json_find(cut, "path_mm");
  const std::string expected = fmt::format("an array of at least {} points [x, y, z] (mm)", least);
  if (!p) json_missing(at / "path_mm", expected);
  if (!p->is_array() || p->size() < least) json_error(at / "path_mm", *p, expected);
  return json_points(*p, at / "path_mm");
}

}  // namespace

CaseCuts parse_case_cuts(const CaseFile& case_file) {
  CaseCuts out;
  if (const nlohmann::json* inc = case_file.section("incisions")) {
    const JsonPath at = case_file.at("incisions");
    if (!inc->is_object()) json_error(at, *inc, "an object with radius_mm, depth_mm and at_mm and/or place");
    json_allow_keys(*inc, at, {"radius_mm", "depth_mm", "plug", "at_mm", "place", "surface_tolerance_mm"});
    const double radius = positive_mm(*inc, "radius_mm", at, "a positive incision radius in mm");
    const double depth = positive_mm(*inc, "depth_mm", at, "a positive incision depth in mm");
    const PlugHandling plug = json_find(*inc, "plug") ? parse_plug((*inc)["plug"], at / "plug") : PlugHandling::remove;
    if (const auto* tol = json_find(*inc, "surface_tolerance_mm"))
      out.surface_tolerance_mm = json_number_in(*tol, at / "surface_tolerance_mm", kSmallest, kInf, "a positive distance in mm");
    if (const auto* points = json_find(*inc, "at_mm"))
      for (const Vec3& c : json_points(*points, at / "at_mm")) out.incisions.push_back({c, radius, depth, plug});
    if (const auto* place = json_find(*inc, "place")) {
      const JsonPath pp = at / "place";
      if (!place->is_object()) json_error(pp, *place, "an object with spacing_mm (and count, region, seed)");
      json_allow_keys(*place, pp, {"spacing_mm", "count", "region", "seed"});
      IncisionPattern p;
      p.radius_mm = radius;
      p.depth_mm = depth;
      p.plug = plug;
      p.spacing_mm = positive_mm(*place, "spacing_mm", pp, "a positive spacing between incision centres in mm");
      if (const auto* c = json_find(*place, "count")) p.count = json_int_in(*c, pp / "count", 1, kMaxCount);
      if (const auto* r = json_find(*place, "region")) p.region = parse_region(*r, pp / "region");
      if (const auto* s = json_find(*place, "seed")) p.seed = static_cast<std::uint32_t>(json_int_in(*s, pp / "seed", 0, std::numeric_limits<int>::max()));
      out.pattern = p;
    }
    if (out.incisions.empty() && !out.pattern) json_missing(at / "at_mm", "incision centres \"at_mm\" or a \"place\" section");
  }
  if (const nlohmann::json* cuts = case_file.section("cuts")) {
    const JsonPath at = case_file.at("cuts");
    if (!cuts->is_array()) json_error(at, *cuts, "an array of cuts {\"type\": \"scalpel\" | \"flap\", ...}");
    for (std::size_t i = 0; i < cuts->size(); ++i) {
      const nlohmann::json& c = (*cuts)[i];
      const JsonPath ci = at / i;
      if (!c.is_object()) json_error(ci, c, "an object {\"type\": \"scalpel\" | \"flap\", ...}");
      const auto* type = json_find(c, "type");
      if (!type) json_missing(ci / "type", "\"scalpel\" or \"flap\"");
      const std::string t = json_string(*type, ci / "type");
      if (t == "scalpel") {
        json_allow_keys(c, ci, {"type", "path_mm", "depth_mm", "blade_angle_deg"});
        ScalpelCut s;
        s.path_mm = parse_path(c, ci, 2);
        s.depth_mm = positive_mm(c, "depth_mm", ci, "a positive cut depth in mm");
        if (const auto* a = json_find(c, "blade_angle_deg"))
          s.blade_angle_deg = json_number_in(*a, ci / "blade_angle_deg", -89.0, 89.0, "a blade tilt in degrees in [-89, 89]");
        out.scalpel_cuts.push_back(std::move(s));
        out.scalpel_index.push_back(i);
      } else if (t == "flap") {
        json_allow_keys(c, ci, {"type", "path_mm", "depth_mm", "shape"});
        Flap f;
        f.path_mm = parse_path(c, ci, 3);
        f.depth_mm = positive_mm(c, "depth_mm", ci, "a positive flap depth in mm");
        if (const auto* s = json_find(c, "shape")) {
          const std::string shape = s->is_string() ? s->get<std::string>() : "";
          if (shape == "u") f.shape = FlapShape::u_shaped;
          else if (shape == "closed") f.shape = FlapShape::closed;
          else json_error(ci / "shape", *s, "\"u\" or \"closed\"");
        }
        out.flaps.push_back(std::move(f));
        out.flap_index.push_back(i);
      } else {
        json_error(ci / "type", *type, "\"scalpel\" or \"flap\"");
      }
    }
  }
  return out;
}

CutRequests resolve_case_cuts(const CaseFile& case_file, const CaseCuts& cuts, const BodySurface& surface) {
  CutRequests r;
  r.incisions = cuts.incisions;
  if (cuts.pattern) {
    try {
      const std::vector<RoundIncision> placed = place_incisions(surface, *cuts.pattern);
      r.incisions.insert(r.incisions.end(), placed.begin(), placed.end());
    } catch (const InputError& e) {
      throw InputError(fmt::format("{}: {}", (case_file.at("incisions") / "place").str(), e.what()));
    }
  }
  r.scalpel_cuts = cuts.scalpel_cuts;
  r.flaps = cuts.flaps;
  return r;
}

CutPlan plan_case_cuts(const CaseFile& case_file, const CaseCuts& cuts, const CutRequests& requests,
                       const BodySurface& surface) {
  CutRequestNames names;
  names.incision = (case_file.at("incisions")).str() + ": incision";
  names.scalpel = (case_file.at("cuts")).str() + ": scalpel cut";
  names.flap = (case_file.at("cuts")).str() + ": flap";
  return plan_cuts(surface, requests, cuts.surface_tolerance_mm, names);
}

}  // namespace cleave
