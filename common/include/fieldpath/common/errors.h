#pragma once
/// Bad input from the user: a file, line or key is named in the message. Every module throws this
/// for bad input; the CLI prints it as one line and exits with code 1. Anything else is exit 2.
#include <stdexcept>

namespace fieldpath::common {

struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace fieldpath::common
