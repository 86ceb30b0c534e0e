// Segmentation and intensity volumes: NRRD round trips, NIfTI orientation (sform, qform, flipped
// and permuted axes give the same world-space mask), LPS to RAS, resampling to a chosen cell
// size, label selection and thresholds.
#include <cstring>
#include <fstream>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nifti2_io.h>
#include <numbers>

#include "cleave/core/error.hpp"
#include "cleave/io/image_label_selection.hpp"
#include "cleave/io/model_source.hpp"
#include "cleave/io/nifti_volume.hpp"
#include "cleave/io/nrrd_volume.hpp"
#include "cleave/io/nrrd_writer.hpp"
#include "cleave/io/volume_resample.hpp"
#include "io_fixtures.hpp"

namespace cleave {
namespace {

using test::TempFolder;
using ::testing::HasSubstr;

using test::input_error_of;

/// Writes a NIfTI file with nifticlib: samples[i + nx (j + ny k)] with the given voxel-to-world
/// map (sform when `use_qform` is false, else qform via quaternion; the other code is 0).
enum class NiftiGeometry { sform, qform };
template <typename T>
void write_nifti(const std::filesystem::path& file, const Vec3i& dims, int datatype, const std::vector<T>& samples,
                 const Mat3& index_to_world, const Vec3& origin, NiftiGeometry geometry) {
  const int64_t nifti_dims[8] = {3, dims.x(), dims.y(), dims.z(), 1, 1, 1, 1};
  nifti_image* nim = nifti_make_new_nim(nifti_dims, datatype, 1);
  ASSERT_NE(nim, nullptr);
  ASSERT_EQ(static_cast<size_t>(nim->nbyper), sizeof(T));
  std::memcpy(nim->data, samples.data(), samples.size() * sizeof(T));
  nifti_dmat44 m{};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m.m[r][c] = index_to_world(r, c);
    m.m[r][3] = origin[r];
  }
  m.m[3][3] = 1;
  const Vec3 spacing = index_to_world.colwise().norm().transpose();
  for (int a = 0; a < 3; ++a) nim->pixdim[a + 1] = spacing[a];
  nim->dx = spacing.x();
  nim->dy = spacing.y();
  nim->dz = spacing.z();
  nim->xyz_units = NIFTI_UNITS_MM;
  if (geometry == NiftiGeometry::sform) {
    nim->sform_code = NIFTI_XFORM_SCANNER_ANAT;
    nim->sto_xyz = m;
    nim->qform_code = 0;
  } else {
    nim->sform_code = 0;
    nim->qform_code = NIFTI_XFORM_SCANNER_ANAT;
    double dx, dy, dz;
    nifti_dmat44_to_quatern(m, &nim->quatern_b, &nim->quatern_c, &nim->quatern_d, &nim->qoffset_x, &nim->qoffset_y,
                            &nim->qoffset_z, &dx, &dy, &dz, &nim->qfac);
  }
  ASSERT_EQ(nifti_set_filenames(nim, file.string().c_str(), 0, 1), 0);
  nifti_image_write(nim);
  nifti_image_free(nim);
  ASSERT_TRUE(std::filesystem::exists(file)) << file;
}

/// An asymmetric world-space shape (mm), so that any flip or axis swap would show.
bool in_shape(const Vec3& p) {
  const bool box = p.x() > -10 && p.x() < 14 && p.y() > -6 && p.y() < 8 && p.z() > -4 && p.z() < 6;
  const bool bump = p.x() > 6 && p.x() < 14 && p.y() > 8 && p.y() < 12 && p.z() > 0 && p.z() < 6;
  return box || bump;
}

/// Samples in_shape at every sample centre of an image with this geometry.
std::vector<std::uint8_t> sample_shape(const Vec3i& dims, const Mat3& index_to_world, const Vec3& origin) {
  std::vector<std::uint8_t> samples;
  for (int k = 0; k < dims.z(); ++k)
    for (int j = 0; j < dims.y(); ++j)
      for (int i = 0; i < dims.x(); ++i)
        samples.push_back(in_shape(origin + index_to_world * Vec3(i, j, k)) ? 3 : 0);
  return samples;
}

// NIfTI-1 stores its geometry as 32-bit floats: positions of tens of mm agree to ~1e-6 mm.
constexpr double kFloatGeometryToleranceMm = 1e-5;

void expect_same_volume(const LabelVolume& a, const LabelVolume& b) {
  EXPECT_EQ(a.grid.dims, b.grid.dims);
  EXPECT_NEAR((a.grid.origin_mm - b.grid.origin_mm).norm(), 0.0, kFloatGeometryToleranceMm);
  EXPECT_NEAR(a.grid.cell_size_mm, b.grid.cell_size_mm, kFloatGeometryToleranceMm);
  EXPECT_EQ(a.labels, b.labels);
}

// ---------------------------------------------------------------------------------------------
// NRRD

LabelVolume patterned_volume(const Vec3i& dims, double h, const Vec3& origin) {
  GridSpec grid;
  grid.dims = dims;
  grid.cell_size_mm = h;
  grid.origin_mm = origin;
  LabelVolume v = make_empty_label_volume(grid, false);
  for (int z = 0; z < dims.z(); ++z)
    for (int y = 0; y < dims.y(); ++y)
      for (int x = 0; x < dims.x(); ++x)
        v.labels[static_cast<size_t>(grid.voxel_index({x, y, z}))] = static_cast<Label>((x * 7 + y * 3 + z) % 4);
  return v;
}

TEST(NrrdRoundTrip, WriteThenReadGivesTheSameLabelsSpacingAndOrigin) {
  for (NrrdEncoding encoding : {NrrdEncoding::raw, NrrdEncoding::gzip}) {
    TempFolder tmp;
    // Every face of this volume holds labelled voxels, so the mask's bounding box is the grid.
    const LabelVolume written = patterned_volume({9, 6, 5}, 2.5, {-31.25, 12.5, 0.75});
    const auto file = tmp / "labels.nrrd";
    write_nrrd_label_volume(written, file, encoding);
    const ImageVolume image = read_nrrd_volume(file);
    EXPECT_EQ(image.dims, written.grid.dims);
    EXPECT_TRUE(image.index_to_world.isApprox(2.5 * Mat3::Identity()));
    EXPECT_NEAR((image.origin_mm - written.grid.voxel_center_mm({0, 0, 0})).norm(), 0.0, 1e-12);
    const LabelVolume read = load_model_source(file.string(), {});
    expect_same_volume(read, written);
  }
}

TEST(NrrdRoundTrip, AMaskSmallerThanTheImageIsCroppedAtTheSameWorldPositions) {
  TempFolder tmp;
  LabelVolume written = patterned_volume({12, 10, 8}, 1.5, {4, -7, 2});
  for (int z = 0; z < 8; ++z)
    for (int y = 0; y < 10; ++y)
      for (int x = 0; x < 12; ++x)
        if (x < 2 || y > 7 || z == 0) written.labels[static_cast<size_t>(written.grid.voxel_index({x, y, z}))] = 0;
  const auto file = tmp / "cropped.nrrd";
  write_nrrd_label_volume(written, file);
  const LabelVolume read = load_model_source(file.string(), {});
  EXPECT_EQ(read.inside_count(), written.inside_count());
  for (int z = 0; z < read.grid.dims.z(); ++z)
    for (int y = 0; y < read.grid.dims.y(); ++y)
      for (int x = 0; x < read.grid.dims.x(); ++x) {
        const Vec3 centre = read.grid.voxel_center_mm({x, y, z});
        EXPECT_EQ(read.at({x, y, z}), written.at(written.grid.voxel_of(centre))) << centre.transpose();
      }
}

TEST(NrrdVolume, LpsSpaceIsConvertedToRas) {
  TempFolder tmp;
  const auto file = tmp / "lps.nrrd";
  const Mat3 directions = Vec3(2.0, 3.0, 4.0).asDiagonal();
  test::write_bytes(file, test::nrrd_header({2, 2, 2}, "left-posterior-superior", directions, {10, 20, 30}) +
                              std::string(8, '\1'));
  const ImageVolume image = read_nrrd_volume(file);
  EXPECT_TRUE(image.origin_mm.isApprox(Vec3(-10, -20, 30)));
  EXPECT_TRUE(image.index_to_world.isApprox(Mat3(Vec3(-2.0, -3.0, 4.0).asDiagonal())));
}

TEST(NrrdVolume, DetachedHeaderWithGzipData) {
  TempFolder tmp;
  const LabelVolume written = patterned_volume({4, 3, 2}, 2.0, {0, 0, 0});
  write_nrrd_label_volume(written, tmp / "attached.nrrd", NrrdEncoding::raw);
  // Split the attached file into a .nhdr header and a raw data file it names.
  const std::string attached = test::read_bytes(tmp / "attached.nrrd");
  const size_t end = attached.find("\n\n");
  ASSERT_NE(end, std::string::npos);
  test::write_bytes(tmp / "labels.nhdr", attached.substr(0, end + 1) + "data file: labels.raw\n");
  test::write_bytes(tmp / "labels.raw", attached.substr(end + 2));
  expect_same_volume(load_model_source((tmp / "labels.nhdr").string(), {}), written);
}

// ---------------------------------------------------------------------------------------------
// NIfTI orientation: the same world-space shape stored with different axis orders and flips.

TEST(NiftiVolume, FlippedAndPermutedAxesGiveTheSameWorldSpaceMask) {
  TempFolder tmp;
  const double h = 2.0;
  // Reference: axis-aligned, sample centres on the odd-mm lattice.
  const Vec3i dims_a{16, 12, 8};
  const Mat3 plain = h * Mat3::Identity();
  const Vec3 origin_a{-15, -9, -7};
  write_nifti(tmp / "plain.nii", dims_a, DT_UINT8, sample_shape(dims_a, plain, origin_a), plain, origin_a,
              NiftiGeometry::sform);
  // Permuted and flipped (sform, determinant -1): i runs along -z, j along +x, k along -y.
  Mat3 permuted = Mat3::Zero();
  permuted(2, 0) = -h;
  permuted(0, 1) = h;
  permuted(1, 2) = -h;
  const Vec3i dims_b{8, 16, 12};
  const Vec3 origin_b{-15, 13, 7};
  write_nifti(tmp / "permuted.nii.gz", dims_b, DT_UINT8, sample_shape(dims_b, permuted, origin_b), permuted, origin_b,
              NiftiGeometry::sform);
  // A proper rotation stored as a qform quaternion: i along +y, j along -x, k along +z.
  Mat3 rotated = Mat3::Zero();
  rotated(1, 0) = h;
  rotated(0, 1) = -h;
  rotated(2, 2) = h;
  const Vec3i dims_c{12, 16, 8};
  const Vec3 origin_c{15, -9, -7};
  write_nifti(tmp / "rotated.nii", dims_c, DT_UINT8, sample_shape(dims_c, rotated, origin_c), rotated, origin_c,
              NiftiGeometry::qform);

  const LabelVolume a = load_model_source((tmp / "plain.nii").string(), {});
  const LabelVolume b = load_model_source((tmp / "permuted.nii.gz").string(), {});
  const LabelVolume c = load_model_source((tmp / "rotated.nii").string(), {});
  EXPECT_GT(a.inside_count(), 200);
  expect_same_volume(b, a);
  expect_same_volume(c, a);
  // The reference's grid is the shape's bounding box in mm: x in (-10, 14) -> samples -9..13.
  EXPECT_NEAR(a.grid.origin_mm.x(), -10.0, 1e-9);
  EXPECT_NEAR(a.grid.origin_mm.y(), -6.0, 1e-9);
  EXPECT_NEAR(a.grid.origin_mm.z(), -4.0, 1e-9);
  EXPECT_EQ(a.grid.dims, Vec3i(12, 9, 5));
  for (int z = 0; z < a.grid.dims.z(); ++z)
    for (int y = 0; y < a.grid.dims.y(); ++y)
      for (int x = 0; x < a.grid.dims.x(); ++x)
        EXPECT_EQ(a.at({x, y, z}) != 0, in_shape(a.grid.voxel_center_mm({x, y, z})));
}

TEST(NiftiVolume, ScaledIntensitiesAndThreshold) {
  TempFolder tmp;
  const Vec3i dims{10, 10, 10};
  std::vector<std::int16_t> samples;
  for (int k = 0; k < 10; ++k)
    for (int j = 0; j < 10; ++j)
      for (int i = 0; i < 10; ++i) samples.push_back(static_cast<std::int16_t>(10 * i));
  write_nifti(tmp / "ramp.nii", dims, DT_INT16, samples, Mat3::Identity(), {0, 0, 0}, NiftiGeometry::sform);
  ModelSourceOptions options;
  options.threshold = 45.0;
  const LabelVolume v = load_model_source((tmp / "ramp.nii").string(), options);
  // Samples i = 5..9 have values 50..90 >= 45: a 5 x 10 x 10 block of label 1.
  EXPECT_EQ(v.grid.dims, Vec3i(5, 10, 10));
  EXPECT_EQ(v.inside_count(), 500);
  EXPECT_NEAR(v.grid.origin_mm.x(), 4.5, 1e-12);
  for (Label l : v.labels) EXPECT_EQ(l, 1);
}

/// A minimal single-file NIfTI-1 (4 x 3 x 2 uint8 samples 0..23, pixdim 1.5 / 2 / 2.5 mm, no
/// sform or qform) written field by field in the given byte order.
void write_raw_nifti1(const std::filesystem::path& file, bool big_endian) {
  std::vector<unsigned char> bytes(352 + 24, 0);
  const auto put = [&](std::size_t offset, const auto value) {
    unsigned char raw[sizeof(value)];
    std::memcpy(raw, &value, sizeof(value));
    for (std::size_t i = 0; i < sizeof(value); ++i) bytes[offset + i] = raw[big_endian ? sizeof(value) - 1 - i : i];
  };
  put(0, std::int32_t{348});
  const std::int16_t dims[8] = {3, 4, 3, 2, 1, 1, 1, 1};
  for (int i = 0; i < 8; ++i) put(40 + 2 * static_cast<std::size_t>(i), dims[i]);
  put(70, std::int16_t{DT_UINT8});
  put(72, std::int16_t{8});
  const float pixdim[8] = {1.0f, 1.5f, 2.0f, 2.5f, 1.0f, 1.0f, 1.0f, 1.0f};
  for (int i = 0; i < 8; ++i) put(76 + 4 * static_cast<std::size_t>(i), pixdim[i]);
  put(108, 352.0f);  // vox_offset
  bytes[123] = NIFTI_UNITS_MM;
  std::memcpy(bytes.data() + 344, "n+1", 4);
  for (int i = 0; i < 24; ++i) bytes[352 + static_cast<std::size_t>(i)] = static_cast<unsigned char>(i);
  std::ofstream(file, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

TEST(NiftiVolume, BigEndianFileReadsLikeItsLittleEndianTwin) {
  // nifticlib swaps a header whose sizeof_hdr is stored in the other byte order; cleave's own
  // header checks (dim[0], pixdim) must read it the same way (they refused such files with
  // "dim[0] is 768" before).
  TempFolder tmp;
  write_raw_nifti1(tmp / "little.nii", false);
  write_raw_nifti1(tmp / "big.nii", true);
  const ImageVolume little = read_nifti_volume(tmp / "little.nii");
  const ImageVolume big = read_nifti_volume(tmp / "big.nii");
  EXPECT_EQ(little.dims, Vec3i(4, 3, 2));
  EXPECT_EQ(big.dims, little.dims);
  EXPECT_EQ(big.index_to_world, little.index_to_world);
  EXPECT_EQ(little.index_to_world.diagonal(), Vec3(1.5, 2.0, 2.5));
  EXPECT_EQ(big.values, little.values);
  EXPECT_EQ(little.values.back(), 23.0);
}

// ---------------------------------------------------------------------------------------------
// Resampling and selection

ImageVolume sphere_image(double radius_mm, const Vec3& spacing) {
  ImageVolume image;
  image.source = "sphere";
  image.dims = (Vec3::Constant(2.4 * radius_mm).cwiseQuotient(spacing)).cast<int>();
  image.index_to_world = spacing.asDiagonal();
  image.origin_mm = -0.5 * image.index_to_world * (image.dims - Vec3i::Ones()).cast<double>();
  for (int k = 0; k < image.dims.z(); ++k)
    for (int j = 0; j < image.dims.y(); ++j)
      for (int i = 0; i < image.dims.x(); ++i)
        image.values.push_back((image.origin_mm + image.index_to_world * Vec3(i, j, k)).norm() < radius_mm ? 1.0 : 0.0);
  return image;
}

TEST(VolumeResample, ChosenCellSizeKeepsTheVolumeAndGivesSubCellSurfaceDistances) {
  const double radius = 20.0, h = 2.5;
  const ImageVolume image = sphere_image(radius, Vec3::Constant(0.5));
  const LabelVolume v = resample_image_labels(image, select_image_labels(image, {}), {h, {}});
  EXPECT_DOUBLE_EQ(v.grid.cell_size_mm, h);
  // Bounding box of the sample voxels: 2 * 20 mm = 40 mm -> 16 cells of 2.5 mm.
  EXPECT_EQ(v.grid.dims, Vec3i::Constant(16));
  const double volume = static_cast<double>(v.inside_count()) * h * h * h;
  EXPECT_NEAR(volume / (4.0 / 3.0 * std::numbers::pi * radius * radius * radius), 1.0, 0.03);
  // Box-filtered occupancy gives d = signed distance near the surface (sub-cell accuracy).
  double worst = 0;
  for (int z = 0; z <= v.grid.dims.z(); ++z)
    for (int y = 0; y <= v.grid.dims.y(); ++y)
      for (int x = 0; x <= v.grid.dims.x(); ++x) {
        const double exact = v.grid.corner_position_mm({x, y, z}).norm() - radius;
        if (std::abs(exact) > 0.3 * h) continue;
        const auto d = static_cast<double>(v.corner_distance_mm[static_cast<size_t>(v.grid.corner_index({x, y, z}))]);
        worst = std::max(worst, std::abs(d - exact));
      }
  EXPECT_LT(worst, 0.2 * h);
}

TEST(VolumeResample, DefaultCellSizeIsTheLargestSpacing) {
  const ImageVolume image = sphere_image(10.0, {1.0, 1.5, 0.75});
  const LabelVolume v = resample_image_labels(image, select_image_labels(image, {}), {});
  EXPECT_DOUBLE_EQ(v.grid.cell_size_mm, 1.5);
}

ImageVolume three_label_image() {
  ImageVolume image;
  image.source = "seg.nii";
  image.dims = {6, 2, 2};
  for (int n = 0; n < 4; ++n)
    for (double v : {0.0, 1.0, 1.0, 2.0, 5.0, 5.0}) image.values.push_back(v);
  return image;
}

TEST(ImageLabelSelection, KeepsOnlyTheSelectedLabelsWithTheirValues) {
  const ImageVolume image = three_label_image();
  const std::vector<Label> all = select_image_labels(image, {});
  EXPECT_EQ(std::count(all.begin(), all.end(), 1), 8);
  EXPECT_EQ(std::count(all.begin(), all.end(), 2), 4);
  EXPECT_EQ(std::count(all.begin(), all.end(), 5), 8);
  const std::vector<Label> kept = select_image_labels(image, {{2, 5}, std::nullopt});
  EXPECT_EQ(std::count(kept.begin(), kept.end(), 0), 12);
  EXPECT_EQ(std::count(kept.begin(), kept.end(), 2), 4);
  EXPECT_EQ(std::count(kept.begin(), kept.end(), 5), 8);
  const LabelVolume v = resample_image_labels(image, kept, {});
  EXPECT_EQ(v.grid.dims, Vec3i(3, 2, 2)) << "cropped to the selected labels (x = 3..5)";
  EXPECT_EQ(v.at({0, 0, 0}), 2);
  EXPECT_EQ(v.at({2, 1, 1}), 5);
}

TEST(ImageLabelSelection, AbsentLabelNamesItAndListsThePresentOnes) {
  EXPECT_EQ(input_error_of([] { select_image_labels(three_label_image(), {{2, 7}, std::nullopt}); }),
            "seg.nii: label 7 is absent; labels present: 1, 2, 5");
}

TEST(ImageLabelSelection, LabelsAbove255AreRefusedNotRemapped) {
  ImageVolume image = three_label_image();
  image.values[3] = 300;
  EXPECT_EQ(input_error_of([&] { select_image_labels(image, {}); }),
            "seg.nii: label 300 does not fit cleave's tissue labels 1..255; select labels in that range (--label) "
            "or give a threshold (--threshold)");
  EXPECT_EQ(select_image_labels(image, {{5}, std::nullopt})[4], 5) << "selecting labels <= 255 still works";
}

TEST(ImageLabelSelection, NonIntegerValuesNeedAThreshold) {
  ImageVolume image = three_label_image();
  image.values[2] = 0.37;
  EXPECT_EQ(input_error_of([&] { select_image_labels(image, {}); }),
            "seg.nii: sample 2 has the non-integer value 0.37, so this is an intensity image, not a label image; "
            "give a threshold (--threshold) to select the inside");
  const std::vector<Label> thresholded = select_image_labels(image, {{}, 1.5});
  EXPECT_EQ(std::count(thresholded.begin(), thresholded.end(), 1), 12);
}

TEST(ImageLabelSelection, EmptyMasks) {
  ImageVolume image = three_label_image();
  EXPECT_EQ(input_error_of([&] { select_image_labels(image, {{}, 6.0}); }),
            "seg.nii: the mask is empty: no sample is >= the threshold 6 (values range from 0 to 5)");
  std::fill(image.values.begin(), image.values.end(), 0.0);
  EXPECT_EQ(input_error_of([&] { select_image_labels(image, {}); }), "seg.nii: the mask is empty: every sample is 0");
}

TEST(ImageLabelSelection, LabelsAndThresholdExcludeEachOther) {
  EXPECT_EQ(input_error_of([] { select_image_labels(three_label_image(), {{1}, 0.5}); }),
            "seg.nii: give either labels (for a segmentation) or a threshold (for an intensity image), not both");
}

TEST(VolumeResample, CellSizeLargerThanTheMaskCanStillHitIt) {
  const ImageVolume image = sphere_image(2.0, Vec3::Constant(0.5));
  const LabelVolume v = resample_image_labels(image, select_image_labels(image, {}), {10.0, {}});
  EXPECT_EQ(v.grid.dims, Vec3i::Ones());
  EXPECT_EQ(v.inside_count(), 1) << "the one cell's centre is the sphere's centre";
}

}  // namespace
}  // namespace cleave
