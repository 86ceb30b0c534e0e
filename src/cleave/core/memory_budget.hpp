#pragma once
// Refuse work that would not fit in memory before allocating it.
#include <cstdint>
#include <string>

namespace cleave {

/// Bytes of physical memory on this machine (0 if unknown).
std::uint64_t physical_memory_bytes();

/// Throws InputError naming `what` and the bytes it would need when `bytes_needed` exceeds
/// half of the physical memory (the other half stays for solvers and the OS).
void require_memory(std::uint64_t bytes_needed, const std::string& what);

}  // namespace cleave
