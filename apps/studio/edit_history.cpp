#include "studio/edit_history.hpp"

#include "cleave/core/error.hpp"
#include "studio/design_limits.hpp"

namespace cleave::studio {

void EditHistory::push(DesignState next) {
  next.next_id = std::max(next.next_id, highest_next_id_);
  highest_next_id_ = next.next_id;
  states_.erase(states_.begin() + static_cast<std::ptrdiff_t>(cursor_) + 1, states_.end());
  states_.push_back(std::move(next));
  ++cursor_;
  while (states_.size() > kMaxUndoDepth + 1) {
    states_.pop_front();
    --cursor_;
  }
}

void EditHistory::undo() {
  if (!can_undo()) throw InputError("undo: nothing to undo");
  --cursor_;
  keep_ids_unique();
}

void EditHistory::keep_ids_unique() {
  // An undone edit may have used ids; the state we return to must not hand them out again.
  states_[cursor_].next_id = std::max(states_[cursor_].next_id, highest_next_id_);
}

void EditHistory::redo() {
  if (!can_redo()) throw InputError("redo: nothing to redo");
  ++cursor_;
  keep_ids_unique();
}

}  // namespace cleave::studio
