#pragma once
// The case sections of the cut domain (docs/case-format.md):
//
//   "incisions": {
//     "radius_mm": 6, "depth_mm": 5,                 every incision's size
//     "plug": "remove" | "keep",                      default "remove" (the plug is a hidden free piece)
//     "at_mm": [[x, y, z], ...],                      explicit centres on the surface, and/or
//     "place": {                                      Poisson-disk placement over the surface
//       "spacing_mm": 25,                             least distance between centres
//       "count": 12,                                  optional: exactly this many (error if fewer fit)
//       "region": "surface" | {"box_mm": [[x0,y0,z0],[x1,y1,z1]]} | {"sphere_mm": {"centre": [x,y,z], "radius": r}},
//       "seed": 1
//     }
//   }
//   "cuts": [
//     {"type": "scalpel", "path_mm": [[x,y,z], ...], "depth_mm": 5, "blade_angle_deg": 0},
//     {"type": "flap", "path_mm": [[x,y,z], ...], "depth_mm": 5, "shape": "u" | "closed"}
//   ]
//   Optional in either: "surface_tolerance_mm" (how far a given point may lie off the surface;
//   default 1.5 cells) at the top of "incisions".
//
// Every error is an InputError naming the file, JSON path, value and what was expected.
#include <optional>
#include <vector>

#include "cleave/cut/cut_plan.hpp"
#include "cleave/cut/place_incisions.hpp"
#include "cleave/io/case_file.hpp"

namespace cleave {

struct CaseCuts {
  std::vector<RoundIncision> incisions;   ///< "at_mm"
  std::optional<IncisionPattern> pattern; ///< "place"
  std::vector<ScalpelCut> scalpel_cuts;
  std::vector<Flap> flaps;
  std::vector<std::size_t> scalpel_index; ///< position of each scalpel cut in "cuts"
  std::vector<std::size_t> flap_index;    ///< position of each flap in "cuts"
  double surface_tolerance_mm = 0;        ///< 0 = default

  bool empty() const { return incisions.empty() && !pattern && scalpel_cuts.empty() && flaps.empty(); }
};

/// Parses "incisions" and "cuts" (either may be absent). Throws InputError on bad fields.
CaseCuts parse_case_cuts(const CaseFile& case_file);

/// The concrete requests: explicit incisions plus the placed ones (placement errors are reported
/// under /incisions/place), scalpel cuts and flaps.
CutRequests resolve_case_cuts(const CaseFile& case_file, const CaseCuts& cuts, const BodySurface& surface);

/// Validates and plans the requests with error names pointing into the case file.
CutPlan plan_case_cuts(const CaseFile& case_file, const CaseCuts& cuts, const CutRequests& requests,
                       const BodySurface& surface);

}  // namespace cleave
