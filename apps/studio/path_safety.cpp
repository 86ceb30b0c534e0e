#include "studio/path_safety.hpp"

#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "cleave/io/json_fields.hpp"

namespace cleave::studio {
namespace {

constexpr std::size_t kMaxNameBytes = 1024;

bool is_within(const std::filesystem::path& root, const std::filesystem::path& p) {
  auto r = root.begin();
  auto q = p.begin();
  for (; r != root.end(); ++r, ++q) {
    if (r->empty() && std::next(r) == root.end()) break;  // trailing separator of root
    if (q == p.end() || *q != *r) return false;
  }
  return true;
}

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

}  // namespace

std::optional<std::filesystem::path> resolve_inside(const std::filesystem::path& root, std::string_view relative) {
  if (relative.empty() || relative.size() > kMaxNameBytes) return std::nullopt;
  if (relative.front() == '/') return std::nullopt;
  if (relative.find('\0') != std::string_view::npos || relative.find('\\') != std::string_view::npos) return std::nullopt;
  const std::filesystem::path rel{std::string(relative)};
  for (const auto& part : rel) {
    const std::string s = part.string();
    if (s.empty() || s == "." || s == "..") return std::nullopt;
  }
  std::error_code ec;
  const std::filesystem::path canonical_root = std::filesystem::canonical(root, ec);
  if (ec) return std::nullopt;
  const std::filesystem::path candidate = std::filesystem::weakly_canonical(canonical_root / rel, ec);
  if (ec || !is_within(canonical_root, candidate) || candidate == canonical_root) return std::nullopt;
  return candidate;
}

std::filesystem::path require_inside(const std::filesystem::path& root, std::string_view relative, const std::string& what) {
  auto p = resolve_inside(root, relative);
  if (!p)
    throw InputError(fmt::format("{} '{}' is outside the session folder; expected a file name such as design.json", what,
                                 utf8_prefix(relative, 200)));
  return *p;
}

std::optional<std::string> percent_decode(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '%') {
      out.push_back(text[i]);
      continue;
    }
    if (i + 2 >= text.size()) return std::nullopt;
    const int hi = hex_value(text[i + 1]);
    const int lo = hex_value(text[i + 2]);
    if (hi < 0 || lo < 0 || (hi == 0 && lo == 0)) return std::nullopt;
    out.push_back(static_cast<char>(hi * 16 + lo));
    i += 2;
  }
  return out;
}

}  // namespace cleave::studio
