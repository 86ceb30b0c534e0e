// libFuzzer target: NRRD reading (teem) must turn any bytes into a volume or one InputError.
#include "cleave/core/error.hpp"
#include "cleave/io/nrrd_volume.hpp"
#include "file_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto file = cleave::fuzz::write_input(data, size, ".nrrd");
  try {
    (void)cleave::read_nrrd_volume(file);
  } catch (const cleave::InputError&) {
  }
  return 0;
}
