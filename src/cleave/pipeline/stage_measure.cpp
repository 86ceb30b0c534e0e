#include "cleave/pipeline/stages.hpp"

namespace cleave {

// Scaffolding while the measure domain lands: this stage leaves the run context as it is.
void stage_measure(RunContext&) {}

}  // namespace cleave
