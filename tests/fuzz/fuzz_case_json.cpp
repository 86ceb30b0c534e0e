// libFuzzer target: the case file parser must turn any bytes into a case or one InputError.
#include <cstddef>
#include <cstdint>
#include <string>

#include "cleave/core/error.hpp"
#include "cleave/io/case_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const cleave::CaseFile c = cleave::parse_case_text(text, "fuzz.json", "/nonexistent");
    (void)c;
  } catch (const cleave::InputError&) {
  }
  return 0;
}
