// Incremental edits give the same field as a fresh design; failing edits change nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <fmt/format.h>
#include <limits>

#include "cleave/core/error.hpp"

#include "cleave/stress/stress_designer.hpp"
#include "stress_test_models.hpp"

namespace cleave {
namespace {

double relative_difference(const DesignResult& a, const DesignResult& b) {
  double diff = 0, size = 0;
  for (std::size_t c = 0; c < a.stress_kPa.size(); ++c) {
    diff = std::max(diff, (a.stress_kPa[c] - b.stress_kPa[c]).cwiseAbs().maxCoeff());
    size = std::max(size, b.stress_kPa[c].cwiseAbs().maxCoeff());
  }
  return diff / size;
}

class DesignerEdits : public ::testing::TestWithParam<EigenvalueSolver> {};

TEST_P(DesignerEdits, EditsEqualAFreshDesign) {
  const TissueModel m = test::builtin_model("plate", {Vec3i(16, 16, 2), std::nullopt});
  StressDesign d;
  d.solver = GetParam();
  d.equilibration = Equilibration::none;
  d.strokes = {DesignStroke{{{10, 50, 10}, {90, 50, 10}}, StrokePlacement::surface}};
  d.control_points = {{{20, 20, 10}, 20, 10}};
  StressDesigner designer(m, d);
  designer.add_stroke(DesignStroke{{{50, 10, 10}, {50, 90, 10}}, StrokePlacement::surface});
  designer.move_stroke(0, DesignStroke{{{10, 30, 10}, {90, 70, 10}}, StrokePlacement::surface});
  designer.add_control_point({{80, 80, 10}, 30, 5});
  designer.move_control_point(0, {{30, 20, 10}, 25, 12});
  designer.add_stroke(DesignStroke{{{10, 10, 10}, {90, 90, 10}}, StrokePlacement::surface});
  designer.delete_stroke(2);
  designer.add_control_point({{50, 50, 0}, 5, 5});
  designer.delete_control_point(2);

  StressDesign final_design = d;
  final_design.strokes = {DesignStroke{{{10, 30, 10}, {90, 70, 10}}, StrokePlacement::surface},
                          DesignStroke{{{50, 10, 10}, {50, 90, 10}}, StrokePlacement::surface}};
  final_design.control_points = {{{30, 20, 10}, 25, 12}, {{80, 80, 10}, 30, 5}};
  const DesignResult fresh = design_residual_stress(m, final_design);
  EXPECT_LT(relative_difference(designer.result(), fresh), 1e-8);
}

INSTANTIATE_TEST_SUITE_P(Solvers, DesignerEdits, ::testing::Values(EigenvalueSolver::cholesky, EigenvalueSolver::paper_cg));

TEST(Designer, AFailingEditLeavesTheDesignAsItWas) {
  const TissueModel m = test::builtin_model("plate", {Vec3i(16, 16, 2), std::nullopt});
  StressDesign d;
  d.strokes = {DesignStroke{{{10, 50, 10}, {90, 50, 10}}, StrokePlacement::surface}};
  d.control_points = {{{20, 20, 10}, 20, 10}};
  StressDesigner designer(m, d);
  const std::vector<Vec6> before = designer.result().stress_kPa;
  EXPECT_THROW(designer.add_stroke(DesignStroke{{{10, 50, 10}}, StrokePlacement::surface}), InputError);
  EXPECT_THROW(designer.delete_control_point(0), InputError);  // would leave no control point
  EXPECT_THROW(designer.move_stroke(5, d.strokes[0]), InputError);
  EXPECT_EQ(designer.design().strokes.size(), 1u);
  EXPECT_EQ(designer.design().control_points.size(), 1u);
  EXPECT_EQ(designer.result().stress_kPa, before);
}

TEST(Designer, AnEditBackToOneOfTheLastTwoDesignsIsAnsweredFromMemory) {
  const TissueModel m = test::builtin_model("plate", {Vec3i(16, 16, 2), std::nullopt});
  StressDesign a;  // equilibrated (the default): every stage has work to skip
  a.strokes = {DesignStroke{{{10, 50, 10}, {90, 50, 10}}, StrokePlacement::surface}};
  a.control_points = {{{20, 20, 10}, 20, 10}};
  const DesignStroke moved{{{10, 30, 10}, {90, 70, 10}}, StrokePlacement::surface};
  StressDesigner designer(m, a);
  const DesignResult first = designer.result();
  EXPECT_FALSE(first.remembered);

  designer.move_stroke(0, moved);  // B
  const DesignResult b = designer.result();
  EXPECT_FALSE(b.remembered);
  designer.move_stroke(0, a.strokes[0]);  // back to A
  EXPECT_TRUE(designer.result().remembered);
  EXPECT_EQ(designer.result().stress_kPa, first.stress_kPa) << "the result computed for A, bit for bit";
  EXPECT_EQ(designer.result().timings.directions_s, 0.0);
  EXPECT_EQ(designer.result().timings.equilibration_s, 0.0);

  designer.move_control_point(0, {{20, 20, 10}, 25, 10});  // C: A and C are the last two now
  EXPECT_FALSE(designer.result().remembered);
  designer.move_control_point(0, a.control_points[0]);  // A again: recalled because it was just used
  EXPECT_TRUE(designer.result().remembered);
  EXPECT_EQ(designer.result().stress_kPa, first.stress_kPa);

  designer.move_stroke(0, moved);  // B was pushed out by C: computed again, and right
  EXPECT_FALSE(designer.result().remembered);
  StressDesign b_design = a;
  b_design.strokes = {moved};
  EXPECT_LT(relative_difference(designer.result(), design_residual_stress(m, b_design)), 1e-8);
  EXPECT_LT(relative_difference(designer.result(), b), 1e-8);

  DesignStroke one_ulp_off = a.strokes[0];  // not A: compared exactly
  one_ulp_off.points_mm[0].x() = std::nextafter(one_ulp_off.points_mm[0].x(), 100.0);
  designer.move_stroke(0, one_ulp_off);
  EXPECT_FALSE(designer.result().remembered);
}

// The picture first: a stroke dragged over fresh cells of the abdomen, edit by edit, by two
// designers. One completes each edit (set_design), the other draws from a provisional stress
// (EquilibrationPass::picture) and completes it afterwards (finish_equilibration): after that
// every result is the first designer's (to rounding: see below), the provisional one was within
// what the picture resolves, and an edit back is answered from memory as for the complete pass.
TEST(Designer, APictureFirstThenTheFinishedEquilibrationIsTheCompleteEdit) {
  const TissueModel m = test::builtin_model("abdomen");
  StressDesign d = test::abdomen_demo_design(m);
  d.equilibration = Equilibration::growth;
  StressDesigner complete(m, d), picture(m, d);
  const double w = m.volume.grid().extent_mm().x(), l = m.volume.grid().extent_mm().z();
  const double h = m.volume.grid().cell_size_mm;
  int provisional_edits = 0;
  for (int edit = 1; edit <= 4; ++edit) {
    StressDesign moved = d;
    moved.strokes[0].points_mm.clear();
    for (int i = 1; i <= 9; ++i) moved.strokes[0].points_mm.push_back(test::skin_point(m, 0.1 * i * w, 0.2 * l + edit * h));
    complete.set_design(moved);
    picture.set_design(moved, EquilibrationPass::picture);
    const DesignResult& whole = complete.result();
    if (picture.result().provisional) {
      ++provisional_edits;
      EXPECT_GT(picture.result().residual_final, whole.residual_final);  // less balanced, not yet remembered
      EXPECT_GT(relative_difference(picture.result(), whole), 0.0);
      EXPECT_LT(relative_difference(picture.result(), whole), 1e-4);
      picture.finish_equilibration();
    }
    EXPECT_FALSE(picture.result().provisional);
    // Two designers agree to rounding, not bit for bit: the direction stage chooses between its
    // kept factor and CG by measured times (the ASan build chose differently at edit 4). The
    // equilibration's own bit-for-bit equality is Equilibration.APictureFirstThenFinish...
    EXPECT_LT(relative_difference(picture.result(), whole), 1e-6) << "edit " << edit;  // measured up to 3.6e-8 (ASan, -j2)
    EXPECT_NEAR(picture.result().residual_final, whole.residual_final, 0.5 * whole.residual_final) << "edit " << edit;
    const std::vector<Vec6> finished = picture.result().stress_kPa;
    picture.finish_equilibration();  // nothing left to do
    EXPECT_TRUE(picture.result().stress_kPa == finished);
  }
  EXPECT_GE(provisional_edits, 1) << "no edit over fresh cells stopped for the picture";
  // The last two designs are remembered once finished; a provisional one is not until then.
  picture.set_design(d, EquilibrationPass::picture);
  picture.finish_equilibration();
  complete.set_design(d);
  EXPECT_LT(relative_difference(picture.result(), complete.result()), 1e-6);
  StressDesign last = d;
  last.strokes[0].points_mm.clear();
  for (int i = 1; i <= 9; ++i) last.strokes[0].points_mm.push_back(test::skin_point(m, 0.1 * i * w, 0.2 * l + 4 * h));
  picture.set_design(last, EquilibrationPass::picture);
  EXPECT_TRUE(picture.result().remembered);
  EXPECT_FALSE(picture.result().provisional);
}

// A provisional edit superseded by the next one: that edit (complete) equals a fresh design.
TEST(Designer, AnEditAfterAProvisionalOneEqualsAFreshDesign) {
  const TissueModel m = test::builtin_model("abdomen");
  StressDesign d = test::abdomen_demo_design(m);
  d.equilibration = Equilibration::growth;
  StressDesigner designer(m, d);
  const double w = m.volume.grid().extent_mm().x(), l = m.volume.grid().extent_mm().z();
  const double h = m.volume.grid().cell_size_mm;
  StressDesign moved = d;
  for (int edit = 1; edit <= 3; ++edit) {
    moved.strokes[0].points_mm.clear();
    for (int i = 1; i <= 9; ++i) moved.strokes[0].points_mm.push_back(test::skin_point(m, 0.1 * i * w, 0.2 * l - edit * h));
    designer.set_design(moved, EquilibrationPass::picture);  // never finished
  }
  moved.control_points[0].langer_kPa = 30;
  designer.set_design(moved);
  EXPECT_FALSE(designer.result().provisional);
  EXPECT_LT(relative_difference(designer.result(), design_residual_stress(m, moved)), 1e-8);
  EXPECT_LE(designer.result().residual_final, 1e-10 * designer.result().residual_designed);
}

}  // namespace
}  // namespace cleave
