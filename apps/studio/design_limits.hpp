#pragma once
// Bounds on what a client may send: they keep a message, the journal and the work per edit
// bounded, and reject values no tissue has.
#include <cstddef>

namespace cleave::studio {

inline constexpr std::size_t kMaxPathPoints = 4096;        ///< points in one stroke or cut path
inline constexpr std::size_t kMaxDesignItems = 4096;       ///< strokes + control points + cuts
inline constexpr double kMaxCoordinate_mm = 1.0e5;         ///< |x|, |y|, |z| of any position (100 m)
inline constexpr double kMaxEigenvalue_kPa = 1.0e4;        ///< |eigenvalue| (skin: ~10-20 kPa)
inline constexpr double kMaxCutDepth_mm = 1.0e3;           ///< depth of a cut
inline constexpr std::size_t kMaxMessageBytes = 4u << 20;  ///< one WebSocket message (4 MiB)
inline constexpr std::size_t kMaxHttpBodyBytes = 1u << 20; ///< one HTTP request body (1 MiB)
inline constexpr std::size_t kMaxUndoDepth = 256;          ///< design snapshots kept for undo

}  // namespace cleave::studio
