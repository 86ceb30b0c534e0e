#pragma once
// How far a scalpel cut gapes and how much a flap shrinks (paper section 7, figs. 8 and 9).
//
//   WoundWidth w = scalpel_wound_width(volume, displacement_mm, path);   // path from sweep_path
//   w.max_mm, w.mean_mm
//   FlapChange f = flap_change(volume, displacement_mm, region);         // region from flap_region
//   f.skin_area_change_percent, f.volume_change_percent
//
// Wound width at a path sample x on the skin: the two lips are the material points at x on
// either side of the cut (side = the path's in-plane perpendicular m), each displaced with its own
// side's cells (displacement_at_point.hpp); width = (u_plus - u_minus) . m, the separation
// across the cut (mm; 0 while closed, negative if the lips overlap). Samples within one cell of
// either end of the path are left out of max/mean, since the wound closes there.
//
// Flap change: skin area = boundary faces of the flap cells whose outward normal points along
// the flap's normal (each quad's area from its deformed diagonals); volume = sum over flap cells
// of h^3 det F at the cell centre. Changes are (after - before) / before * 100.
#include <span>
#include <vector>

#include "cleave/cut/flap_links.hpp"
#include "cleave/cut/scalpel_links.hpp"

namespace cleave {

struct WoundWidth {
  std::vector<double> width_mm;  ///< per path sample (0 at the excluded ends)
  double max_mm = 0;
  double mean_mm = 0;
  int samples = 0;               ///< samples counted in max/mean
};

WoundWidth scalpel_wound_width(const LinkedVolume& volume, std::span<const Vec3> displacement_mm,
                               const SweptPath& path);

struct FlapChange {
  double skin_area_before_mm2 = 0;
  double skin_area_after_mm2 = 0;
  double skin_area_change_percent = 0;
  double volume_before_mm3 = 0;
  double volume_after_mm3 = 0;
  double volume_change_percent = 0;
};

FlapChange flap_change(const LinkedVolume& volume, std::span<const Vec3> displacement_mm, const FlapRegion& region);

}  // namespace cleave
