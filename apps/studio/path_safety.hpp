#pragma once
// Keeping file access inside one folder: the web root for static files, the session folder for
// save / load / export. A name from outside (a URL path, a file name in a message) is accepted
// only when it is relative, has no ".." or empty component, no NUL or backslash, and still
// lies inside the folder once symbolic links are resolved.
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace cleave::studio {

/// The file `relative` names inside `root`, or std::nullopt when it would leave `root` (or is
/// not a plain relative name as described above). `root` must exist. The file itself need not.
std::optional<std::filesystem::path> resolve_inside(const std::filesystem::path& root, std::string_view relative);

/// Same, throwing InputError "<what> '<name>' is outside the session folder; expected a file
/// name such as design.json" instead of returning nullopt.
std::filesystem::path require_inside(const std::filesystem::path& root, std::string_view relative, const std::string& what);

/// Decodes %XX escapes of a URL path (before resolve_inside). std::nullopt for a malformed
/// escape or an encoded NUL.
std::optional<std::string> percent_decode(std::string_view text);

}  // namespace cleave::studio
