#pragma once
// What a message broadcast to every client may replace in a client's send queue while it is still
// unsent there. A client that reads slowly (a loaded machine, a slow network) needs only the
// newest picture: results are snapshots, so a queued result is replaced in place by a newer one
// instead of queueing one per edit. A result that leaves out the surface parts the clients were
// sent before (studio_compute.hpp) needs the result that carried them, so it replaces only
// another such result, and no result moves ahead of a wound-opening frame queued before it (the
// frames lead up to the result of their own edit).

namespace cleave::studio {

enum class BroadcastKind {
  every,           ///< progress messages, replies: every one is sent
  state,           ///< the design after an edit: replaces the newest queued state
  frame,           ///< a frame of a wound opening: every one is sent, and a newer result queues after it
  full_result,     ///< a result with its whole surface: replaces the newest queued result
  partial_result,  ///< a result without the surface parts sent before: replaces the newest queued
                   ///< result only when that is partial too
};

}  // namespace cleave::studio
