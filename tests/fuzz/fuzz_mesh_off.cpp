// libFuzzer target: .off surface mesh reading must turn any bytes into a mesh or one InputError.
#include "cleave/core/error.hpp"
#include "cleave/io/surface_mesh_file.hpp"
#include "file_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto file = cleave::fuzz::write_input(data, size, ".off");
  try {
    (void)cleave::read_surface_mesh(file, 1.0);
  } catch (const cleave::InputError&) {
  }
  return 0;
}
