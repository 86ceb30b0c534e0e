// libFuzzer target: NIfTI reading (nifticlib) must turn any bytes into a volume or one InputError.
#include "cleave/core/error.hpp"
#include "cleave/io/nifti_volume.hpp"
#include "file_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto file = cleave::fuzz::write_input(data, size, ".nii");
  try {
    (void)cleave::read_nifti_volume(file);
  } catch (const cleave::InputError&) {
  }
  return 0;
}
