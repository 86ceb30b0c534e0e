// Real data: the Colin27 head MRI (mricron-data), thresholded to the head at 4 mm cells.
#include <algorithm>
#include <gtest/gtest.h>
#include <iostream>

#include "cleave/grid/linked_volume.hpp"
#include "cleave/io/model_source.hpp"
#include "io_fixtures.hpp"

namespace cleave {
namespace {

// T1 intensities (0..255): air/background lies below ~10, scalp, skull marrow and brain above.
// 40 separates the head from the background noise without eating into the scalp.
constexpr double kHeadThreshold = 40.0;
constexpr double kCellSizeMm = 4.0;

TEST(RealData, Colin27HeadThresholdedIsOneHeadSizedBody) {
  const auto file = test::require_real_data(test::kColin27Head);
  ASSERT_TRUE(std::filesystem::exists(file));
  ModelSourceOptions options;
  options.threshold = kHeadThreshold;
  options.cell_size_mm = kCellSizeMm;
  const LabelVolume v = load_model_source(file.string(), options);
  const LinkedVolume linked = LinkedVolume::from_labels(v);
  std::vector<int> sizes(static_cast<size_t>(linked.component_count()), 0);
  for (int c : linked.cell_components()) ++sizes[static_cast<size_t>(c)];
  const int largest = *std::max_element(sizes.begin(), sizes.end());
  Vec3 lo = Vec3::Constant(1e30), hi = -lo;
  for (CellId c = 0; c < linked.cell_count(); ++c) {
    lo = lo.cwiseMin(linked.cell_center_mm(c));
    hi = hi.cwiseMax(linked.cell_center_mm(c));
  }
  const Vec3 extent = hi - lo + Vec3::Constant(kCellSizeMm);
  const double litres = linked.cell_count() * kCellSizeMm * kCellSizeMm * kCellSizeMm / 1e6;
  std::cout << "ch2.nii.gz >= " << kHeadThreshold << " at 4 mm: " << linked.cell_count() << " cells, " << litres
            << " L, extent " << extent.transpose() << " mm, " << linked.component_count() << " components, largest "
            << largest << "\n";
  // The image is 181 x 217 x 181 mm (RAS): head breadth (x) 130-181 mm, length (y) 160-217 mm,
  // height (z, crown to the cut at the neck) 120-181 mm.
  EXPECT_GT(extent.x(), 130.0);
  EXPECT_LE(extent.x(), 184.0);
  EXPECT_GT(extent.y(), 160.0);
  EXPECT_LE(extent.y(), 220.0);
  EXPECT_GT(extent.z(), 120.0);
  EXPECT_LE(extent.z(), 184.0);
  // An adult head above the neck holds 3-5.5 litres of tissue.
  EXPECT_GT(litres, 3.0);
  EXPECT_LT(litres, 5.5);
  EXPECT_GT(largest, 0.95 * linked.cell_count()) << "one main component";
  // The world frame is the file's sform (RAS+, mm): the head lies around the MNI origin.
  EXPECT_LT(lo.x(), -50.0);
  EXPECT_GT(hi.x(), 50.0);
  EXPECT_TRUE(v.has_distance());
}

}  // namespace
}  // namespace cleave
