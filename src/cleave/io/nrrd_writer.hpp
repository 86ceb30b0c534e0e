#pragma once
// Writing a LabelVolume as a NRRD label image (uchar samples) that any NRRD reader (teem, 3D
// Slicer, ITK) and read_nrrd_volume place at the same world positions.
#include <filesystem>

#include "cleave/grid/label_volume.hpp"

namespace cleave {

enum class NrrdEncoding { raw, gzip };

/// Writes the labels of `volume` to `file` (.nrrd, header and data in one file): space
/// "right-anterior-superior", space directions = cell size along x, y, z, space origin = the
/// centre of voxel (0, 0, 0), cell centering. Corner distances and label names are not written.
/// The file is written to a temporary name and renamed into place. Throws InputError naming the
/// file when it cannot be written.
void write_nrrd_label_volume(const LabelVolume& volume, const std::filesystem::path& file,
                             NrrdEncoding encoding = NrrdEncoding::gzip);

}  // namespace cleave
