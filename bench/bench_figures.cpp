#include "bench_figures.hpp"

#include <fmt/format.h>

#include "cleave/core/error.hpp"

namespace cleave::bench {

std::string_view implementation_key(Implementation implementation) {
  switch (implementation) {
    case Implementation::cleave: return "cleave";
    case Implementation::paper: return "paper";
    case Implementation::eigen_cg: return "eigen_cg";
    case Implementation::cholmod: return "cholmod";
  }
  return "cleave";
}

Implementation implementation_from_key(std::string_view key, std::string_view option) {
  for (Implementation i : {Implementation::cleave, Implementation::paper, Implementation::eigen_cg, Implementation::cholmod})
    if (implementation_key(i) == key) return i;
  throw InputError(fmt::format("{}: unknown implementation '{}'; expected paper, eigen_cg or cholmod", option, key));
}

std::string_view stage_key(Stage stage) {
  switch (stage) {
    case Stage::vector: return "vector";
    case Stage::value: return "value";
    case Stage::value_point: return "value_point";
    case Stage::equilibrate: return "equilibrate";
    case Stage::preview: return "preview";
    case Stage::step: return "step";
    case Stage::step_budget: return "step_budget";
    case Stage::update: return "update";
    case Stage::vector_drag: return "vector_drag";
    case Stage::update_drag: return "update_drag";
    case Stage::update_final: return "update_final";
    case Stage::update_drag_final: return "update_drag_final";
  }
  return "vector";
}

StageFigures& ImplementationFigures::stage(Stage s) {
  switch (s) {
    case Stage::vector: return vector;
    case Stage::value: return value;
    case Stage::value_point: return value_point;
    case Stage::equilibrate: return equilibrate;
    case Stage::preview: return preview;
    case Stage::step: return step;
    case Stage::step_budget: return step_budget;
    case Stage::update: return update;
    case Stage::vector_drag: return vector_drag;
    case Stage::update_drag: return update_drag;
    case Stage::update_final: return update_final;
    case Stage::update_drag_final: return update_drag_final;
  }
  return vector;
}

const StageFigures& ImplementationFigures::stage(Stage s) const {
  return const_cast<ImplementationFigures&>(*this).stage(s);
}

}  // namespace cleave::bench
