#pragma once
// The case file: one JSON document that describes a whole run (docs/case-format.md).
// This reader validates the sections every run needs (model, materials, output) and keeps the
// document, so that each domain parses its own section (design, residual_stress, cuts, ...)
// with the same error conventions (JsonPath).
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>

#include "cleave/fem/material.hpp"
#include "cleave/io/json_fields.hpp"
#include "cleave/io/model_source.hpp"

namespace cleave {

struct CaseOutput {
  bool vtu = true;            ///< result.vtu (cells, fields)
  bool surface_ply = true;    ///< surface.ply (render surface, deformed)
  bool surface_gltf = true;   ///< surface.gltf
  bool streamlines = true;    ///< streamlines.vtp (Langer direction field)
};

struct CaseFile {
  std::filesystem::path path;     ///< the file it was read from ("" when parsed from text)
  nlohmann::json document;        ///< the whole validated document
  std::string model_source;       ///< built-in name or path (relative paths resolved against the case's folder)
  ModelSourceOptions model_options;
  std::map<Label, Material> materials;
  CaseOutput output;

  /// JsonPath of a top-level section, for domain parsers: case_file.at("design").
  JsonPath at(const std::string& section) const { return JsonPath{path.filename().string(), ""} / section; }
  const nlohmann::json* section(const std::string& name) const { return json_find(document, name); }
};

/// Top-level keys a case may hold; anything else is refused with the list.
inline constexpr const char* kCaseSections[] = {"cleave_case", "model", "materials", "residual_stress", "design",
                                                "incisions", "cuts", "simulation", "output", "description"};

/// Reads and validates a case file. Throws InputError naming the file, JSON path and value.
CaseFile load_case_file(const std::filesystem::path& file);
/// Same, from JSON text (the studio's save/load); `name` appears in error messages.
CaseFile parse_case_text(const std::string& text, const std::string& name, const std::filesystem::path& base_folder);

}  // namespace cleave
