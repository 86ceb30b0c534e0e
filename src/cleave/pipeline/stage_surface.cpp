#include "cleave/pipeline/stages.hpp"

namespace cleave {

// Scaffolding while the surface domain lands: this stage leaves the run context as it is.
void stage_surface(RunContext&) {}

}  // namespace cleave
