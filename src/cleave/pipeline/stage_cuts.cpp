#include "cleave/pipeline/stages.hpp"

namespace cleave {

// Scaffolding while the cuts domain lands: this stage leaves the run context as it is.
void stage_cuts(RunContext&) {}

}  // namespace cleave
