#include "cleave/io/image_label_selection.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <fmt/format.h>
#include <map>

#include "cleave/core/error.hpp"

namespace cleave {
namespace {

constexpr int kMaxLabel = 255;              // cleave's Label is uint8, 0 = outside
constexpr size_t kMaxListedLabels = 20;     // error messages list at most this many labels

std::string list_labels(const std::map<long long, std::int64_t>& present) {
  std::vector<std::string> names;
  for (const auto& [value, count] : present) {
    if (names.size() == kMaxListedLabels) {
      names.push_back(fmt::format("... ({} in all)", present.size()));
      break;
    }
    names.push_back(std::to_string(value));
  }
  return names.empty() ? std::string("none") : fmt::format("{}", fmt::join(names, ", "));
}

std::vector<Label> select_by_threshold(const ImageVolume& image, double threshold) {
  if (!std::isfinite(threshold))
    throw InputError(fmt::format("{}: threshold {}; expected a finite number", image.source, threshold));
  std::vector<Label> labels(image.values.size(), Label{0});
  std::int64_t inside = 0;
  for (size_t n = 0; n < labels.size(); ++n)
    if (image.values[n] >= threshold) {
      labels[n] = 1;
      ++inside;
    }
  if (inside == 0) {
    const auto [lo, hi] = std::minmax_element(image.values.begin(), image.values.end());
    throw InputError(fmt::format("{}: the mask is empty: no sample is >= the threshold {} (values range from {} to {})",
                                 image.source, threshold, *lo, *hi));
  }
  return labels;
}

}  // namespace

std::vector<Label> select_image_labels(const ImageVolume& image, const ImageSelection& selection) {
  const std::string& f = image.source;
  if (selection.threshold && !selection.labels.empty())
    throw InputError(fmt::format("{}: give either labels (for a segmentation) or a threshold (for an intensity "
                                 "image), not both", f));
  if (selection.threshold) return select_by_threshold(image, *selection.threshold);

  std::map<long long, std::int64_t> present;  // non-zero label value -> sample count
  for (size_t n = 0; n < image.values.size(); ++n) {
    const double v = image.values[n];
    if (v == 0.0) continue;
    if (v != std::round(v))
      throw InputError(fmt::format("{}: sample {} has the non-integer value {}, so this is an intensity image, not "
                                   "a label image; give a threshold (--threshold) to select the inside",
                                   f, n, v));
    ++present[static_cast<long long>(v)];
  }
  std::vector<long long> kept;
  if (selection.labels.empty()) {
    for (const auto& entry : present) kept.push_back(entry.first);
  } else {
    for (int label : selection.labels) {
      if (present.count(label) == 0)
        throw InputError(fmt::format("{}: label {} is absent; labels present: {}", f, label, list_labels(present)));
      kept.push_back(label);
    }
  }
  if (kept.empty()) throw InputError(fmt::format("{}: the mask is empty: every sample is 0", f));
  for (long long label : kept)
    if (label < 1 || label > kMaxLabel)
      throw InputError(fmt::format("{}: label {} does not fit cleave's tissue labels 1..{}; select labels in that "
                                   "range (--label) or give a threshold (--threshold)", f, label, kMaxLabel));

  std::array<bool, kMaxLabel + 1> keep{};
  for (long long label : kept) keep[static_cast<size_t>(label)] = true;
  std::vector<Label> labels(image.values.size(), Label{0});
  for (size_t n = 0; n < labels.size(); ++n) {
    const auto v = static_cast<long long>(image.values[n]);
    if (v >= 1 && v <= kMaxLabel && keep[static_cast<size_t>(v)]) labels[n] = static_cast<Label>(v);
  }
  return labels;
}

}  // namespace cleave
