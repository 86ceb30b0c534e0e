#include "cleave/io/nrrd_volume.hpp"

#include <cmath>
#include <cstdlib>
#include <fmt/format.h>
#include <fstream>
#include <limits>
#include <memory>
#include <string>
#include <string_view>
#include <teem/nrrd.h>

#include "cleave/core/error.hpp"
#include "cleave/core/memory_budget.hpp"
#include "cleave/io/teem_error.hpp"

namespace cleave {
namespace {

struct NrrdDeleter {
  void operator()(Nrrd* n) const { nrrdNuke(n); }
};
struct NrrdIoDeleter {
  void operator()(NrrdIoState* n) const { nrrdIoStateNix(n); }
};
using NrrdPtr = std::unique_ptr<Nrrd, NrrdDeleter>;

constexpr double kDefaultSpacingMm = 1.0;  // NRRD files with neither directions nor spacings

/// Sign flips taking the file's world space to RAS+ (per world axis).
Vec3 flips_to_ras(int space) {
  switch (space) {
    case nrrdSpaceLeftPosteriorSuperior:
    case nrrdSpaceLeftPosteriorSuperiorTime:
    case nrrdSpaceScannerXYZ:
    case nrrdSpaceScannerXYZTime:
      return {-1, -1, 1};
    case nrrdSpaceLeftAnteriorSuperior:
    case nrrdSpaceLeftAnteriorSuperiorTime:
      return {-1, 1, 1};
    default:
      return {1, 1, 1};
  }
}

/// teem also reads PNM, VTK and plain-text tables, and leaks memory on some of their error paths;
/// a .nrrd / .nhdr file must start with the NRRD magic, so anything else is refused before teem.
void require_nrrd_magic(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  char magic[7] = {};
  in.read(magic, sizeof magic);
  if (in.gcount() != sizeof magic || std::string_view(magic, sizeof magic) != "NRRD000")
    throw InputError(fmt::format("{}: not a NRRD file (expected the magic 'NRRD000' at the start)", file.string()));
}

NrrdPtr load(const std::filesystem::path& file, bool header_only) {
  NrrdPtr nrrd(nrrdNew());
  std::unique_ptr<NrrdIoState, NrrdIoDeleter> nio(nrrdIoStateNew());
  nio->skipData = header_only ? AIR_TRUE : AIR_FALSE;
  if (nrrdLoad(nrrd.get(), file.string().c_str(), nio.get()) != 0)
    throw InputError(fmt::format("{}: cannot read NRRD: {}", file.string(), take_teem_error(NRRD)));
  return nrrd;
}

}  // namespace

ImageVolume read_nrrd_volume(const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) throw InputError(fmt::format("{}: no such file", file.string()));
  const std::string f = file.string();
  require_nrrd_magic(file);

  // Header first: check the shape and the memory before teem allocates the data.
  NrrdPtr header = load(file, /*header_only=*/true);
  if (header->type == nrrdTypeBlock)
    throw InputError(fmt::format("{}: sample type 'block' is not a number; expected scalar samples", f));
  std::vector<unsigned> axes;  // the three spatial axes (size-1 extra axis dropped)
  for (unsigned a = 0; a < header->dim; ++a)
    if (header->dim == 3 || header->axis[a].size > 1) axes.push_back(a);
  if (axes.size() != 3)
    throw InputError(fmt::format("{}: has {} axes; expected a 3-D volume", f, header->dim));
  const std::uint64_t samples = checked_sample_count(header->axis[axes[0]].size, header->axis[axes[1]].size,
                                                     header->axis[axes[2]].size, f);
  std::uint64_t bytes = 0;
  if (__builtin_mul_overflow(samples, nrrdTypeSize[header->type] + sizeof(double), &bytes))
    bytes = std::numeric_limits<std::uint64_t>::max();
  require_memory(bytes,
                 fmt::format("{} ({}x{}x{} samples)", f, header->axis[axes[0]].size, header->axis[axes[1]].size,
                             header->axis[axes[2]].size));

  NrrdPtr nrrd = load(file, /*header_only=*/false);
  ImageVolume image;
  image.source = f;
  for (int d = 0; d < 3; ++d) {
    const size_t size = nrrd->axis[axes[static_cast<size_t>(d)]].size;
    if (size > static_cast<size_t>(std::numeric_limits<int>::max()))
      throw InputError(fmt::format("{}: axis {} has {} samples; too many", f, d, size));
    image.dims[d] = static_cast<int>(size);
  }
  const Vec3 flips = flips_to_ras(nrrd->space);
  if (nrrd->spaceDim > 0) {
    if (nrrd->spaceDim != 3)
      throw InputError(fmt::format("{}: space has {} dimensions; expected a 3-D space", f, nrrd->spaceDim));
    for (int d = 0; d < 3; ++d) {
      const NrrdAxisInfo& axis = nrrd->axis[axes[static_cast<size_t>(d)]];
      for (int w = 0; w < 3; ++w) image.index_to_world(w, d) = flips[w] * axis.spaceDirection[w];
      if (!image.index_to_world.col(d).allFinite())
        throw InputError(fmt::format("{}: axis {} has no space direction; expected one per spatial axis", f, d));
    }
    for (int w = 0; w < 3; ++w)
      image.origin_mm[w] = std::isfinite(nrrd->spaceOrigin[w]) ? flips[w] * nrrd->spaceOrigin[w] : 0.0;
  } else {
    for (int d = 0; d < 3; ++d) {
      const double spacing = nrrd->axis[axes[static_cast<size_t>(d)]].spacing;
      image.index_to_world(d, d) = std::isnan(spacing) ? kDefaultSpacingMm : spacing;
    }
  }
  image.integer_samples = nrrd->type != nrrdTypeFloat && nrrd->type != nrrdTypeDouble;
  image.values.resize(static_cast<size_t>(samples));
  auto lookup = nrrdDLookup[nrrd->type];
  for (size_t n = 0; n < image.values.size(); ++n) image.values[n] = lookup(nrrd->data, n);
  check_image_volume(image);
  return image;
}

}  // namespace cleave
