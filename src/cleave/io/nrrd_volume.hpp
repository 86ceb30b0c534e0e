#pragma once
// Reading NRRD volumes (.nrrd, .nhdr with detached data; raw, gzip, bzip2 or ascii encoding)
// with teem, into an ImageVolume in RAS+ millimetres.
//
// Geometry: "space directions" and "space origin" give the voxel-to-world map; without them the
// per-axis "spacings" (default 1 mm when absent) and the origin 0 are used. Files in LPS
// ("left-posterior-superior", also "scanner-xyz") or LAS space are converted to RAS+ by negating
// the world x (and y) axes; RAS+ and unnamed 3-D spaces are taken as they are.
// Accepted: 3 axes, or 4 with one axis of size 1 (dropped). Any scalar sample type.
#include <filesystem>

#include "cleave/io/image_volume.hpp"

namespace cleave {

/// Reads `file`. Throws InputError naming the file and the problem: missing file, header teem
/// cannot parse, truncated data, a dimension other than 3, zero/negative/non-finite spacing,
/// non-scalar samples, or an image that would not fit in memory (checked before reading data).
ImageVolume read_nrrd_volume(const std::filesystem::path& file);

}  // namespace cleave
