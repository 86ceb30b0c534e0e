#include "cleave/io/nrrd_writer.hpp"

#include <fmt/format.h>
#include <memory>
#include <teem/nrrd.h>
#include <unistd.h>

#include "cleave/core/error.hpp"
#include "cleave/io/teem_error.hpp"

namespace cleave {
namespace {

struct NrrdNixer {  // frees the Nrrd struct but not the wrapped data (owned by the LabelVolume)
  void operator()(Nrrd* n) const { nrrdNix(n); }
};
struct NrrdIoDeleter {
  void operator()(NrrdIoState* n) const { nrrdIoStateNix(n); }
};

}  // namespace

void write_nrrd_label_volume(const LabelVolume& volume, const std::filesystem::path& file, NrrdEncoding encoding) {
  const std::string f = file.string();
  const GridSpec& grid = volume.grid;
  if (static_cast<std::int64_t>(volume.labels.size()) != grid.voxel_count())
    throw InputError(fmt::format("{}: the volume holds {} labels for {} voxels", f, volume.labels.size(),
                                 grid.voxel_count()));
  std::unique_ptr<Nrrd, NrrdNixer> nrrd(nrrdNew());
  // teem does not modify the data it writes; its API takes a non-const pointer.
  void* data = const_cast<Label*>(volume.labels.data());
  const auto fail = [&] { throw InputError(fmt::format("{}: cannot write NRRD: {}", f, take_teem_error(NRRD))); };
  if (nrrdWrap_va(nrrd.get(), data, nrrdTypeUChar, 3, static_cast<size_t>(grid.dims.x()),
                  static_cast<size_t>(grid.dims.y()), static_cast<size_t>(grid.dims.z())) != 0)
    fail();
  if (nrrdSpaceSet(nrrd.get(), nrrdSpaceRightAnteriorSuperior) != 0) fail();
  const Vec3 first_centre = grid.voxel_center_mm({0, 0, 0});
  const double origin[3] = {first_centre.x(), first_centre.y(), first_centre.z()};
  if (nrrdSpaceOriginSet(nrrd.get(), origin) != 0) fail();
  for (int a = 0; a < 3; ++a) {
    NrrdAxisInfo& axis = nrrd->axis[a];
    for (int w = 0; w < 3; ++w) axis.spaceDirection[w] = w == a ? grid.cell_size_mm : 0.0;
    axis.kind = nrrdKindSpace;
    axis.center = nrrdCenterCell;
  }
  std::unique_ptr<NrrdIoState, NrrdIoDeleter> nio(nrrdIoStateNew());
  if (nrrdIoStateEncodingSet(nio.get(), encoding == NrrdEncoding::gzip ? nrrdEncodingGzip : nrrdEncodingRaw) != 0) fail();

  std::error_code ec;
  if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path(), ec);
  const std::filesystem::path temporary = file.string() + fmt::format(".tmp-{}", getpid());
  if (nrrdSave(temporary.string().c_str(), nrrd.get(), nio.get()) != 0) {
    std::filesystem::remove(temporary, ec);
    fail();
  }
  std::filesystem::rename(temporary, file, ec);
  if (ec) {
    std::filesystem::remove(temporary, ec);
    throw InputError(fmt::format("{}: cannot write NRRD: {}", f, ec.message()));
  }
}

}  // namespace cleave
