#pragma once
// The case `cleave demo` runs (paper sections 5 and 7 on the built-in abdomen), as a case-file
// document (docs/case-format.md), so that the CLI, the tests and the studio run the same thing:
//   model       the built-in abdomen at 3.6 mm cells (three cells through the 10.8 mm wall: two
//               lock in shear and underestimate the openings, docs/VALIDATION.md)
//   materials   E = 80 kPa, nu = 0.4 for skin, fat and muscle (paper section 7)
//   design      three strokes running horizontally around the body (along x), four control
//               points 20 kPa along / 10 kPa across; no equilibrium term (w_E = 0), exactly
//               equilibrated at the vertices the simulation leaves free (the held rim and inner
//               surface carry the reactions: docs/stress-design.md)
//   incisions   radius 8 mm, 5 mm deep (skin and fat), plugs removed, Poisson-disk spaced 35 mm
//               over the upper part of the body (z from 0.55 to 0.9 of its length)
//   cuts        a 5 cm scalpel cut across the lines (path along z) and one along them, 8 mm deep,
//               and a U-shaped flap 5 mm deep, in the lower part, apart from the incisions
//   simulation  static; held: a 5 mm band along the wall's four edges and its inner surface
//               (it lies on the body beneath)
// With DemoStress::direct the design is replaced by a direct uniform stress (20 kPa along x,
// 10 kPa along z), the demo's fallback when the design step fails.
#include <nlohmann/json.hpp>

#include "cleave/model/tissue_model.hpp"

namespace cleave {

enum class DemoStress { designed, direct };

/// Cell edge of the demo's model (mm); build `model` with it (ShapeResolution::cell_size_mm).
inline constexpr double kDemoCellSizeMm = 3.6;

/// The demo case on `model` (the built-in abdomen at kDemoCellSizeMm); its paths and points are
/// placed on that model's skin.
nlohmann::json abdomen_demo_case(const TissueModel& model, DemoStress stress);

/// The demo's design settings and supports on `model` (the built-in abdomen at any resolution),
/// as case sections: {"design": {"weights": {"equilibrium": 0}, "equilibrate": true,
/// "equilibrium_support": "simulation"}, "simulation": {"mode": "static", "fixed": [the 5 mm rim
/// along the wall's four edges, {"surface": "inner"}]}}. The design section holds no strokes or
/// control points. abdomen_demo_case uses them; so does the studio on the bare abdomen.
nlohmann::json abdomen_demo_settings(const TissueModel& model);

}  // namespace cleave
