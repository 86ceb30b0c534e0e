#pragma once
// Errors a user can act on. Every message names the file, field or value and what was expected.
#include <stdexcept>
#include <string>

namespace cleave {

/// Bad input from outside: a file, a case field, a command-line value, a client message.
/// `what()` is one line meant for the user, e.g.
///   "head.nrrd: field 'spacings' has 0 for axis 2; expected a positive number (mm)".
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A computation that could not finish (a solver that did not converge, a result with NaN).
class ComputeError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace cleave
