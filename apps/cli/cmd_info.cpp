// `cleave info MODEL`: what the model is made of (cells, vertices, links, components, size, memory).
#include <cstdio>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "command_registry.hpp"
#include "model_arguments.hpp"

namespace cleave::cli {
namespace {

struct InfoArguments {
  ModelArguments model;
  bool json = false;
};

int run_info(const InfoArguments& args) {
  const TissueModel m = args.model.load();
  const LinkedVolume& v = m.volume;
  const auto [lo, hi] = m.bounding_box_mm();
  const std::size_t bytes = v.bytes();
  if (args.json) {
    nlohmann::json j = {{"model", m.source},
                        {"cells", v.cell_count()},
                        {"vertices", v.vertex_count()},
                        {"links", v.link_count()},
                        {"components", v.component_count()},
                        {"grid", {v.grid().dims.x(), v.grid().dims.y(), v.grid().dims.z()}},
                        {"cell_size_mm", v.grid().cell_size_mm},
                        {"bounding_box_mm", {{lo.x(), lo.y(), lo.z()}, {hi.x(), hi.y(), hi.z()}}},
                        {"bytes", bytes},
                        {"bytes_per_cell", static_cast<double>(bytes) / v.cell_count()}};
    nlohmann::json labels = nlohmann::json::object();
    for (const auto& [label, material] : m.materials) labels[std::to_string(label)] = material.name;
    j["labels"] = labels;
    std::puts(j.dump(2).c_str());
    return 0;
  }
  fmt::print("model        {}\n", m.source);
  fmt::print("grid         {} x {} x {} cells of {:.4g} mm\n", v.grid().dims.x(), v.grid().dims.y(), v.grid().dims.z(),
             v.grid().cell_size_mm);
  fmt::print("cells        {}\n", v.cell_count());
  fmt::print("vertices     {}\n", v.vertex_count());
  fmt::print("links        {} uncut, {} cut\n", v.link_count(), v.cut_link_count());
  fmt::print("components   {}\n", v.component_count());
  fmt::print("bounding box [{:.2f}, {:.2f}, {:.2f}] - [{:.2f}, {:.2f}, {:.2f}] mm ({:.1f} x {:.1f} x {:.1f} mm)\n", lo.x(),
             lo.y(), lo.z(), hi.x(), hi.y(), hi.z(), hi.x() - lo.x(), hi.y() - lo.y(), hi.z() - lo.z());
  fmt::print("memory       {:.2f} MB ({:.0f} bytes per cell, vertices included)\n", static_cast<double>(bytes) / 1e6,
             static_cast<double>(bytes) / v.cell_count());
  for (const auto& [label, material] : m.materials)
    fmt::print("label {:<6} {} (E = {} kPa, nu = {}, {} kg/m^3)\n", int{label}, material.name, material.youngs_modulus_kPa,
               material.poisson_ratio, material.density_kg_per_m3);
  return 0;
}

const CommandRegistrar kInfo{{"info", 10, [](CLI::App& app) -> std::function<int()> {
                                auto args = std::make_shared<InfoArguments>();
                                auto* cmd = app.add_subcommand("info", "print cells, vertices, links, components, size and memory of a model");
                                args->model.add_to(*cmd, /*model_required=*/true);
                                cmd->add_flag("--json", args->json, "print one JSON object (keys: cells, vertices, components, bytes, ...)");
                                return [args] { return run_info(*args); };
                              }}};

}  // namespace
}  // namespace cleave::cli
