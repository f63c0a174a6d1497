#pragma once
/// Error kinds the program maps to exit codes: bad input → 1 (one clear line naming the file, line
/// or key), anything else → 2 (internal failure).
#include <stdexcept>
#include <string>

namespace fieldpath::app {

/// Bad input from the user (file, line or key in the message). Exit code 1.
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace fieldpath::app
