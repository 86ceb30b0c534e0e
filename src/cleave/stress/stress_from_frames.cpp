#include "cleave/stress/stress_from_frames.hpp"

#include <fmt/format.h>

#include "cleave/core/error.hpp"

namespace cleave {

std::vector<Vec6> stress_from_frames(const std::vector<DirectionFrame>& frames, const std::vector<Vec3>& eigenvalues_kPa) {
  if (frames.size() != eigenvalues_kPa.size())
    throw InputError(fmt::format("got {} frames and {} eigenvalue triples; expected one of each per cell", frames.size(),
                                 eigenvalues_kPa.size()));
  std::vector<Vec6> stress(frames.size());
  for (std::size_t c = 0; c < frames.size(); ++c) {
    const DirectionFrame& f = frames[c];
    const Vec3& l = eigenvalues_kPa[c];
    stress[c] = to_voigt(l[0] * f.langer * f.langer.transpose() + l[1] * f.cross * f.cross.transpose() +
                         l[2] * f.normal * f.normal.transpose());
  }
  return stress;
}

}  // namespace cleave
