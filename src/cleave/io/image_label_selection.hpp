#pragma once
// Which samples of an image are tissue, and with which tissue label: label selection for
// segmentations, a threshold for intensity images.
#include <optional>
#include <vector>

#include "cleave/grid/label_volume.hpp"
#include "cleave/io/image_volume.hpp"

namespace cleave {

struct ImageSelection {
  std::vector<int> labels;           ///< keep only these label values (empty: every non-zero value)
  std::optional<double> threshold;   ///< intensity images: samples >= threshold are tissue label 1
};

/// One Label per image sample (same order as image.values), 0 = outside.
///   threshold given:  value >= threshold -> 1, else 0.
///   otherwise:        the image is a label image; kept values stay their own tissue label.
/// Labels must be integers 1..255 (cleave's Label is 8-bit): a kept value outside that range is an
/// error, never silently remapped. Throws InputError naming image.source and the problem: both a
/// threshold and labels given; non-integer values without a threshold; a selected label that is
/// absent (the message lists the labels present); a kept label outside 1..255; an empty mask.
std::vector<Label> select_image_labels(const ImageVolume& image, const ImageSelection& selection);

}  // namespace cleave
