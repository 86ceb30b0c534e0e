// The studio's cut-face colours (paper fig. 5) per render-surface vertex: the depth layout kept
// per cut state and the released traction recomputed per design edit.
#include <gtest/gtest.h>

#include "cleave/io/model_source.hpp"
#include "cleave/surface/render_surface.hpp"
#include "studio/cut_face_values.hpp"

namespace cleave::studio {
namespace {

TEST(CutFaceValues, DepthRunsSkinToInnerLayerAndTractionIsSigmaTimesTheFaceNormal) {
  ModelSourceOptions options;
  options.resolution = Vec3i(48, 16, 32);  // the abdominal wall: skin outside, inner layer inside
  const TissueModel uncut = make_tissue_model("abdomen", load_model_source("abdomen", options));
  const BodySurface body(uncut);
  TissueModel cut = uncut;
  // a cut through the whole wall across x = the middle: faces with normal +x / -x
  std::vector<CellFace> faces;
  for (CellId c = 0; c < cut.volume.cell_count(); ++c)
    if (cut.volume.cell_voxel(c).x() == 23 && cut.volume.neighbor(c, 1) != kNone) faces.push_back({c, 1});
  ASSERT_FALSE(faces.empty());
  (void)cut.volume.cut_links(faces);
  const RenderSurface surface = build_render_surface(cut);

  const CutFaceLayout layout = cut_face_layout(body, cut, surface);
  ASSERT_TRUE(layout.any);
  EXPECT_EQ(layout.faces.size(), 2 * faces.size()) << "both sides of every cut link";
  ASSERT_EQ(layout.depth.size(), static_cast<std::size_t>(surface.vertex_count()));
  float lo = 2, hi = -2;
  int on_cut = 0;
  for (const float d : layout.depth) {
    if (d < 0) {
      EXPECT_EQ(d, -1.0f) << "off the cut faces";
      continue;
    }
    ++on_cut;
    lo = std::min(lo, d);
    hi = std::max(hi, d);
  }
  EXPECT_GT(on_cut, 0);
  EXPECT_LT(lo, 0.3f) << "cut vertices near the skin";
  EXPECT_GT(hi, 0.7f) << "cut vertices near the inner layer";
  EXPECT_LE(hi, 1.0f);

  // sigma_xx = 20 kPa releases 20 kPa on faces with normal x; sigma_yy releases nothing there.
  std::vector<Vec6> along_x(static_cast<std::size_t>(cut.volume.cell_count()), Vec6::Zero());
  std::vector<Vec6> along_y = along_x;
  for (Vec6& s : along_x) s[0] = 20.0;
  for (Vec6& s : along_y) s[1] = 20.0;
  const std::vector<float> tx = cut_face_traction_kPa(layout, surface, along_x);
  const std::vector<float> ty = cut_face_traction_kPa(layout, surface, along_y);
  for (std::size_t v = 0; v < tx.size(); ++v) {
    if (layout.depth[v] < 0) {
      EXPECT_EQ(tx[v], -1.0f);
      continue;
    }
    EXPECT_NEAR(tx[v], 20.0f, 1e-5f);
    EXPECT_NEAR(ty[v], 0.0f, 1e-5f);
  }
  EXPECT_TRUE(cut_face_traction_kPa(cut_face_layout(body, uncut, build_render_surface(uncut)), surface, along_x).empty())
      << "no cut, no faces";
}

}  // namespace
}  // namespace cleave::studio
