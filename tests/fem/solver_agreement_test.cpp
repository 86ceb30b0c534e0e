// All solvers give the same static displacement on a cut model with a free piece (the plug of a
// round incision), through solve_static's Dirichlet elimination, rigid supports and projection.
#include <gtest/gtest.h>

#include "cleave/fem/solve_static.hpp"
#include "fem_test_models.hpp"

namespace cleave {
namespace {

TEST(SolverAgreement, CholmodEigenCgAndMultigridAgreeOnACutPlate) {
  const int n = 32;
  TissueModel model = test::make_box_model({n, n, 2}, 1.0);
  const Vec3 centre{n / 2.0, n / 2.0, 0.0};
  const auto in_plug = [&](CellId c) {
    const Vec3 d = model.volume.cell_center_mm(c) - centre;
    return std::hypot(d.x(), d.y()) < 5.0;
  };
  model.volume.cut_links(test::faces_between(model.volume, in_plug));
  ASSERT_EQ(model.volume.component_count(), 2);
  Vec6 stress;
  stress << 20.0, 10.0, 0, 4.0, 0, 0;
  const std::vector<Vec6> field(static_cast<std::size_t>(model.volume.cell_count()), stress);
  StaticOptions options;
  options.settings.relative_tolerance = 1e-10;
  options.settings.max_iterations = 5000;
  for (VertexId v = 0; v < model.volume.vertex_count(); ++v)
    if (model.volume.vertex_position_mm(v).x() < 1e-9) options.fixed_vertices.push_back(v);

  std::vector<StaticResult> results;
  for (const SolverKind kind : {SolverKind::cholmod, SolverKind::eigen_cg, SolverKind::multigrid_cg}) {
    options.solver = kind;
    results.push_back(solve_static(model, field, options));
    std::printf("solver %s: %d iterations, relative residual %.2e\n", results.back().solver_name.c_str(),
                results.back().report.iterations, results.back().report.relative_residual);
  }
  double scale = 0;
  for (const Vec3& u : results[0].displacement_mm) scale = std::max(scale, u.norm());
  ASSERT_GT(scale, 0.1);
  for (std::size_t k = 1; k < results.size(); ++k) {
    double diff = 0;
    for (std::size_t v = 0; v < results[0].displacement_mm.size(); ++v)
      diff = std::max(diff, (results[k].displacement_mm[v] - results[0].displacement_mm[v]).norm());
    EXPECT_LT(diff, 1e-6 * scale) << results[k].solver_name << " vs " << results[0].solver_name;
  }
}

}  // namespace
}  // namespace cleave
