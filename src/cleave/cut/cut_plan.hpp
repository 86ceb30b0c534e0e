#pragma once
// Turning cut requests into links, with every request validated before the model is touched:
//
//   CutPlan plan = plan_cuts(surface, requests);   // throws InputError; the model is unchanged
//   CutReport r = apply_cut_plan(model.volume, plan);   // all at once, or step by step:
//   for (const auto& step : plan.steps) { CutReport r = model.volume.cut_links(step.links); ... }
//
// Checks (each an InputError naming the request, the value and what was expected):
//   incision: centre within the tolerance of the surface; radius at least one cell and its
//             diameter smaller than the body; the whole rim on the surface; depth > 0 and not
//             beyond the body's thickness under the centre (plus half a cell).
//   scalpel:  at least 2 points, each within the tolerance of the surface; length at least half
//             a cell; blade angle in (-90, 90) degrees; depth > 0 and not beyond the thickness
//             along the blade anywhere on the path.
//   flap:     as scalpel for its points and depth; a simple (non self-intersecting) polygon of at
//             least one cell face in area; at least one flap cell.
#include <string>
#include <vector>

#include "cleave/cut/body_surface.hpp"
#include "cleave/cut/cut_requests.hpp"
#include "cleave/cut/flap_links.hpp"
#include "cleave/cut/round_incision_links.hpp"
#include "cleave/cut/scalpel_links.hpp"

namespace cleave {

/// Default distance a requested point may lie off the surface, in cells.
inline constexpr double kSurfaceToleranceCells = 1.5;

/// Names used in error messages: "<prefix> <index>", e.g. "case.json: /incisions/list 3".
struct CutRequestNames {
  std::string incision = "incision";
  std::string scalpel = "cut";
  std::string flap = "flap";
};

struct CutStep {
  enum class Kind { incision, scalpel, flap } kind = Kind::incision;
  std::size_t index = 0;           ///< into the request list of its kind
  std::vector<CellFace> links;     ///< links this step cuts
  std::vector<CellId> hidden_cells;  ///< removed plugs: free pieces not to display
};

struct CutPlan {
  std::vector<IncisionFrame> incisions;  ///< per incision request
  std::vector<SweptPath> scalpel_paths;  ///< per scalpel request
  std::vector<FlapRegion> flaps;         ///< per flap request
  std::vector<CutStep> steps;            ///< in application order

  std::vector<CellId> hidden_cells() const;
};

/// Validates all requests against the (uncut) body surface and computes their links.
/// `tolerance_mm` <= 0 means kSurfaceToleranceCells cells.
CutPlan plan_cuts(const BodySurface& surface, const CutRequests& requests, double tolerance_mm = 0,
                  const CutRequestNames& names = {});

/// Applies every step; the reports are merged (splits and touched cells concatenated).
CutReport apply_cut_plan(LinkedVolume& volume, const CutPlan& plan);

}  // namespace cleave
