#include "peak_memory.hpp"

#include <sys/resource.h>

#include <fstream>
#include <sstream>
#include <string>

namespace cleave::bench {
namespace {

constexpr double kBytesPerKibibyte = 1024.0;
constexpr double kBytesPerMegabyte = 1e6;

/// VmHWM in kB from /proc/self/status, or a negative number when absent.
double vm_hwm_kB() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmHWM:", 0) != 0) continue;
    std::istringstream fields(line.substr(6));
    double kB = -1;
    fields >> kB;
    return kB;
  }
  return -1;
}

}  // namespace

double peak_resident_memory_mb() {
  const double kB = vm_hwm_kB();
  if (kB >= 0) return kB * kBytesPerKibibyte / kBytesPerMegabyte;
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0;
  return static_cast<double>(usage.ru_maxrss) * kBytesPerKibibyte / kBytesPerMegabyte;  // ru_maxrss is in KiB on Linux
}

bool reset_peak_resident_memory() {
  std::ofstream clear_refs("/proc/self/clear_refs");
  if (!clear_refs) return false;
  clear_refs << "5";
  return static_cast<bool>(clear_refs.flush());
}

}  // namespace cleave::bench
