#pragma once
// teem reports errors through its "biff" message stack; this turns one into a single line.
#include <string>

namespace cleave {

/// Takes (and clears) the biff messages under `key` (e.g. NRRD) and returns the most specific
/// one as a single line without teem's "[nrrd] function:" prefixes, e.g.
/// "fread got only 120 of 1000 bytes". Returns "unreadable file" when biff holds nothing.
std::string take_teem_error(const char* key);

}  // namespace cleave
