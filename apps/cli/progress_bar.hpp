#pragma once
// A one-line progress bar on stderr for long CLI work (only when stderr is a terminal, otherwise
// one line per stage so that logs stay readable).
#include <string>
#include <string_view>

#include "cleave/core/progress.hpp"

namespace cleave::cli {

/// A ProgressFn that draws on stderr. `quiet` disables it.
ProgressFn stderr_progress(bool quiet);

}  // namespace cleave::cli
