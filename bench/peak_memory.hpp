#pragma once
// Peak resident memory of this process (the high-water mark of its RSS), for per-model figures.
//
//   reset_peak_resident_memory();          // start a model's measurement from the current RSS
//   ... build and run the model ...
//   double mb = peak_resident_memory_mb();  // MB = 1e6 bytes
//
// Linux: reads VmHWM from /proc/self/status and resets it by writing "5" to
// /proc/self/clear_refs (kernel >= 4.0). Elsewhere, or when /proc is unreadable, falls back to
// getrusage's ru_maxrss, which cannot be reset (the figure is then the peak since start).
namespace cleave::bench {

/// Peak resident set size in MB (1e6 bytes); 0 when the platform reports nothing.
double peak_resident_memory_mb();

/// Lowers the high-water mark to the current RSS. Returns false when the platform cannot.
bool reset_peak_resident_memory();

}  // namespace cleave::bench
