#pragma once
// No NaN or Inf reaches the page (issue 8, numerical safety): every message the computation
// sends (results, frames, progress) is checked before it goes out. nlohmann::json would write a
// non-finite number as null, which the page would draw as 0 or trip over; instead the message is
// replaced by an error that names the stage which produced the value, and the page keeps its
// previous picture. The session (the design and its journal) is not touched.
//
//   nlohmann::json out = checked_outgoing(std::move(message));   // message, or the error
//   send(out.dump());
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>

namespace cleave::studio {

/// JSON pointer of the first non-finite number in `message` (depth first, in key order), e.g.
/// "/fields/langer_kPa/17"; nullopt when every number is finite.
std::optional<std::string> first_non_finite(const nlohmann::json& message);

/// The computation stage that produces the value at `pointer` in a message of `type`, in the
/// page's words: "/fields/langer_kPa/3" -> "eigenvalues", "/surface/..." -> "surface",
/// a frame's "/positions_mm/..." -> "wound opening (frame)".
std::string stage_of(std::string_view type, std::string_view pointer);

/// `message` when all its numbers are finite; otherwise
///   {"type":"error","stage":S,"generation":G,"seq":N,"message":"computation failed in stage S:
///    /fields/langer_kPa/17 is not finite (nan); the previous result stays shown"}
/// ("generation" and "seq" copied when the message has them).
nlohmann::json checked_outgoing(nlohmann::json message);

}  // namespace cleave::studio
