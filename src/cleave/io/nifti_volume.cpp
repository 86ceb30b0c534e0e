#include "cleave/io/nifti_volume.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fmt/format.h>
#include <limits>
#include <memory>
#include <nifti2_io.h>

#include "cleave/core/error.hpp"
#include "cleave/core/memory_budget.hpp"

namespace cleave {
namespace {

struct NiftiDeleter {
  void operator()(nifti_image* n) const { nifti_image_free(n); }
};
using NiftiPtr = std::unique_ptr<nifti_image, NiftiDeleter>;

constexpr double kMetresToMm = 1000.0;
constexpr double kMicronsToMm = 0.001;

double unit_to_mm(int xyz_units) {
  switch (xyz_units) {
    case NIFTI_UNITS_METER: return kMetresToMm;
    case NIFTI_UNITS_MICRON: return kMicronsToMm;
    default: return 1.0;  // mm, or unknown (taken as mm, as most tools do)
  }
}

constexpr std::int64_t kMaxNiftiDims = 7;  // dim[0]: the number of dimensions, 1 to 7

/// The header field as nifticlib will see it: byte-swapped when the header's size is stored in
/// the other byte order.
template <typename T>
T in_file_order(T value, bool swapped) {
  if (!swapped) return value;
  T out;
  auto* dst = reinterpret_cast<unsigned char*>(&out);
  const auto* src = reinterpret_cast<const unsigned char*>(&value);
  for (std::size_t i = 0; i < sizeof(T); ++i) dst[i] = src[sizeof(T) - 1 - i];
  return out;
}

/// Raw pixdim[1..3] of the header on disk (nifticlib replaces a zero pixdim by 1 when it builds
/// the image, which would hide a broken file). Also refuses a dim[0] outside 1..7 before
/// nifti_image_read sees it: nifticlib copies dim[1..dim[0]] into a fixed array of 8 (a
/// NIfTI-2 header with dim[0] = 2^32 + 3 overflowed its stack; found by fuzz_nifti). The header
/// comes as stored; nifticlib swaps it when sizeof_hdr is stored in the other byte order, so
/// dim[0] is judged in that order too (a byte-swapped NIfTI-2 header whose dim[0] read 1 as
/// stored and 2^56 swapped overflowed the same array; found by the 2 h fuzz_nifti run).
Vec3 raw_pixdims(const std::string& f) {
  int version = 0;
  void* header = nifti_read_header(f.c_str(), &version, /*check=*/1);
  if (header == nullptr)
    throw InputError(fmt::format("{}: not a readable NIfTI-1/NIfTI-2 file (missing, truncated or malformed header)", f));
  Vec3 pixdim;
  std::int64_t dimensions = 0;
  std::int64_t header_size = 0;
  const std::int64_t expected_size = version == 2 ? 540 : 348;
  bool swapped = false;
  if (version == 2) {
    const auto* h = static_cast<const nifti_2_header*>(header);
    swapped = h->sizeof_hdr != expected_size && in_file_order(h->sizeof_hdr, true) == expected_size;
    header_size = in_file_order(h->sizeof_hdr, swapped);
    for (int a = 0; a < 3; ++a) pixdim[a] = in_file_order(h->pixdim[a + 1], swapped);
    dimensions = in_file_order(h->dim[0], swapped);
  } else {
    const auto* h = static_cast<const nifti_1_header*>(header);
    swapped = h->sizeof_hdr != expected_size && in_file_order(h->sizeof_hdr, true) == expected_size;
    header_size = in_file_order(h->sizeof_hdr, swapped);
    for (int a = 0; a < 3; ++a) pixdim[a] = static_cast<double>(in_file_order(h->pixdim[a + 1], swapped));
    dimensions = in_file_order(h->dim[0], swapped);
  }
  std::free(header);
  if (header_size != expected_size)
    throw InputError(fmt::format("{}: header size (sizeof_hdr) is {}; expected {} for NIfTI-{}", f, header_size,
                                 expected_size, version == 2 ? 2 : 1));
  if (dimensions < 1 || dimensions > kMaxNiftiDims)
    throw InputError(fmt::format("{}: header dim[0] is {}; expected 1 to 7 dimensions", f, dimensions));
  return pixdim;
}

/// Reads sample n of `nim` as a double (integer and real scalar types).
double sample(const nifti_image& nim, size_t n) {
  const void* d = nim.data;
  switch (nim.datatype) {
    case DT_UINT8: return static_cast<const std::uint8_t*>(d)[n];
    case DT_INT8: return static_cast<const std::int8_t*>(d)[n];
    case DT_UINT16: return static_cast<const std::uint16_t*>(d)[n];
    case DT_INT16: return static_cast<const std::int16_t*>(d)[n];
    case DT_UINT32: return static_cast<const std::uint32_t*>(d)[n];
    case DT_INT32: return static_cast<const std::int32_t*>(d)[n];
    case DT_UINT64: return static_cast<double>(static_cast<const std::uint64_t*>(d)[n]);
    case DT_INT64: return static_cast<double>(static_cast<const std::int64_t*>(d)[n]);
    case DT_FLOAT32: return static_cast<double>(static_cast<const float*>(d)[n]);
    case DT_FLOAT64: return static_cast<const double*>(d)[n];
    default: return 0.0;  // rejected before reading
  }
}

bool is_scalar_type(int datatype) {
  switch (datatype) {
    case DT_UINT8: case DT_INT8: case DT_UINT16: case DT_INT16: case DT_UINT32: case DT_INT32:
    case DT_UINT64: case DT_INT64: case DT_FLOAT32: case DT_FLOAT64:
      return true;
    default:
      return false;
  }
}

/// The most sample bytes the image's data file can hold: its size past the data offset, or for a
/// gzip-compressed file 1032 times its size (the largest ratio deflate reaches).
std::uint64_t readable_sample_bytes(const nifti_image& nim, const std::string& header_file) {
  const std::string data_file = nim.iname != nullptr ? nim.iname : header_file;
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(data_file, ec);
  if (ec) return 0;
  constexpr std::uint64_t kDeflateMaxRatio = 1032;
  if (nifti_is_gzfile(data_file.c_str()) != 0) return kDeflateMaxRatio * static_cast<std::uint64_t>(size);
  const auto offset = static_cast<std::uint64_t>(std::max<std::int64_t>(nim.iname_offset, 0));
  return size > offset ? static_cast<std::uint64_t>(size) - offset : 0;
}

}  // namespace

ImageVolume read_nifti_volume(const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) throw InputError(fmt::format("{}: no such file", file.string()));
  const std::string f = file.string();
  nifti_set_debug_level(0);  // nifticlib prints to stderr otherwise; errors are reported here

  const Vec3 pixdim = raw_pixdims(f);
  NiftiPtr nim(nifti_image_read(f.c_str(), /*read_data=*/0));
  if (!nim) throw InputError(fmt::format("{}: not a readable NIfTI-1/NIfTI-2 file (malformed header)", f));
  if (!is_scalar_type(nim->datatype))
    throw InputError(fmt::format("{}: sample type {} is not a scalar number; expected integer or real samples", f,
                                 nifti_datatype_string(nim->datatype)));
  // nt..nw may be anything a corrupt header declares: compare them one by one (their product
  // can overflow).
  for (const auto extra : {nim->nt, nim->nu, nim->nv, nim->nw})
    if (extra > 1)
      throw InputError(fmt::format("{}: holds {}x{}x{}x{} volumes; expected a single 3-D volume", f, nim->nt, nim->nu,
                                   nim->nv, nim->nw));
  if (nim->nx <= 0 || nim->ny <= 0 || nim->nz <= 0 || nim->nx > std::numeric_limits<int>::max() ||
      nim->ny > std::numeric_limits<int>::max() || nim->nz > std::numeric_limits<int>::max())
    throw InputError(fmt::format("{}: image size {}x{}x{}; expected 1 to 2^31 samples along each axis", f, nim->nx,
                                 nim->ny, nim->nz));
  const std::uint64_t samples =
      checked_sample_count(static_cast<std::uint64_t>(nim->nx), static_cast<std::uint64_t>(nim->ny),
                           static_cast<std::uint64_t>(nim->nz), f);
  std::uint64_t bytes = 0;
  if (__builtin_mul_overflow(samples, static_cast<std::uint64_t>(nim->nbyper) + sizeof(double), &bytes))
    bytes = std::numeric_limits<std::uint64_t>::max();
  require_memory(bytes,
                 fmt::format("{} ({}x{}x{} samples)", f, nim->nx, nim->ny, nim->nz));

  ImageVolume image;
  image.source = f;
  image.dims = {static_cast<int>(nim->nx), static_cast<int>(nim->ny), static_cast<int>(nim->nz)};
  const double to_mm = unit_to_mm(nim->xyz_units);
  if (nim->sform_code > 0) {
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) image.index_to_world(r, c) = to_mm * nim->sto_xyz.m[r][c];
      image.origin_mm[r] = to_mm * nim->sto_xyz.m[r][3];
    }
  } else {
    for (int a = 0; a < 3; ++a)
      if (!(pixdim[a] > 0) || !std::isfinite(pixdim[a]))
        throw InputError(fmt::format("{}: spacing of axis {} (pixdim[{}]) is {} mm; expected a positive spacing", f, a,
                                     a + 1, pixdim[a]));
    if (nim->qform_code > 0) {
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) image.index_to_world(r, c) = to_mm * nim->qto_xyz.m[r][c];
        image.origin_mm[r] = to_mm * nim->qto_xyz.m[r][3];
      }
    } else {
      image.index_to_world = (to_mm * pixdim).asDiagonal();
    }
  }
  image.integer_samples = nim->datatype != DT_FLOAT32 && nim->datatype != DT_FLOAT64;

  // Before nifticlib allocates the declared samples: a file cannot hold more than its size (past
  // the data offset), or, gzip-compressed, more than deflate's largest ratio (1032:1) of its size.
  // A 348-byte header declaring 5.7 GB of samples made nifti_image_load allocate them (fuzz_nifti).
  const std::uint64_t data_bytes = samples * static_cast<std::uint64_t>(nim->nbyper);
  if (data_bytes > readable_sample_bytes(*nim, f))
    throw InputError(fmt::format("{}: the image data is truncated or unreadable (expected {} bytes of samples)", f, data_bytes));
  if (nifti_image_load(nim.get()) != 0 || nim->data == nullptr)
    throw InputError(fmt::format("{}: the image data is truncated or unreadable (expected {} bytes of samples)", f,
                                 samples * static_cast<std::uint64_t>(nim->nbyper)));
  const bool scaled = nim->scl_slope != 0.0 && std::isfinite(nim->scl_slope) && std::isfinite(nim->scl_inter) &&
                      !(nim->scl_slope == 1.0 && nim->scl_inter == 0.0);
  if (scaled && (nim->scl_slope != std::round(nim->scl_slope) || nim->scl_inter != std::round(nim->scl_inter)))
    image.integer_samples = false;
  image.values.resize(static_cast<size_t>(samples));
  for (size_t n = 0; n < image.values.size(); ++n) {
    const double raw = sample(*nim, n);
    image.values[n] = scaled ? nim->scl_slope * raw + nim->scl_inter : raw;
  }
  check_image_volume(image);
  return image;
}

}  // namespace cleave
