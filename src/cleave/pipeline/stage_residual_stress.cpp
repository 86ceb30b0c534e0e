#include "cleave/pipeline/stages.hpp"

namespace cleave {

// Scaffolding while the residual_stress domain lands: this stage leaves the run context as it is.
void stage_residual_stress(RunContext&) {}

}  // namespace cleave
