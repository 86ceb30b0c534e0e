#include "progress_bar.hpp"

#include <cstdio>
#include <memory>
#include <unistd.h>

namespace cleave::cli {

ProgressFn stderr_progress(bool quiet) {
  if (quiet) return {};
  const bool tty = ::isatty(STDERR_FILENO) != 0;
  auto last_stage = std::make_shared<std::string>();
  auto last_percent = std::make_shared<int>(-1);
  return [tty, last_stage, last_percent](std::string_view stage, double fraction) {
    const int percent = static_cast<int>(fraction * 100.0 + 0.5);
    if (tty) {
      if (stage == *last_stage && percent == *last_percent) return;
      constexpr int kWidth = 30;
      const int filled = percent * kWidth / 100;
      std::fprintf(stderr, "\r%-32.*s [%.*s%*s] %3d%%", static_cast<int>(stage.size()), stage.data(), filled,
                   "##############################", kWidth - filled, "", percent);
      if (percent >= 100) std::fputc('\n', stderr);
    } else if (stage != *last_stage) {
      std::fprintf(stderr, "%.*s ...\n", static_cast<int>(stage.size()), stage.data());
    }
    std::fflush(stderr);
    *last_stage = std::string(stage);
    *last_percent = percent;
  };
}

}  // namespace cleave::cli
