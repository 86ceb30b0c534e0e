#pragma once
// Undo / redo over design states: a list of snapshots and a cursor. An edit drops the redo
// branch and appends; undo and redo move the cursor. At most kMaxUndoDepth snapshots are kept
// (the oldest are forgotten), so memory stays bounded however long a session runs.
#include <cstddef>
#include <deque>

#include "studio/design_state.hpp"

namespace cleave::studio {

class EditHistory {
 public:
  EditHistory() : states_{DesignState{}} {}
  explicit EditHistory(DesignState initial) : states_{initial}, highest_next_id_{initial.next_id} {}

  const DesignState& current() const { return states_[cursor_]; }
  void push(DesignState next);
  bool can_undo() const { return cursor_ > 0; }
  bool can_redo() const { return cursor_ + 1 < states_.size(); }
  /// Moves back one edit; InputError "nothing to undo" at the oldest kept state.
  void undo();
  /// Moves forward one edit; InputError "nothing to redo" when no undone edit is left.
  void redo();
  std::size_t undo_depth() const { return cursor_; }
  std::size_t redo_depth() const { return states_.size() - 1 - cursor_; }

 private:
  void keep_ids_unique();

  std::deque<DesignState> states_;
  std::size_t cursor_ = 0;
  int highest_next_id_ = 1;  ///< ids below this were handed out in this session
};

}  // namespace cleave::studio
