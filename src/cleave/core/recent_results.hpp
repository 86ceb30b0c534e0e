#pragma once
// The results of the last few distinct inputs of a computation whose result depends on its input
// alone (and on state that does not change while the results are kept). In the studio an edit
// back to an earlier design (undo, redo, a stroke dragged back) gives a field equal to one
// computed before, bit for bit, and is answered without solving again.
//
//   RecentResults<Vec6, StaticResult> recent(2);
//   if (const StaticResult* known = recent.find(stress_kPa)) return *known;
//   ...; recent.remember(stress_kPa, result);
//
// Inputs are compared exactly (element by element with ==): a field that differs in one bit is
// a new input. The newest result is found first; past `capacity` the oldest is forgotten.
#include <algorithm>
#include <cstddef>
#include <deque>
#include <span>
#include <vector>

namespace cleave {

template <typename Element, typename Result>
class RecentResults {
 public:
  explicit RecentResults(std::size_t capacity) : capacity_(capacity) {}

  /// The result remembered for an input equal to `input`, or nullptr.
  const Result* find(std::span<const Element> input) const {
    for (const Entry& e : entries_)
      if (std::ranges::equal(e.input, input)) return &e.result;
    return nullptr;
  }

  /// Remembers `result` for `input` as the newest entry (an equal input's older entry is replaced).
  void remember(std::span<const Element> input, Result result) {
    std::erase_if(entries_, [&](const Entry& e) { return std::ranges::equal(e.input, input); });
    entries_.push_front(Entry{std::vector<Element>(input.begin(), input.end()), std::move(result)});
    while (entries_.size() > capacity_) entries_.pop_back();
  }

  void clear() { entries_.clear(); }
  std::size_t size() const { return entries_.size(); }

 private:
  struct Entry {
    std::vector<Element> input;
    Result result;
  };
  std::size_t capacity_;
  std::deque<Entry> entries_;
};

}  // namespace cleave
