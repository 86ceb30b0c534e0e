#include "cleave/io/teem_error.hpp"

#include <cstdlib>
#include <sstream>
#include <teem/biff.h>

namespace cleave {
namespace {

/// "[nrrd] _nrrdRead: some problem" -> "some problem".
std::string strip_prefixes(std::string line) {
  if (!line.empty() && line.front() == '[') {
    const size_t close = line.find("] ");
    if (close != std::string::npos) line.erase(0, close + 2);
  }
  const size_t colon = line.find(": ");
  if (colon != std::string::npos && line.find(' ') > colon) line.erase(0, colon + 2);
  while (!line.empty() && (line.back() == '\n' || line.back() == ' ')) line.pop_back();
  return line;
}

}  // namespace

std::string take_teem_error(const char* key) {
  char* raw = biffGetDone(key);
  const std::string text = raw ? raw : "";
  std::free(raw);
  std::istringstream lines(text);
  std::string line, last;
  while (std::getline(lines, line)) {
    std::string stripped = strip_prefixes(line);
    if (!stripped.empty()) last = std::move(stripped);
  }
  return last.empty() ? "unreadable file" : last;
}

}  // namespace cleave
