// The generalized-alpha rule (DynamicsSettings::high_frequency_radius, Chung & Hulbert 1993) at the
// studio's opening step: a slit plate's opening is far faster than 30 ms (in-plane waves cross it
// in about 5 ms), so its modes are unresolved. HHT (radius 0.67) lets them ring from step to step;
// radius 0 removes them within a few steps. Both come to rest at the same equilibrium. (Resolved
// motion: Dynamics.GeneralizedAlphaDampsOnlyWhatTheStepCannotResolve, with the cantilever.)
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "cleave/core/error.hpp"
#include "cleave/fem/dynamics.hpp"
#include "fem_test_models.hpp"

namespace cleave {
namespace {

constexpr double kStudioStep_s = 0.03;

using test::OpeningPlate;

DynamicsSettings held_at_x0(const LinkedVolume& volume, std::optional<double> radius, double mass_damping_per_s) {
  DynamicsSettings settings;
  settings.solver = SolverKind::cholmod;  // exact steps: the integrators alone differ
  settings.mass_damping_per_s = mass_damping_per_s;
  settings.high_frequency_radius = radius;
  for (VertexId v = 0; v < volume.vertex_count(); ++v)
    if (volume.vertex_position_mm(v).x() < 1e-9) settings.fixed_vertices.push_back(v);
  return settings;
}

/// The largest displacement after each of `steps` steps of dt.
std::vector<double> opening(const OpeningPlate& plate, std::optional<double> radius, double dt, int steps, double damping = 20.0) {
  Dynamics sim(plate.model, plate.stress, held_at_x0(plate.model.volume, radius, damping));
  std::vector<double> out;
  for (int i = 0; i < steps; ++i) {
    sim.step(dt);
    out.push_back(sim.displacement().lpNorm<Eigen::Infinity>());
  }
  return out;
}

/// The largest step-to-step swing |d(n+1) - 2 d(n) + d(n-1)| from step `from` on.
double ringing(const std::vector<double>& d, std::size_t from) {
  double r = 0;
  for (std::size_t n = std::max<std::size_t>(from, 1); n + 1 < d.size(); ++n) r = std::max(r, std::abs(d[n + 1] - 2 * d[n] + d[n - 1]));
  return r;
}

TEST(DynamicsGeneralizedAlpha, TheStudiosOpeningStopsRingingAndRestsWhereHhtRests) {
  const OpeningPlate plate;
  const int steps = 40;
  const std::vector<double> hht = opening(plate, std::nullopt, kStudioStep_s, steps);
  const std::vector<double> annihilating = opening(plate, 0.0, kStudioStep_s, steps);
  const double rest = hht.back();
  std::printf("opening at 30 ms steps, largest displacement (mm):\n  HHT   ");
  for (int i = 0; i < 10; ++i) std::printf(" %.4f", hht[static_cast<std::size_t>(i)]);
  std::printf("\n  r = 0 ");
  for (int i = 0; i < 10; ++i) std::printf(" %.4f", annihilating[static_cast<std::size_t>(i)]);
  std::printf("\n  swing from step 3 on: HHT %.3e, r = 0 %.3e (rest %.4f mm)\n", ringing(hht, 3), ringing(annihilating, 3), rest);
  EXPECT_GT(ringing(hht, 3), 0.02 * rest);                      // HHT still rings after three steps
  EXPECT_LT(ringing(annihilating, 3), 0.1 * ringing(hht, 3));   // generalized-alpha (r = 0) does not
  EXPECT_NEAR(annihilating.back(), rest, 1e-3 * rest);          // the same equilibrium (HHT still swings 1e-4)
}

TEST(DynamicsGeneralizedAlpha, ARadiusOutsideZeroToOneIsRefused) {
  const OpeningPlate plate;
  for (const double radius : {-0.1, 1.5, std::nan("")}) {
    try {
      Dynamics sim(plate.model, plate.stress, held_at_x0(plate.model.volume, radius, 0.0));
      ADD_FAILURE() << "radius " << radius << " was taken";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("high-frequency spectral radius is"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("expected a number from 0 to 1"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace cleave
