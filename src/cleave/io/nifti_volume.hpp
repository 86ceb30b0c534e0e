#pragma once
// Reading NIfTI-1 and NIfTI-2 volumes (.nii, .nii.gz) with nifticlib, into
// an ImageVolume in RAS+ millimetres (NIfTI's own world frame).
//
// Geometry: the sform when sform_code > 0, else the qform when qform_code > 0, else the plain
// scaling by pixdim (NIfTI "method 1"). Values are scaled by scl_slope/scl_inter when the slope
// is non-zero. Spatial units other than mm (metres, micrometres) are converted to mm.
// Accepted: 3-D images (extra dimensions of size 1 are allowed); integer or real scalar samples.
#include <filesystem>

#include "cleave/io/image_volume.hpp"

namespace cleave {

/// Reads `file`. Throws InputError naming the file and the problem: missing file, unreadable or
/// malformed header, truncated data, more than one volume, zero/negative spacing, complex or RGB
/// samples, or an image that would not fit in memory (checked before reading the data).
ImageVolume read_nifti_volume(const std::filesystem::path& file);

}  // namespace cleave
