#pragma once
// The results of the last few distinct inputs of a computation whose result depends on its input
// alone (and on state that does not change while the results are kept). In the studio an edit
// back to an earlier design (undo, redo, a stroke dragged back) gives a field equal to one
// computed before, bit for bit, and is answered without solving again.
//
//   RecentResults<std::vector<Vec6>, StaticResult> recent(2);
//   if (const StaticResult* known = recent.find(stress_kPa)) return *known;   // a span probes
//   ...; recent.remember({stress_kPa.begin(), stress_kPa.end()}, result);
//
// Inputs are compared exactly: ranges element by element with ==, other keys with their own ==
// (which may take a probe of another type, e.g. references to the caller's arrays, so that a
// lookup copies nothing). The newest result is found first; past `capacity` the oldest is
// forgotten.
#include <algorithm>
#include <cstddef>
#include <deque>
#include <iterator>
#include <ranges>
#include <utility>

namespace cleave {

template <typename Key, typename Result>
class RecentResults {
 public:
  explicit RecentResults(std::size_t capacity) : capacity_(capacity) {}

  /// The result remembered for a key equal to `probe`, or nullptr.
  template <typename Probe>
  const Result* find(const Probe& probe) const {
    for (const Entry& e : entries_)
      if (same(e.key, probe)) return &e.result;
    return nullptr;
  }

  /// find, and the entry found becomes the newest (without copying it): a result recalled now
  /// stays among the last ones when the next new result is remembered.
  template <typename Probe>
  const Result* renew(const Probe& probe) {
    const auto it = std::find_if(entries_.begin(), entries_.end(), [&](const Entry& e) { return same(e.key, probe); });
    if (it == entries_.end()) return nullptr;
    std::rotate(entries_.begin(), it, std::next(it));
    return &entries_.front().result;
  }

  /// Remembers `result` for `key` as the newest entry (an equal key's older entry is replaced).
  void remember(Key key, Result result) {
    std::erase_if(entries_, [&](const Entry& e) { return same(e.key, key); });
    entries_.push_front(Entry{std::move(key), std::move(result)});
    while (entries_.size() > capacity_) entries_.pop_back();
  }

  void clear() { entries_.clear(); }
  std::size_t size() const { return entries_.size(); }

 private:
  struct Entry {
    Key key;
    Result result;
  };
  template <typename Probe>
  static bool same(const Key& key, const Probe& probe) {
    if constexpr (std::ranges::range<Key> && std::ranges::range<Probe>)
      return std::ranges::equal(key, probe);
    else
      return key == probe;
  }
  std::size_t capacity_;
  std::deque<Entry> entries_;
};

}  // namespace cleave
