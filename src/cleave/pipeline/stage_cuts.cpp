// Stage "cuts" of a batch run: the case's "incisions" and "cuts" sections (io/case_cuts.hpp).
// Every request is validated before the linked volume is touched; then incisions, scalpel cuts
// and flaps are cut in that order. Adds the cell field "removed" (1 for the cells of removed
// plugs: cut-free pieces not displayed, which the mechanics stage holds; also left in
// ctx.removed_cells) and summary["cut"]: counts of requests, links cut, vertices split and
// components.
#include "cleave/cut/body_surface.hpp"
#include "cleave/io/case_cuts.hpp"
#include "cleave/pipeline/stages.hpp"

namespace cleave {

void stage_cuts(RunContext& ctx) {
  const CaseCuts cuts = parse_case_cuts(ctx.case_file);
  if (cuts.empty()) return;
  const BodySurface surface(ctx.model);
  const CutRequests requests = resolve_case_cuts(ctx.case_file, cuts, surface);
  const CutPlan plan = plan_case_cuts(ctx.case_file, cuts, requests, surface);
  LinkedVolume& volume = ctx.model.volume;
  int links_cut = 0;
  std::size_t splits = 0;
  for (std::size_t i = 0; i < plan.steps.size(); ++i) {
    const CutReport r = volume.cut_links(plan.steps[i].links);
    links_cut += r.links_cut;
    splits += r.splits.size();
    report(ctx.progress, "cuts", static_cast<double>(i + 1) / static_cast<double>(plan.steps.size()));
  }
  DataArray removed{"removed", 1, std::vector<double>(static_cast<std::size_t>(volume.cell_count()), 0.0)};
  ctx.removed_cells = plan.hidden_cells();
  const std::vector<CellId>& hidden = ctx.removed_cells;
  for (const CellId c : hidden) removed.values[static_cast<std::size_t>(c)] = 1.0;
  ctx.fields.cell_data.push_back(std::move(removed));
  ctx.summary["cut"] = {{"incisions", requests.incisions.size()},
                        {"scalpel_cuts", requests.scalpel_cuts.size()},
                        {"flaps", requests.flaps.size()},
                        {"links_cut", links_cut},
                        {"vertices_split", splits},
                        {"removed_cells", hidden.size()},
                        {"components", volume.component_count()}};
}

}  // namespace cleave
