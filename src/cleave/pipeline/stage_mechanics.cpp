#include "cleave/pipeline/stages.hpp"

namespace cleave {

// Scaffolding while the mechanics domain lands: this stage leaves the run context as it is.
void stage_mechanics(RunContext&) {}

}  // namespace cleave
