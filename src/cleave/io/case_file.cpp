#include "cleave/io/case_file.hpp"

#include <cmath>
#include <fmt/format.h>
#include <limits>

#include "cleave/core/error.hpp"
#include "cleave/io/atomic_file.hpp"

namespace cleave {
namespace {

constexpr std::uintmax_t kMaxCaseBytes = 64u << 20;

void parse_model(const nlohmann::json& model, const JsonPath& at, const std::filesystem::path& base, CaseFile& out) {
  json_allow_keys(model, at, {"source", "resolution", "cell_size_mm", "labels", "threshold", "mesh_scale"});
  const nlohmann::json* source = json_find(model, "source");
  if (!source) json_missing(at / "source", "a built-in shape name or a path to a volume or mesh");
  out.model_source = json_string(*source, at / "source");
  if (out.model_source.empty()) json_error(at / "source", *source, "a built-in shape name or a path to a volume or mesh");
  const ModelSourceKind kind = classify_model_source(out.model_source);
  if (kind == ModelSourceKind::case_file) json_error(at / "source", *source, "a model, not another case file");
  if (kind != ModelSourceKind::builtin && std::filesystem::path(out.model_source).is_relative())
    out.model_source = (base / out.model_source).lexically_normal().string();

  if (const auto* res = json_find(model, "resolution")) {
    if (!res->is_array() || res->size() != 3) json_error(at / "resolution", *res, "[NX, NY, NZ] (three positive integers)");
    out.model_options.resolution = Vec3i{json_int_in((*res)[0], at / "resolution" / 0, 1, 100000),
                                         json_int_in((*res)[1], at / "resolution" / 1, 1, 100000),
                                         json_int_in((*res)[2], at / "resolution" / 2, 1, 100000)};
  }
  if (const auto* h = json_find(model, "cell_size_mm"))
    out.model_options.cell_size_mm =
        json_number_in(*h, at / "cell_size_mm", 1e-6, 1e6, "a positive cell size in mm");
  if (out.model_options.resolution && out.model_options.cell_size_mm)
    throw InputError(fmt::format("{}: give either resolution or cell_size_mm, not both", at.str()));
  if (const auto* labels = json_find(model, "labels")) {
    if (!labels->is_array()) json_error(at / "labels", *labels, "an array of label numbers");
    for (std::size_t i = 0; i < labels->size(); ++i)
      out.model_options.labels.push_back(json_int_in((*labels)[i], at / "labels" / i, 1, 65535));
  }
  if (const auto* t = json_find(model, "threshold")) out.model_options.threshold = json_number(*t, at / "threshold");
  if (const auto* s = json_find(model, "mesh_scale"))
    out.model_options.mesh_scale = json_number_in(*s, at / "mesh_scale", 1e-9, 1e9, "a positive scale factor");
}

void parse_materials(const nlohmann::json& materials, const JsonPath& at, CaseFile& out) {
  if (!materials.is_object()) json_error(at, materials, "an object mapping label numbers to materials");
  for (const auto& [key, value] : materials.items()) {
    const JsonPath here = at / key;
    int label = 0;
    try {
      std::size_t used = 0;
      label = std::stoi(key, &used);
      if (used != key.size()) label = -1;
    } catch (const std::exception&) {
      label = -1;
    }
    if (label < 1 || label > 255)
      throw InputError(fmt::format("{}: key '{}' is not a label; expected a label number from 1 to 255", at.str(), key));
    json_allow_keys(value, here, {"name", "E_kPa", "nu", "density_kg_per_m3"});
    Material m;
    m.name = "label " + key;
    if (const auto* n = json_find(value, "name")) m.name = json_string(*n, here / "name");
    constexpr double kInf = std::numeric_limits<double>::infinity();
    constexpr double kSmallest = std::numeric_limits<double>::min();
    if (const auto* e = json_find(value, "E_kPa"))
      m.youngs_modulus_kPa = json_number_in(*e, here / "E_kPa", kSmallest, kInf, "a positive Young's modulus in kPa");
    if (const auto* nu = json_find(value, "nu"))
      m.poisson_ratio = json_number_in(*nu, here / "nu", std::nextafter(-1.0, 0.0), std::nextafter(0.5, 0.0),
                                       "a Poisson ratio in (-1, 0.5)");
    if (const auto* d = json_find(value, "density_kg_per_m3"))
      m.density_kg_per_m3 = json_number_in(*d, here / "density_kg_per_m3", kSmallest, kInf, "a positive density in kg/m^3");
    validate_material(m, here.str());
    out.materials[static_cast<Label>(label)] = m;
  }
}

void parse_output(const nlohmann::json& output, const JsonPath& at, CaseOutput& out) {
  json_allow_keys(output, at, {"vtu", "surface_ply", "surface_gltf", "streamlines"});
  if (const auto* v = json_find(output, "vtu")) out.vtu = json_bool(*v, at / "vtu");
  if (const auto* v = json_find(output, "surface_ply")) out.surface_ply = json_bool(*v, at / "surface_ply");
  if (const auto* v = json_find(output, "surface_gltf")) out.surface_gltf = json_bool(*v, at / "surface_gltf");
  if (const auto* v = json_find(output, "streamlines")) out.streamlines = json_bool(*v, at / "streamlines");
}

}  // namespace

CaseFile parse_case_text(const std::string& text, const std::string& name, const std::filesystem::path& base_folder) {
  CaseFile out;
  out.path = name;
  out.document = parse_json_text(text, name);
  const JsonPath root{std::filesystem::path(name).filename().string(), ""};
  if (!out.document.is_object()) json_error(root, out.document, "a JSON object with at least a \"model\" section");
  for (const auto& [key, value] : out.document.items()) {
    bool known = false;
    for (const char* s : kCaseSections) known = known || key == s;
    if (!known)
      throw InputError(fmt::format("{} has unknown section '{}'; expected one of: {}", root.str(), key,
                                   fmt::join(kCaseSections, ", ")));
  }
  parse_model(json_object(out.document, "model", root), root / "model", base_folder, out);
  if (const auto* m = out.section("materials")) parse_materials(*m, root / "materials", out);
  if (const auto* o = out.section("output")) parse_output(*o, root / "output", out.output);
  return out;
}

CaseFile load_case_file(const std::filesystem::path& file) {
  const std::string text = read_file(file, kMaxCaseBytes);
  CaseFile c = parse_case_text(text, file.string(), file.has_parent_path() ? file.parent_path() : ".");
  c.path = file;
  return c;
}

}  // namespace cleave
