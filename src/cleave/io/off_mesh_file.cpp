#include "cleave/io/off_mesh_file.hpp"

#include <charconv>
#include <fmt/format.h>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "cleave/core/error.hpp"

namespace cleave {
namespace {

/// Splits the file into whitespace-separated tokens per non-empty, non-comment line.
class OffLines {
 public:
  explicit OffLines(const std::filesystem::path& file) : file_(file.string()), in_(file) {}
  /// Next line's tokens and its 1-based number; throws "truncated" at the end of the file.
  std::vector<std::string> next(const char* expecting) {
    std::string line;
    while (std::getline(in_, line)) {
      ++number_;
      const size_t hash = line.find('#');
      if (hash != std::string::npos) line.erase(hash);
      std::istringstream words(line);
      std::vector<std::string> tokens;
      for (std::string w; words >> w;) tokens.push_back(w);
      if (!tokens.empty()) return tokens;
    }
    throw InputError(fmt::format("{}: the file ends at line {} while expecting {} (truncated?)", file_, number_,
                                 expecting));
  }
  int line() const { return number_; }
  const std::string& file() const { return file_; }

 private:
  std::string file_;
  std::ifstream in_;
  int number_ = 0;
};

template <typename T>
T parse(const OffLines& lines, const std::string& token, const char* what) {
  T value{};
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (ec != std::errc() || end != token.data() + token.size())
    throw InputError(fmt::format("{}: line {}: '{}' is not a valid {}", lines.file(), lines.line(), token, what));
  return value;
}

}  // namespace

TriangleMesh read_off_mesh(const std::filesystem::path& file, double scale) {
  OffLines lines(file);
  std::vector<std::string> tokens = lines.next("the OFF header");
  const std::string& first = tokens.front();
  if (first.size() >= 3 && first.compare(first.size() - 3, 3, "OFF") == 0) {
    if (first != "OFF" && first != "COFF" && first != "NOFF" && first != "CNOFF" && first != "STOFF")
      throw InputError(fmt::format("{}: header '{}' is not supported; expected OFF, COFF, NOFF, CNOFF or STOFF",
                                   lines.file(), first));
    tokens.erase(tokens.begin());
    if (tokens.empty()) tokens = lines.next("the vertex and face counts");
  }
  if (tokens.size() < 2)
    throw InputError(fmt::format("{}: line {}: expected the counts 'vertices faces edges'", lines.file(), lines.line()));
  const auto vertex_count = parse<long long>(lines, tokens[0], "vertex count");
  const auto face_count = parse<long long>(lines, tokens[1], "face count");
  constexpr long long kMaxElements = 1LL << 30;
  if (vertex_count < 0 || face_count < 0 || vertex_count > kMaxElements || face_count > kMaxElements)
    throw InputError(fmt::format("{}: line {}: counts {} vertices and {} faces; expected 0 to 2^30 each",
                                 lines.file(), lines.line(), vertex_count, face_count));
  TriangleMesh mesh;
  for (long long v = 0; v < vertex_count; ++v) {
    tokens = lines.next("a vertex");
    if (tokens.size() < 3)
      throw InputError(fmt::format("{}: line {}: vertex {} has {} coordinates; expected x y z", lines.file(),
                                   lines.line(), v, tokens.size()));
    const Vec3 p(parse<double>(lines, tokens[0], "coordinate"), parse<double>(lines, tokens[1], "coordinate"),
                 parse<double>(lines, tokens[2], "coordinate"));
    if (!p.allFinite())
      throw InputError(fmt::format("{}: vertex {} is ({}, {}, {}); expected finite coordinates", lines.file(), v,
                                   p.x(), p.y(), p.z()));
    mesh.vertices_mm.push_back(scale * p);
  }
  for (long long f = 0; f < face_count; ++f) {
    tokens = lines.next("a face");
    const auto n = parse<long long>(lines, tokens[0], "face size");
    if (n < 3 || static_cast<size_t>(n) + 1 > tokens.size())
      throw InputError(fmt::format("{}: line {}: face {} lists {} of its {} vertex indices; expected at least 3",
                                   lines.file(), lines.line(), f, tokens.size() - 1, n));
    std::vector<int> corners;
    for (long long k = 1; k <= n; ++k) {
      const auto index = parse<long long>(lines, tokens[static_cast<size_t>(k)], "vertex index");
      if (index < 0 || index >= vertex_count)
        throw InputError(fmt::format("{}: line {}: face {} refers to vertex {}; the file has {} vertices",
                                     lines.file(), lines.line(), f, index, vertex_count));
      corners.push_back(static_cast<int>(index));
    }
    for (size_t k = 1; k + 1 < corners.size(); ++k) mesh.triangles.push_back({corners[0], corners[k], corners[k + 1]});
  }
  return mesh;
}

}  // namespace cleave
